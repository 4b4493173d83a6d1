"""The Falcon-style delta (examples/devices/delta.yaml) against closed-form kinematics and a Lagrangian.

References, independent of the loop solver and of the actuated-coordinate kernel:
- forward kinematics: trilateration of the three spheres of radius Lb about the elbows (shifted by
  the platform radius), the solution on the platform's side; inverse kinematics: per leg
  ``x cos q - z sin q = (x^2 + y^2 + z^2 + La^2 - Lb^2) / (2 La)`` in the leg's frame;
- dynamics: an explicit Lagrangian built here from the closed-form pose of every body (arms, both
  rods of each parallelogram, lower bars, platform): ``H_a = sum m Jc^T Jc + Jw^T R I R^T Jw`` with
  Jacobians by finite differences, ``G_a`` the gradient of the potential, C from the Christoffel
  symbols of that ``H_a``;
- energy conservation without damping; H positive definite and ``Hdot - 2 C_cvt`` skew-symmetric are checked for
  every example device in tests/dynamics/test_example_properties.py.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from hapticdesign.analysis.dynamics.device import (
    coriolis_centrifugal,
    dynamics_of,
    forward_dynamics,
    gravity,
    mass_matrix,
)
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.devices.device_file import load_device_file

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "devices" / "delta.yaml"
PSI = (0.0, 2 * np.pi / 3, 4 * np.pi / 3)
MOUNT = Rotation.from_euler("y", np.pi / 2).as_matrix()


def _rz(a: float) -> np.ndarray:
    return Rotation.from_euler("z", a).as_matrix()


def _ry(a: float) -> np.ndarray:
    return Rotation.from_euler("y", a).as_matrix()


@pytest.fixture(scope="module")
def device():
    return load_device_file(EXAMPLE)


def _elbow(p, j: int, q: float) -> np.ndarray:
    """Elbow of leg j in the delta's own frame."""
    return _rz(PSI[j]) @ np.array([p["R"] + p["La"] * np.cos(q), 0.0, -p["La"] * np.sin(q)])


def _platform(p, qa: np.ndarray) -> np.ndarray:
    """Closed form: platform centre in the delta's frame (trilateration, lower solution)."""
    centres = [_elbow(p, j, qa[j]) - _rz(PSI[j]) @ np.array([p["r"], 0.0, 0.0]) for j in range(3)]
    c1, c2, c3 = centres
    ex = (c2 - c1) / np.linalg.norm(c2 - c1)
    i = ex @ (c3 - c1)
    ey = (c3 - c1 - i * ex) / np.linalg.norm(c3 - c1 - i * ex)
    ez = np.cross(ex, ey)
    d, j = np.linalg.norm(c2 - c1), ey @ (c3 - c1)
    x = d / 2
    y = (i**2 + j**2 - 2 * i * x) / (2 * j)
    z = np.sqrt(p["Lb"] ** 2 - x**2 - y**2)
    candidates = [c1 + x * ex + y * ey + s * z * ez for s in (1.0, -1.0)]
    return min(candidates, key=lambda c: c[2])


def _inverse(p, centre: np.ndarray) -> np.ndarray:
    """Closed form: actuated angles placing the platform centre (delta frame), arms bent towards the platform."""
    out = []
    for j in range(3):
        x, y, z = _rz(-PSI[j]) @ centre + np.array([p["r"] - p["R"], 0.0, 0.0])
        k = (x**2 + y**2 + z**2 + p["La"] ** 2 - p["Lb"] ** 2) / (2 * p["La"])
        # x cos q - z sin q = k  ->  rho cos(q + phi) = k with rho = |(x, z)|, phi = atan2(z, x)
        rho, phi = np.hypot(x, z), np.arctan2(z, x)
        out.append(-np.arccos(k / rho) - phi)  # of the two solutions, the arm below the base plane
    return np.array(out)


