"""The five-bar (examples/devices/five-bar.yaml) against closed-form kinematics and Pinocchio.

References, all independent of the loop solver and of the actuated-coordinate kernel:
- forward kinematics: intersection of the two distal circles (upper solution, elbows out);
- inverse kinematics: the law of cosines per branch;
- dynamics: Pinocchio's CRBA/RNEA of the loop-opened tree (4 revolute joints), reduced to the
  actuated coordinates with passive rates and accelerations obtained by finite differences of the
  closed-form passive angles (``tau_a = T^T rnea(q, T qd_a, qdd)``, d'Alembert);
- energy conservation without damping (scipy ``solve_ivp``); H positive definite and ``Hdot - 2 C_cvt``
  skew-symmetric are checked for every example device in tests/dynamics/test_example_properties.py.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from hapticdesign.analysis.dynamics.device import (
    dynamics_of,
    forward_dynamics,
    gravity,
    inverse_dynamics,
    mass_matrix,
)
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.devices.device_file import load_device_file

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"
RANGE = ((1.6, 2.4), (0.7, 1.5))  # actuated box around home used for sampling


@pytest.fixture(scope="module")
def device():
    return load_device_file(EXAMPLE)


def _lengths(device):
    p = device.params
    return p["d"], p["l1"], p["l2"]


def _handle(device, qa: np.ndarray) -> np.ndarray:
    """Closed form: the handle (x, z) as the upper intersection of the distal circles."""
    d, l1, l2 = _lengths(device)
    b1 = np.array([-d / 2 + l1 * np.cos(qa[0]), l1 * np.sin(qa[0])])
    b2 = np.array([d / 2 + l1 * np.cos(qa[1]), l1 * np.sin(qa[1])])
    gap = b2 - b1
    dist = np.linalg.norm(gap)
    height = np.sqrt(l2**2 - (dist / 2) ** 2)
    normal = np.array([-gap[1], gap[0]]) / dist
    return b1 + gap / 2 + height * normal


def _passive(device, qa: np.ndarray) -> np.ndarray:
    """Closed form: elbow angles p1, p2 (relative to the proximal links) from the handle position."""
    d, l1, l2 = _lengths(device)
    tip = _handle(device, qa)
    out = []
    for base, q in ((-d / 2, qa[0]), (d / 2, qa[1])):
        elbow = np.array([base + l1 * np.cos(q), l1 * np.sin(q)])
        out.append(np.arctan2(tip[1] - elbow[1], tip[0] - elbow[0]) - q)
    return np.unwrap(np.array(out))


def _samples(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.stack([rng.uniform(lo, hi, n) for lo, hi in RANGE], axis=-1)


def test_forward_kinematics_is_the_circle_intersection(device):
    for qa in _samples(20, 1):
        pose = configuration_of(device).pose(qa)
        x, z = _handle(device, qa)
        np.testing.assert_allclose(pose[:3, 3], [x, 0.0, z], atol=1e-13)


def test_inverse_kinematics_law_of_cosines(device):
    d, l1, l2 = _lengths(device)
    for x, z in [(0.0, 0.20), (0.03, 0.18), (-0.04, 0.22), (0.02, 0.16)]:
        qa = []
        for base, sign in ((-d / 2, 1.0), (d / 2, -1.0)):  # elbows out: left branch +, right branch -
            rx, rz = x - base, z
            reach = np.hypot(rx, rz)
            qa.append(np.arctan2(rz, rx) + sign * np.arccos((l1**2 + reach**2 - l2**2) / (2 * l1 * reach)))
        pose = configuration_of(device).pose(np.array(qa))
        np.testing.assert_allclose(pose[:3, 3], [x, 0.0, z], atol=1e-13)


def test_passive_angles_follow_the_closed_form(device):
    for qa in _samples(10, 2):
        q = dynamics_of(device).full_coordinates(qa)
        np.testing.assert_allclose(q[2:], _passive(device, qa), atol=1e-12)


def test_handle_jacobian_is_the_derivative_of_the_closed_form(device):
    h = 1e-6
    for qa in _samples(5, 3):
        jac = configuration_of(device).jacobian(qa)
        fd = np.stack([(_handle(device, qa + h * e) - _handle(device, qa - h * e)) / (2 * h) for e in np.eye(2)], axis=1)
        np.testing.assert_allclose(jac[[0, 2]], fd, atol=1e-8)  # central differences: h^2 ~ 1e-12, eps/h ~ 1e-10


# -- dynamics against Pinocchio on the loop-opened tree -----------------------------------------------------
def _pinocchio_tree(device) -> pin.Model:
    """The five-bar opened at the handle, built with Pinocchio's API: joints q1, p1 (left), q2, p2 (right)."""
    d, l1, l2 = _lengths(device)
    model = pin.Model()
    model.gravity = pin.Motion(np.array([0, 0, -device.params["g"], 0, 0, 0]))
    plane = Rotation.from_euler("x", np.pi / 2).as_matrix()

    def inertia(name: str, shift: float = 0.0) -> pin.Inertia:
        body = device.body(name)
        return pin.Inertia(body.m, body.r + np.array([shift, 0.0, 0.0]), body.inertia_at_com)

    for base, proximal, distal, extra in ((-d / 2, "1", "3", "h"), (d / 2, "2", "4", None)):
        j1 = model.addJoint(0, pin.JointModelRZ(), pin.SE3(plane, plane @ np.array([base, 0.0, 0.0])), f"q{proximal}")
        model.appendBodyToJoint(j1, inertia(proximal), pin.SE3.Identity())
        j2 = model.addJoint(j1, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([l1, 0.0, 0.0])), f"p{proximal}")
        model.appendBodyToJoint(j2, inertia(distal), pin.SE3.Identity())
        if extra:
            model.appendBodyToJoint(j2, inertia(extra, shift=l2), pin.SE3.Identity())
    return model


