"""Closed-loop results near a singular configuration: right to about 1e-6, or refused (issue 26).

Oracle: an independent 60-digit planar Lagrangian of examples/devices/five-bar.yaml
(tests/helpers/five_bar_reference.py, mpmath, no code of the package). The five-bar's distal links are in line
at q = (pi, 0): there the passive block of the constraint Jacobian is singular, and its smallest singular value
falls linearly with the distance. Before the solver judged its results by their conditioning, it returned H 23 %
off at 1.6e-6 rad from that pose, and 9e-6 off at 1.6e-4 rad, without a word.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import hapticdesign as hd
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app
from tests.helpers.five_bar_reference import FiveBar

FIVE_BAR = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"
DELTA = FIVE_BAR.with_name("delta.yaml")
ACCURACY = 1e-6


@pytest.fixture(scope="module")
def five_bar():
    return load_device_file(FIVE_BAR)


def _relative(a, b) -> float:
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max())


@pytest.mark.parametrize("distance", [1e-2, 1e-3, 1.6e-4, 5e-5, 2e-5, 1e-5, 1.6e-6, 0.0])
def test_right_to_the_stated_accuracy_or_refused(five_bar, distance):
    q = np.array([np.pi - distance, 0.0])
    try:
        h, g, c = hd.mass_matrix(five_bar, q), hd.gravity(five_bar, q), hd.coriolis_centrifugal(five_bar, q)
    except UserError as exc:
        assert "too close to a singular configuration" in str(exc) and "from a singular pose" in str(exc)
        assert distance <= 2e-5  # refused only within the last few 1e-5 rad
        return
    assert distance > 1e-5, "within 1e-5 rad the bound exceeds 1e-7: a refusal is expected"
    reference = FiveBar(q, configuration_of(five_bar).full(q)[2:])
    assert _relative(h, np.array(reference.H().tolist(), dtype=float)) < ACCURACY
    assert _relative(g, np.array([float(v) for v in reference.G()])) < ACCURACY
    assert _relative(c, np.array(reference.C(), dtype=float)) < ACCURACY
    if distance >= 1.6e-4:
        assert _relative(h, np.array(reference.H().tolist(), dtype=float)) < 1e-8


def test_cli_refuses_the_singular_pose_in_one_line():
    """The issue's case: distal links in line, ``--json``; it exited 0 with an H half its limiting value."""
    result = CliRunner().invoke(app, ["dynamics", "--device", str(FIVE_BAR), "--q", "3.141592653589793,0", "--json"])
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and "singular" in result.stderr


def test_a_pose_whose_straight_path_fails_is_reached_joint_by_joint():
    """The delta at (-1.596, -2.224, -2.203): the straight segment from home leaves the workspace, the path that
    moves one arm after the other does not. The pose it returns closes the loops, keeps home's sign of
    ``det Phi_p``, and puts the handle where the delta's trilateration (tests/loops/test_delta.py, closed
    form, lower platform solution) puts it."""
    from tests.loops.test_delta import MOUNT, _platform

    delta = load_device_file(DELTA)
    conf = configuration_of(delta)
    solver = conf.solver
    target = np.array([-1.596, -2.224, -2.203])
    _, status = solver.solve(target, strict=False)
    assert status != 0  # the straight path fails (else this test shows nothing)
    full = conf.full(target)
    assert np.abs(solver.residual(full)).max() < 1e-12
    assert np.sign(np.linalg.det(solver.constraint_jacobian(full)[:, solver.closures.passive])) == solver.branch
    handle = MOUNT @ (_platform(delta.params, target) + np.array([0.0, 0.0, -delta.params["h"]]))
    np.testing.assert_allclose(conf.pose(target)[:3, 3], handle, atol=1e-12)


@pytest.mark.parametrize("target, words", [
    ((2.01, 1.028, 2.854), "the paths tried from home"),
    ((3.12, 1.699, 0.597), "only on another assembly branch"),
    ((-1.992, -1.431, -0.947), "cannot close"),
])
def test_a_refusal_says_whether_the_pose_or_the_path_failed(target, words):
    """Poses far from the delta's home: one closes on the assembly branch but no path tried reaches it, one closes
    only with the other sign of ``det Phi_p``, one does not close from home's passive angles."""
    delta = load_device_file(DELTA)
    with pytest.raises(UserError, match=words):
        hd.mass_matrix(delta, np.array(target))