def _body_poses(device, qa: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Closed form: world position and orientation of every body frame of the file."""
    p = device.params
    centre = _platform(p, qa)
    out = {"platform": (MOUNT @ centre, MOUNT)}
    for j in range(3):
        arm = _rz(PSI[j]) @ _ry(qa[j])
        hip = _rz(PSI[j]) @ np.array([p["R"], 0.0, 0.0])
        elbow = _elbow(p, j, qa[j])
        anchor = centre + _rz(PSI[j]) @ np.array([p["r"], 0.0, 0.0])
        d = arm.T @ (anchor - elbow) / p["Lb"]
        p2, p1 = np.arcsin(d[1]), np.arctan2(-d[2], d[0])
        rod = arm @ _ry(p1) @ _rz(p2)
        out[f"arm{j + 1}"] = (MOUNT @ hip, MOUNT @ arm)
        for side, offset in (("a", 0.5), ("b", -0.5)):
            out[f"rod{j + 1}{side}"] = (MOUNT @ (elbow + arm @ np.array([0.0, offset * p["w"], 0.0])), MOUNT @ rod)
        out[f"bar{j + 1}"] = (MOUNT @ anchor, MOUNT @ arm @ _ry(p1))
    return out


def _samples(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(0.1, 0.6, (n, 3))


def test_forward_kinematics_is_the_trilateration(device):
    p = device.params
    for qa in _samples(20, 1):
        pose = configuration_of(device).pose(qa)
        handle = MOUNT @ (_platform(p, qa) + np.array([0.0, 0.0, -p["h"]]))
        np.testing.assert_allclose(pose[:3, 3], handle, atol=1e-13)
        np.testing.assert_allclose(pose[:3, :3], MOUNT, atol=1e-13)  # the handle only translates


def test_inverse_kinematics_closed_form(device):
    p = device.params
    for centre in ([0.0, 0.0, -0.10], [0.02, -0.01, -0.09], [-0.015, 0.02, -0.11], [0.01, 0.015, -0.08]):
        qa = _inverse(p, np.array(centre))
        pose = configuration_of(device).pose(qa, frame="platform")
        np.testing.assert_allclose(pose[:3, 3], MOUNT @ np.array(centre), atol=1e-13)


# -- explicit Lagrangian ----------------------------------------------------------------------------
def _jacobians(device, qa: np.ndarray, h: float = 1e-4) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Mass-centre and angular-velocity Jacobians (3 x 3 each) by fourth-order central differences."""
    steps = {s: [_body_poses(device, qa + s * h * e) for e in np.eye(3)] for s in (-2, -1, 1, 2)}
    here = _body_poses(device, qa)
    out = {}
    for name in here:
        body = device.body(name)
        com = lambda pose: pose[0] + pose[1] @ body.r
        jc = np.zeros((3, 3))
        jw = np.zeros((3, 3))
        for k in range(3):
            weights = {-2: 1.0, -1: -8.0, 1: 8.0, 2: -1.0}
            jc[:, k] = sum(w * com(steps[s][k][name]) for s, w in weights.items()) / (12 * h)
            dr = sum(w * steps[s][k][name][1] for s, w in weights.items()) / (12 * h)
            skew = dr @ here[name][1].T
            jw[:, k] = [skew[2, 1], skew[0, 2], skew[1, 0]]
        out[name] = (jc, jw)
    return out


def _lagrangian_mass(device, qa: np.ndarray) -> np.ndarray:
    here = _body_poses(device, qa)
    mass = np.zeros((3, 3))
    for name, (jc, jw) in _jacobians(device, qa).items():
        body = device.body(name)
        inertia = here[name][1] @ body.inertia_at_com @ here[name][1].T
        mass += body.m * jc.T @ jc + jw.T @ inertia @ jw
    return mass


def _potential(device, qa: np.ndarray) -> float:
    g = device.params["g"]
    return sum(device.body(n).m * g * (pos + rot @ device.body(n).r)[2] for n, (pos, rot) in _body_poses(device, qa).items())


def test_mass_matrix_and_gravity_match_the_lagrangian(device):
    h = 1e-4
    for qa in _samples(5, 2):
        mass = _lagrangian_mass(device, qa)
        # Jacobians by 4th-order differences: truncation ~h^4, round-off ~eps/h: ~1e-12 relative
        np.testing.assert_allclose(mass_matrix(device, qa), mass, rtol=1e-8, atol=1e-8 * np.abs(mass).max())
        grad = np.array([(-_potential(device, qa + 2 * h * e) + 8 * _potential(device, qa + h * e)
                          - 8 * _potential(device, qa - h * e) + _potential(device, qa - 2 * h * e)) / (12 * h)
                         for e in np.eye(3)])
        np.testing.assert_allclose(gravity(device, qa), grad, rtol=1e-8, atol=1e-8 * np.abs(grad).max())


def test_coriolis_matches_the_christoffel_symbols_of_the_lagrangian(device):
    h = 1e-3
    for qa in _samples(2, 3):
        dh = np.stack([(-_lagrangian_mass(device, qa + 2 * h * e) + 8 * _lagrangian_mass(device, qa + h * e)
                        - 8 * _lagrangian_mass(device, qa - h * e) + _lagrangian_mass(device, qa - 2 * h * e)) / (12 * h)
                       for e in np.eye(3)])  # dh[k] = dH/dq_k
        gamma = 0.5 * (np.einsum("kij->ijk", dh) + np.einsum("jik->ijk", dh) - np.einsum("ijk->ijk", dh))
        columns = []
        for j in range(3):
            for k in range(j, 3):
                columns.append(gamma[:, j, j] if j == k else 2 * gamma[:, j, k])
        reference = np.stack(columns, axis=1)
        # H from 1e-12-accurate Jacobians differentiated with h = 1e-3 (4th order): ~1e-9 relative
        np.testing.assert_allclose(coriolis_centrifugal(device, qa), reference, rtol=1e-6, atol=1e-6 * np.abs(reference).max())


def test_dynamics_along_a_motion_match_the_lagrangian(device):
    """A 1 kHz motion, each pose continued from the last (second-order predictor and Newton), with a step the
    continuation must split: H and G at poses along it, and C at one, against the Lagrangian."""
    model, pi = dynamics_of(device), device.standard_parameters()
    t = np.arange(300)[:, None] * 1e-3
    path = np.array([0.35, 0.35, 0.35]) + 0.15 * np.sin(2 * np.pi * np.array([2.0, 2.5, 3.0]) * t)
    path[200:] += 0.15
    mass, weight, coriolis = model.H(path, pi), model.G(path, pi), model.C(path, pi)
    h = 1e-4
    for p in (1, 150, 200, 299):
        ref = _lagrangian_mass(device, path[p])
        np.testing.assert_allclose(mass[p], ref, rtol=1e-8, atol=1e-8 * np.abs(ref).max())
        qa = path[p]
        grad = np.array([(-_potential(device, qa + 2 * h * e) + 8 * _potential(device, qa + h * e)
                          - 8 * _potential(device, qa - h * e) + _potential(device, qa - 2 * h * e)) / (12 * h)
                         for e in np.eye(3)])
        np.testing.assert_allclose(weight[p], grad, rtol=1e-8, atol=1e-8 * np.abs(grad).max())
    h = 1e-3
    qa = path[150]
    dh = np.stack([(-_lagrangian_mass(device, qa + 2 * h * e) + 8 * _lagrangian_mass(device, qa + h * e)
                    - 8 * _lagrangian_mass(device, qa - h * e) + _lagrangian_mass(device, qa - 2 * h * e)) / (12 * h)
                   for e in np.eye(3)])
    gamma = 0.5 * (np.einsum("kij->ijk", dh) + np.einsum("jik->ijk", dh) - np.einsum("ijk->ijk", dh))
    reference = np.stack([gamma[:, j, j] if j == k else 2 * gamma[:, j, k] for j in range(3) for k in range(j, 3)],
                         axis=1)
    np.testing.assert_allclose(coriolis[150], reference, rtol=1e-6, atol=1e-6 * np.abs(reference).max())


# -- energy (H PD and Hdot - 2 C_cvt skew: tests/dynamics/test_example_properties.py) ---------------
def test_energy_is_conserved_without_damping(device):
    qa0, qd0 = np.array([0.35, 0.30, 0.40]), np.array([2.0, -1.0, 0.5])

    def rhs(_t, x):
        return np.concatenate([x[3:], forward_dynamics(device, x[:3], x[3:], np.zeros(3))])

    sol = solve_ivp(rhs, (0.0, 0.1), np.concatenate([qa0, qd0]), method="DOP853", rtol=1e-11, atol=1e-12,
                    t_eval=np.linspace(0.0, 0.1, 21))
    assert sol.success
    energies = [0.5 * x[3:] @ mass_matrix(device, x[:3]) @ x[3:] + _potential(device, x[:3]) for x in sol.y.T]
    kinetic = 0.5 * qd0 @ mass_matrix(device, qa0) @ qd0
    assert np.ptp(energies) <= 1e-8 * kinetic
    assert np.ptp(sol.y[0]) > 0.05
