"""A study on a closed-loop device: steps that cannot apply are skipped with their reason, a failed step is one
stderr line and exit status 2 (after the report), and the equations-of-motion step evaluates the loop.

Oracles: H at the five-bar's home (2.0, 1.1) from the closed-loop model must be symmetric positive definite and
equal :func:`hapticdesign.mass_matrix` there; tau at rest (qd = 0, qdd = 0) is G.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import typer

from hapticdesign.analysis.dynamics.device import gravity, mass_matrix
from hapticdesign.interface.commands.study import _finish
from hapticdesign.studies import device_steps
from hapticdesign.studies.device import DeviceSettings
from hapticdesign.studies.steps import STATUS_SKIPPED, Context, SilentProgress, Step, run_steps

FIVE_BAR = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"


@pytest.fixture(scope="module")
def context(tmp_path_factory):
    return Context(DeviceSettings.for_device(FIVE_BAR, None), tmp_path_factory.mktemp("work"), SilentProgress())


def test_closed_loop_equations_of_motion_are_evaluated_at_home(context):
    outcome = device_steps.equations_of_motion(context)
    device = context.settings.device()
    home = np.array([2.0, 1.1])
    h = np.asarray(outcome.numbers["H_at_home"])
    assert np.allclose(h, h.T) and np.linalg.eigvalsh(h).min() > 0
    assert np.array_equal(h, mass_matrix(device, home))
    assert "no symbolic form" in outcome.summary
    rows = outcome.tables[0].rows
    assert rows[0][0] == "2.0000, 1.1000" and len(rows) == 3
    assert np.allclose(rows[0][3:5], gravity(device, home))


def test_linearization_is_skipped_with_its_reason(context):
    (result,) = run_steps([Step("linearization", "Linearization", device_steps.linearization)], context)
    assert result.status == STATUS_SKIPPED and "exact trigonometric basis" in result.reason


def _found(*statuses: str) -> dict:
    return {"report": "/tmp/r.html", "steps": {f"s{i}": {"status": s, "reason": f"why {i}"} for i, s in enumerate(statuses)}}


def test_a_failed_step_is_one_line_and_exit_2(capsys):
    with pytest.raises(typer.Exit) as stop:
        _finish(_found("done", "failed", "skipped", "failed"), quiet=True, as_json=False)
    assert stop.value.exit_code == 2
    assert capsys.readouterr().err.splitlines() == ["error: step s1 failed: why 1", "error: step s3 failed: why 3"]


def test_skipped_steps_are_notes_and_exit_0(capsys):
    _finish(_found("done", "skipped"), quiet=False, as_json=False)
    captured = capsys.readouterr()
    assert captured.out == "report: /tmp/r.html\n" and captured.err == "note: step s1 skipped: why 1\n"