def _reduced_reference(device, model: pin.Model, qa, qda, qdda):
    """``H_a = T^T M T``, ``G_a`` and ``tau_a = T^T rnea(q, qd, qdd)`` with T, passive accelerations by finite differences."""
    data = model.createData()
    h1, h2 = 1e-6, 1e-4
    s = np.stack([(_passive(device, qa + h1 * e) - _passive(device, qa - h1 * e)) / (2 * h1) for e in np.eye(2)], axis=1)
    curvature = (_passive(device, qa + h2 * qda) - 2 * _passive(device, qa) + _passive(device, qa - h2 * qda)) / h2**2
    p = _passive(device, qa)
    order = lambda a, b: np.array([a[0], b[0], a[1], b[1]])  # Pinocchio's joint order q1, p1, q2, p2
    t = np.zeros((4, 2))
    t[[0, 2], [0, 1]] = 1.0
    t[[1, 3]] = s
    q, qd, qdd = order(qa, p), order(qda, s @ qda), order(qdda, s @ qdda + curvature)
    mass = pin.crba(model, data, q)
    mass = np.triu(mass) + np.triu(mass, 1).T
    gravity = pin.computeGeneralizedGravity(model, data, q)
    return t.T @ mass @ t, t.T @ gravity, t.T @ pin.rnea(model, data, q, qd, qdd)


def test_dynamics_match_pinocchio_reduced_by_the_closed_form(device):
    model = _pinocchio_tree(device)
    rng = np.random.default_rng(5)
    for qa in _samples(8, 4):
        qda, qdda = rng.normal(size=2), rng.normal(size=2)
        mass, weight, tau = _reduced_reference(device, model, qa, qda, qdda)
        # finite differences of the closed form: first derivatives ~1e-10, second ~1e-8 relative
        np.testing.assert_allclose(mass_matrix(device, qa), mass, rtol=1e-7, atol=1e-7 * np.abs(mass).max())
        np.testing.assert_allclose(gravity(device, qa), weight, rtol=1e-7, atol=1e-7 * np.abs(weight).max())
        np.testing.assert_allclose(inverse_dynamics(device, qa, qda, qdda), tau, rtol=1e-6, atol=1e-6 * np.abs(tau).max())


