"""The R-CUBE as a closed-loop device file (examples/devices/rcube.yaml) against the built-in R-CUBE.

Oracles: the seed's closed forms of the built-in model (seed 001 eq. 5.28 forward kinematics,
eq. 5.30-5.45 inverse kinematics, eq. 5.49 active Jacobian), its Cartesian inertia
``M_C* = sum_i J_i^-T M_i J_i^-1`` (eq. 5.227) and its stiffness ``K_C = sum_i K_Ci`` (eq. 5.123),
computed chain by chain without loops. The file is solved by the general loop solver, the
closed-loop dynamics in actuated coordinates and the constrained VJM; they share no code path with
the per-chain closed forms beyond the link stiffness formula (eq. 4.59).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.loops.solver import LoopSolver
from hapticdesign.analysis.rcube import dynamics as rcube_dynamics
from hapticdesign.analysis.rcube import kinematics as rcube_kinematics
from hapticdesign.analysis.rcube.design import final_design
from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness as rcube_stiffness
from hapticdesign.analysis.stiffness.device import cartesian_stiffness
from hapticdesign.analysis.stiffness.joints import JointStiffness
from hapticdesign.devices.loading import load_device
from hapticdesign.interface.cli import app

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "devices" / "rcube.yaml"
OFFSETS_MM = [(0.0, 0.0, 0.0), (20.0, -30.0, 40.0), (-45.0, 35.0, -25.0), (55.0, 55.0, 55.0)]
# The file prints the bodies' parameters to 10 significant digits: M_C agrees to about 1e-10; 1e-8
# leaves room for that rounding only. Kinematics and stiffness use the exact lengths and tubes: they
# agree to round-off (1e-9 relative).
PRINTED = 1e-8
ROUND_OFF = 1e-9


@pytest.fixture(scope="module")
def device():
    return load_device(EXAMPLE)


def _pose(offset_mm) -> tuple[np.ndarray, np.ndarray]:
    """A platform position and the built-in inverse kinematics' angles ``(3, 3)`` there."""
    r = final_design().geometry.home + np.array(offset_mm) * 1e-3
    return r, rcube_kinematics.inverse_kinematics(final_design().geometry, r)


@pytest.mark.parametrize("offset_mm", OFFSETS_MM)
def test_platform_follows_the_closed_form_kinematics(device, offset_mm):
    geometry = final_design().geometry
    r, q = _pose(offset_mm)
    pose = configuration_of(device).pose(q[:, 0])
    assert np.allclose(pose[:3, 3], rcube_kinematics.forward_kinematics(geometry, q[:, 0]), rtol=0, atol=1e-12)
    assert np.allclose(pose[:3, 3], r, rtol=0, atol=1e-12)
    assert np.allclose(pose[:3, :3], np.eye(3), rtol=0, atol=1e-12)  # the platform translates (eq. 5.20)
    # passive joints: phi_i2 = -q_i1, phi_i3 = q_i2, phi_i4 = q_i3, phi_i5 = -(q_i2 + q_i3) (eq. 5.13-5.14)
    full = LoopSolver(device.mechanism).solve(q[:, 0])
    expected = np.stack([-q[:, 0], q[:, 1], q[:, 2], -(q[:, 1] + q[:, 2])], axis=-1).ravel()
    assert np.allclose(full[3:], expected, rtol=0, atol=1e-10)
    J = configuration_of(device).jacobian(q[:, 0])
    assert np.allclose(J[:3], rcube_kinematics.active_jacobian(geometry, q[:, 0]), rtol=0, atol=1e-12)
    assert np.allclose(J[3:], 0.0, atol=1e-12)


