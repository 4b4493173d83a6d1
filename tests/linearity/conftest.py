"""Shared fixtures: LN forms of the two Phantom presets (built once per session; presets in tests/conftest.py)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from hapticdesign.analysis.linearity.service import device_form

APPENDIX_C = Path(__file__).resolve().parents[3] / "shared" / "reference" / "seed000_appendix_c_designs.json"


@pytest.fixture(scope="session")
def form3(phantom3):
    return device_form(phantom3)


@pytest.fixture(scope="session")
def form6(phantom6):
    return device_form(phantom6)


@pytest.fixture(scope="session")
def appendix_c():
    return json.loads(APPENDIX_C.read_text())