def test_dynamics_along_a_motion_match_pinocchio(device):
    """A 1 kHz motion, each pose continued from the last (second-order predictor and Newton), with a step the
    continuation must split: H, G and the inverse dynamics at poses along it, against Pinocchio."""
    model, pi = dynamics_of(device), device.standard_parameters()
    t = np.arange(300)[:, None] * 1e-3
    path = np.array([2.0, 1.1]) + 0.3 * np.sin(2 * np.pi * np.array([2.0, 2.5]) * t)
    path[200:] += 0.15
    rng = np.random.default_rng(7)
    qda, qdda = rng.normal(size=path.shape), rng.normal(size=path.shape)
    mass, weight, tau = model.H(path, pi), model.G(path, pi), model.inverse(path, qda, qdda, pi)
    tree = _pinocchio_tree(device)
    for p in (1, 150, 199, 200, 299):
        ref_mass, ref_weight, ref_tau = _reduced_reference(device, tree, path[p], qda[p], qdda[p])
        np.testing.assert_allclose(mass[p], ref_mass, rtol=1e-7, atol=1e-7 * np.abs(ref_mass).max())
        np.testing.assert_allclose(weight[p], ref_weight, rtol=1e-7, atol=1e-7 * np.abs(ref_weight).max())
        np.testing.assert_allclose(tau[p], ref_tau, rtol=1e-6, atol=1e-6 * np.abs(ref_tau).max())


# -- energy (H PD and Hdot - 2 C_cvt skew: tests/dynamics/test_example_properties.py) ---------------
def _potential(device, qa: np.ndarray) -> float:
    """Gravity potential from the closed-form positions of every mass centre."""
    d, l1, l2 = _lengths(device)
    g = device.params["g"]
    p = _passive(device, qa)
    plane = Rotation.from_euler("x", np.pi / 2).as_matrix()
    energy = 0.0
    for base, q, pa, proximal, distal in ((-d / 2, qa[0], p[0], "1", "3"), (d / 2, qa[1], p[1], "2", "4")):
        r1 = plane @ Rotation.from_euler("z", q).as_matrix()
        r2 = plane @ Rotation.from_euler("z", q + pa).as_matrix()
        o1 = np.array([base, 0.0, 0.0])
        o2 = o1 + r1 @ np.array([l1, 0.0, 0.0])
        energy += device.body(proximal).m * g * (o1 + r1 @ device.body(proximal).r)[2]
        energy += device.body(distal).m * g * (o2 + r2 @ device.body(distal).r)[2]
        if proximal == "1":
            tip = o2 + r2 @ np.array([l2, 0.0, 0.0])
            energy += device.body("h").m * g * (tip + r2 @ device.body("h").r)[2]
    return energy


def test_energy_is_conserved_without_damping(device):
    qa0, qd0 = np.array([2.0, 1.1]), np.array([1.5, -1.0])

    def rhs(_t, x):
        return np.concatenate([x[2:], forward_dynamics(device, x[:2], x[2:], np.zeros(2))])

    sol = solve_ivp(rhs, (0.0, 0.1), np.concatenate([qa0, qd0]), method="DOP853", rtol=1e-11, atol=1e-12,
                    t_eval=np.linspace(0.0, 0.1, 21))  # it falls under gravity towards the workspace border
    assert sol.success
    energies = [0.5 * x[2:] @ mass_matrix(device, x[:2]) @ x[2:] + _potential(device, x[:2]) for x in sol.y.T]
    kinetic = 0.5 * qd0 @ mass_matrix(device, qa0) @ qd0
    assert np.ptp(energies) <= 1e-8 * kinetic  # integration tolerance 1e-11 over the run
    assert np.ptp(sol.y[0]) > 0.1  # it actually moved
