"""``transparency`` says when its stiffness is above the wall joint's stable limit, and why a bandwidth is null.

Oracle: seed 000 §4.1.2's 1-DOF limit of a sampled spring with full inertial compensation and no delay,
``K* = b^2 / H_ww`` (the Jury condition of the three-state loop at c = 1), with b = 0.01 N m s/rad from the
five-bar file and ``H_ww`` from :func:`hapticdesign.mass_matrix` where the wall holds joint 1 (issue 35: the loop is
linearized at the wall's equilibrium, the spring's rest 0.01 rad from home (2.0, 1.1), so at (2.01, 1.1)).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.interface.cli import app

FIVE_BAR = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"
runner = CliRunner()


@pytest.fixture(scope="module")
def closed_form_limit() -> float:
    device = load_device_file(FIVE_BAR)
    return 0.01 ** 2 / mass_matrix(device, np.array([2.0 + 0.01, 1.1]))[0, 0]


def _run(stiffness: float):
    return runner.invoke(app, ["transparency", "--device", str(FIVE_BAR), "--joint", "1", "--method", "analytic",
                               "--stiffness", repr(float(stiffness)), "--json"])


def test_stiffness_above_the_limit_is_said(closed_form_limit):
    done = _run(4.0)
    assert done.exit_code == 0, done.output
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: K = 4 N m/rad is above joint 1's stable limit")
    out = json.loads(done.stdout)
    assert out["stable_limit"] == pytest.approx(closed_form_limit, rel=1e-6)
    assert out["units"]["stable_limit"] == "N m/rad"
    if out["bandwidth_hz"] is None:
        assert "above the wall joint's stable limit" in out["bandwidth_note"]


def test_stiffness_below_the_limit_gives_no_warning(closed_form_limit):
    done = _run(0.5 * closed_form_limit)
    assert done.exit_code == 0, done.output
    assert done.stderr == ""
    out = json.loads(done.stdout)
    assert out["stable_limit"] == pytest.approx(closed_form_limit, rel=1e-6)
    assert (out["bandwidth_hz"] is None) == ("bandwidth_note" in out)


def test_the_docs_quote_the_five_bar_limit(closed_form_limit):
    """docs/simulation.md quotes joint 1's limit of the five-bar; it is the closed form's, to 4 digits."""
    docs = (Path(__file__).resolve().parents[2] / "docs" / "simulation.md").read_text()
    assert f"five-bar's {closed_form_limit:.4g} N m/rad on joint 1" in docs
