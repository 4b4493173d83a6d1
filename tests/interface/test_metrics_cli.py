"""``hapticdesign metrics``: seed 001's general metrics on devices of the kinematic core."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.kinematics import forward_kinematics
from hapticdesign.devices.loading import resolve_device
from hapticdesign.interface.cli import app

runner = CliRunner()
PANTOGRAPH = str(Path(__file__).resolve().parents[2] / "examples" / "devices" / "pantograph-2dof.yaml")


def _fd_jacobian(device, q: np.ndarray, eps: float = 1e-7) -> np.ndarray:
    """Translational Jacobian by central differences of forward kinematics (independent of ``jacobian``)."""
    mech = device.mechanism
    cols = [
        (forward_kinematics(mech, q + eps * e)[:3, 3] - forward_kinematics(mech, q - eps * e)[:3, 3]) / (2 * eps)
        for e in np.eye(device.n_dof)
    ]
    return np.stack(cols, axis=1)


def _run(args):
    result = runner.invoke(app, ["metrics", *args, "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_phantom_metrics_against_finite_differences_and_kinetic_energy(phantom3):
    rng = np.random.default_rng(3)
    q = np.array([0.1, 0.5, 0.3])
    out = _run(["--q", "0.1,0.5,0.3"])
    J = _fd_jacobian(phantom3, q)
    assert out["manipulability"] == pytest.approx(np.sqrt(np.linalg.det(J @ J.T)), rel=1e-6)
    s = np.linalg.svd(J, compute_uv=False)
    assert out["condition_number"] == pytest.approx(s[0] / s[-1], rel=1e-6)
    M_C = np.array(out["cartesian_inertia"])
    H = mass_matrix(phantom3, q)
    for _ in range(3):
        v = rng.normal(size=3)
        qd = np.linalg.solve(J, v)
        assert 0.5 * v @ M_C @ v == pytest.approx(0.5 * qd @ H @ qd, rel=1e-6)
    assert out["I_m"] == pytest.approx(np.linalg.det(M_C), rel=1e-9)


def test_planar_device_metrics_do_not_depend_on_axes():
    """A 2-DOF pantograph: the area scaling sqrt(det(J^T J)) of the 3 x 2 Jacobian is the manipulability."""
    device = resolve_device(device_file=PANTOGRAPH)
    q = np.array([0.3, 1.2])
    out = _run(["--device", PANTOGRAPH, "--q", "0.3,1.2"])
    J = _fd_jacobian(device, q)
    assert out["manipulability"] == pytest.approx(np.sqrt(np.linalg.det(J.T @ J)), rel=1e-6)
    qd = np.array([0.4, -0.7])
    v2 = np.array(out["jacobian"]) @ qd
    M_C = np.array(out["cartesian_inertia"])
    assert 0.5 * v2 @ M_C @ v2 == pytest.approx(0.5 * qd @ mass_matrix(device, q) @ qd, rel=1e-9)


def test_six_dof_uses_the_full_jacobian():
    out = _run(["--preset", "phantom-6dof", "--q", "0.1,0.5,0.3,0.2,0.4,0.1"])
    assert np.array(out["jacobian"]).shape == (6, 6)
    assert np.array(out["cartesian_inertia"]).shape == (6, 6)


def test_singular_pose_is_one_line_exit_2():
    result = runner.invoke(app, ["metrics", "--q", "0,0,1.5707963267948966"])
    assert result.exit_code == 2
    assert result.stderr.startswith("error: singular configuration") and result.stderr.count("\n") == 1


def test_registry_metrics_against_a_finite_difference_jacobian(phantom3):
    """I_d, I_f, I_e and the acceleration radius (seed 001 eq. 4.96-4.99) by NumPy from a finite-difference J_m, and
    an index of the registry asked by --index (the handle's isotropy of a 3-joint device: 1 / cond J)."""
    q = np.array([0.2, 0.4, -0.3])
    out = _run(["--q", "0.2,0.4,-0.3", "--index", "isotropy,mass"])
    J, H = _fd_jacobian(phantom3, q), mass_matrix(phantom3, q)
    M_C = np.linalg.inv(J).T @ H @ np.linalg.inv(J)
    assert out["I_d"] == pytest.approx(abs(np.linalg.det(J)) / np.linalg.det(H), rel=1e-6)
    assert out["I_f"] == pytest.approx(np.sqrt(np.trace(M_C @ M_C.T)), rel=1e-6)
    assert out["I_e"] == pytest.approx(np.linalg.cond(M_C), rel=1e-6)
    assert out["acceleration_radius"] == pytest.approx(np.linalg.svd(J @ np.linalg.inv(H), compute_uv=False)[-1],
                                                       rel=1e-6)
    s = np.linalg.svd(J, compute_uv=False)
    assert out["indices"]["isotropy"] == pytest.approx(s[-1] / s[0], rel=1e-6)
    assert out["indices"]["mass"] == pytest.approx(sum(phantom3.body(b).m for b in phantom3.body_names), rel=1e-12)
    assert out["units"]["indices"] == {"isotropy": "1", "mass": "kg"}


def test_an_unknown_index_is_one_line_exit_2():
    result = runner.invoke(app, ["metrics", "--q", "0.1,0.5,0.3", "--index", "nope"])
    assert result.exit_code == 2
    assert result.stderr.startswith("error: unknown index 'nope'") and result.stderr.count("\n") == 1


def test_your_own_index_from_a_file(tmp_path, phantom3):
    """An index of an --indices file, named by --index: the squared isotropy of a 3-joint device, 1 / cond(J)^2."""
    (tmp_path / "mine.py").write_text(
        "import numpy as np, hapticdesign as hd\n\n"
        "@hd.index(unit='1', name='isotropy_squared_metrics', needs=('kinematics',))\n"
        "def isotropy_squared_metrics(pose):\n"
        "    s = np.linalg.svd(pose.J_v, compute_uv=False)\n"
        "    return (s[..., -1] / s[..., 0]) ** 2\n")
    out = _run(["--q", "0.2,0.4,-0.3", "--indices", str(tmp_path / "mine.py"), "--index", "isotropy_squared_metrics"])
    s = np.linalg.svd(_fd_jacobian(phantom3, np.array([0.2, 0.4, -0.3])), compute_uv=False)
    assert out["indices"]["isotropy_squared_metrics"] == pytest.approx((s[-1] / s[0]) ** 2, rel=1e-6)