@pytest.mark.parametrize("offset_mm", OFFSETS_MM)
def test_cartesian_inertia_equals_the_built_in(device, offset_mm):
    r, q = _pose(offset_mm)
    H = mass_matrix(device, q[:, 0])
    J_inv = np.linalg.inv(configuration_of(device).jacobian(q[:, 0])[:3])
    M_C = J_inv.T @ H @ J_inv
    expected = rcube_dynamics.cartesian_mass_matrix(final_design(), r)
    assert np.allclose(M_C, expected, rtol=0, atol=PRINTED * np.abs(expected).max())


@pytest.mark.parametrize("offset_mm", OFFSETS_MM)
def test_stiffness_equals_the_built_in(device, offset_mm):
    r, q = _pose(offset_mm)
    K = cartesian_stiffness(device, q[:, 0])
    expected = rcube_stiffness(final_design(), r)
    scale = np.sqrt(np.outer(np.diag(expected), np.diag(expected)))
    assert np.max(np.abs(K - expected) / scale) < ROUND_OFF


def test_drive_springs_equal_the_built_in_joint_compliance(device):
    """Drive springs on the actuated joints: the built-in adds them as joint springs in series
    (:mod:`hapticdesign.analysis.stiffness.joints`), the file as one-coordinate virtual joints."""
    k = 150.0  # N m/rad, soft enough to matter
    r, q = _pose((20.0, -30.0, 40.0))
    springy = replace(device, elasticity=replace(device.elasticity, joints=(("q1", k), ("q2", k), ("q3", k))))
    drives = (JointStiffness(torsional=k),) + (JointStiffness(),) * 4
    expected = rcube_stiffness(final_design().with_joints(drives), r)
    K = cartesian_stiffness(springy, q[:, 0])
    scale = np.sqrt(np.outer(np.diag(expected), np.diag(expected)))
    assert np.max(np.abs(K - expected) / scale) < ROUND_OFF
    assert K[0, 0] < 0.9 * rcube_stiffness(final_design(), r)[0, 0]  # the springs matter


def test_cli_stiffness_json_and_deflection():
    r, q = _pose((20.0, -30.0, 40.0))
    args = ["stiffness", "--device", str(EXAMPLE), "--q", ",".join(repr(float(v)) for v in q[:, 0]), "--wrench", "1,-2,5"]
    result = CliRunner().invoke(app, args + ["--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    K, expected = np.array(out["K_C"]), rcube_stiffness(final_design(), r)
    scale = np.sqrt(np.outer(np.diag(expected), np.diag(expected)))
    assert np.max(np.abs(K - expected) / scale) < ROUND_OFF
    assert np.allclose(expected @ np.array(out["deflection"]), [1.0, -2.0, 5.0, 0.0, 0.0, 0.0], rtol=0, atol=1e-9)
    text = CliRunner().invoke(app, args)
    assert text.exit_code == 0 and "K_C of frame platform" in text.stdout and "deflection [m, m, m" in text.stdout
    block = json.loads(CliRunner().invoke(app, args + ["--translational", "--json"]).stdout)
    assert np.allclose(block["K_C"], expected[:3, :3], rtol=0, atol=ROUND_OFF * np.abs(expected[:3, :3]).max())
    assert np.allclose(block["deflection"], out["deflection"], rtol=0, atol=1e-15)  # the full K_C deflects


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--wrench", "1,2"], "--wrench: give Fx,Fy,Fz or Fx,Fy,Fz,Mx,My,Mz, got 2 values"),
        (["--q", "0,0"], "--q: expected 3 values, got 2"),
        (["--q", "3,3,3"], "the loops cannot close"),
        (["--frame", "nowhere"], "--frame: unknown frame 'nowhere'"),
    ],
)
def test_cli_stiffness_errors_are_one_line(args, fragment):
    result = CliRunner().invoke(app, ["stiffness", "--device", str(EXAMPLE), *args])
    assert result.exit_code == 2
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0], result.stderr


def test_cli_stiffness_of_a_device_without_links():
    result = CliRunner().invoke(app, ["stiffness", "--preset", "phantom-3dof"])
    assert result.exit_code == 2 and "has no elastic links or joint springs" in result.stderr
