"""Shared fixtures: LN forms of the two Phantom presets (built once per session; presets in tests/conftest.py)."""

from __future__ import annotations

import pytest

from hapticdesign.analysis.linearity.form import device_form
from hapticdesign.studies.seed_reference import appendix_c_designs


@pytest.fixture(scope="session")
def form3(phantom3):
    return device_form(phantom3)


@pytest.fixture(scope="session")
def form6(phantom6):
    return device_form(phantom6)


@pytest.fixture(scope="session")
def appendix_c():
    """The 30 designs printed in seed 000 Appendix C (a copy of shared/reference, shipped with the package)."""
    return appendix_c_designs()
