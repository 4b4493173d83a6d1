"""The example device files of examples/devices/ against independent references."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from hapticdesign.analysis.dynamics.device import (
    coriolis_centrifugal,
    coriolis_matrix,
    forward_dynamics,
    gravity,
    inverse_dynamics,
    mass_matrix,
)
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.devices.loading import resolve_device
from hapticdesign.devices.registry import preset

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(b).max())


# -- Phantom 3-DOF: the file reproduces the built-in preset ------------------------------------------
@pytest.fixture(scope="module")
def phantoms():
    return load_device_file(EXAMPLES / "phantom-3dof.yaml"), preset("phantom-3dof")


def test_phantom_file_has_the_preset_parameters(phantoms):
    from_file, built_in = phantoms
    assert from_file.parameter_names() == built_in.parameter_names()
    assert dict(from_file.params) == dict(built_in.params)
    assert from_file.damping == built_in.damping
    assert from_file.mechanism.end_effector == built_in.mechanism.end_effector


def test_phantom_file_reproduces_preset_dynamics(phantoms):
    from_file, built_in = phantoms
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (20, 3))
    np.testing.assert_allclose(mass_matrix(from_file, q), mass_matrix(built_in, q), rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(coriolis_centrifugal(from_file, q), coriolis_centrifugal(built_in, q), rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(gravity(from_file, q), gravity(built_in, q), rtol=1e-13, atol=1e-16)


def test_phantom_file_follows_parameter_overrides(phantoms):
    from_file, built_in = phantoms
    changes = {"l2": 0.25, "l3a": 0.04, "m3a": 0.3, "g": 9.0}
    a, b = from_file.with_params(changes), built_in.with_params(changes)
    q = np.random.default_rng(4).uniform(-np.pi, np.pi, (5, 3))
    np.testing.assert_allclose(mass_matrix(a, q), mass_matrix(b, q), rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(gravity(a, q), gravity(b, q), rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(
        a.mechanism.frame_pose(q[0], "stylus"), b.mechanism.frame_pose(q[0], "stylus"), atol=1e-15
    )


def test_six_dof_phantom_file_reproduces_the_preset():
    """examples/devices/phantom-6dof.yaml (the 6-DOF LN study's device) against the built-in preset."""
    from_file, built_in = load_device_file(EXAMPLES / "phantom-6dof.yaml"), preset("phantom-6dof")
    assert dict(from_file.params) == dict(built_in.params)
    assert from_file.body_names == built_in.body_names and from_file.damping == built_in.damping
    q = np.random.default_rng(6).uniform(-np.pi, np.pi, (20, 6))
    for quantity in (mass_matrix, coriolis_centrifugal, gravity):
        np.testing.assert_allclose(quantity(from_file, q), quantity(built_in, q), rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(from_file.mechanism.frame_pose(q[0], "stylus"), built_in.mechanism.frame_pose(q[0], "stylus"),
                               atol=1e-15)


def test_loading_twice_gives_an_equal_builder():
    a = load_device_file(EXAMPLES / "phantom-3dof.yaml")
    b = load_device_file(EXAMPLES / "phantom-3dof.yaml")
    assert a.builder == b.builder and hash(a.builder) == hash(b.builder)


# -- 3R arm: against Pinocchio built from the seed's DH equations -------------------------------------
def _rx(angle: float) -> np.ndarray:
    return Rotation.from_euler("x", angle).as_matrix()


def _rz(angle: float) -> np.ndarray:
    return Rotation.from_euler("z", angle).as_matrix()


def _pinocchio_from_dh(rows, bodies, g: float) -> pin.Model:
    """A DH chain in seed 000's convention, written with Pinocchio's API.

    Frame i = frame i-1 . tz(s_i) Rz(theta_i) tx(a_i) Rx(alpha_i) (eq. 2.26); rows are
    ``(kind, a, alpha, s, theta)`` with the joint variable's constant offset in ``s`` (prismatic) or
    ``theta`` (revolute). Revolute: Pinocchio's joint frame is J_i = frame i-1 . tz(s_i) Rz(theta_i) Rz(q_i)
    and the seed's body frame (origin P_(i-1), orientation C(0,i), Table 2.3) is J_i . tz(-s_i) Rx(alpha_i).
    Prismatic: J_i = frame i-1 . Rz(theta_i) tz(s_i) tz(q_i), and the body frame is J_i . Rx(alpha_i).
    """
    model = pin.Model()
    model.gravity = pin.Motion(np.array([0, 0, -g, 0, 0, 0], dtype=float))
    parent, previous = 0, (0.0, 0.0)
    for (kind, a, alpha, s, theta), body in zip(rows, bodies):
        to_previous_link = pin.SE3(_rx(previous[1]), np.array([previous[0], 0.0, 0.0]))
        placement = to_previous_link * pin.SE3(_rz(theta), np.array([0.0, 0.0, s]))
        joint = pin.JointModelRZ() if kind == "R" else pin.JointModelPZ()
        parent = model.addJoint(parent, joint, placement, f"joint{len(model.joints)}")
        rot = _rx(alpha)
        com = np.array([0.0, 0.0, -s if kind == "R" else 0.0]) + rot @ body.r
        model.appendBodyToJoint(parent, pin.Inertia(body.m, com, rot @ body.inertia_at_com @ rot.T), pin.SE3.Identity())
        previous = (a, alpha)
    return model


def test_arm_3r_matches_pinocchio():
    device = resolve_device(device_file=EXAMPLES / "arm-3r.toml", strict=True)
    p = device.params
    rows = [("R", 0.0, np.pi / 2, p["d1"], 0.0), ("R", p["l2"], 0.0, 0.0, 0.0), ("R", p["l3"], 0.0, 0.0, -np.pi / 6)]
    _compare_with_pinocchio(device, _pinocchio_from_dh(rows, [device.body(b) for b in device.body_names], p["g"]))
    assert device.damping == (0.05, 0.05, 0.02)


RPR = """
name: rpr
parameters: {h: 0.2, d0: 0.1, l3: 0.25}
joints: [{name: q1}, {name: d2, type: prismatic}, {name: q3}]
dh:
  - {alpha: -pi/2, s: h, theta: q1}
  - {alpha: pi/2, s: d2 + d0, theta: pi/3}
  - {a: l3, alpha: 0, theta: q3}
bodies:
  - {name: 1, frame: body1, m: 0.7, ry: 0.02, rz: 0.1, Ixx: 0.003, Iyy: 0.002, Izz: 0.0025, Ixy: 0.0002}
  - {name: 2, frame: body2, m: 0.5, rx: 0.01, rz: -0.05, Ixx: 0.002, Iyy: 0.0018, Izz: 0.0006, Iyz: -0.0001}
  - {name: 3, frame: body3, m: 0.3, rx: 0.12, ry: 0.01, Ixx: 0.0002, Iyy: 0.0019, Izz: 0.002, Ixz: 0.00005}
"""


def test_dh_with_a_prismatic_row_matches_pinocchio(tmp_path):
    path = tmp_path / "rpr.yaml"
    path.write_text(RPR)
    device = resolve_device(device_file=path, strict=True)
    p = device.params
    rows = [
        ("R", 0.0, -np.pi / 2, p["h"], 0.0), ("P", 0.0, np.pi / 2, p["d0"], np.pi / 3), ("R", p["l3"], 0.0, 0.0, 0.0)
    ]
    _compare_with_pinocchio(device, _pinocchio_from_dh(rows, [device.body(b) for b in device.body_names], p["g"]))


def _compare_with_pinocchio(device, model: pin.Model) -> None:
    data = model.createData()
    rng = np.random.default_rng(11)
    for _ in range(10):
        q, qd, qdd = rng.uniform(-np.pi, np.pi, 3), rng.normal(size=3), rng.normal(size=3)
        mass = pin.crba(model, data, q)
        mass = np.triu(mass) + np.triu(mass, 1).T
        assert _relative(mass_matrix(device, q), mass) < 1e-9
        assert _relative(gravity(device, q), pin.computeGeneralizedGravity(model, data, q)) < 1e-9
        assert _relative(inverse_dynamics(device, q, qd, qdd), pin.rnea(model, data, q, qd, qdd)) < 1e-9
        coriolis = pin.rnea(model, data, q, qd, np.zeros(3)) - pin.computeGeneralizedGravity(model, data, q)
        assert _relative(coriolis_matrix(device, q, qd) @ qd, coriolis) < 1e-9


# -- 2-DOF parallelogram: properties of a closed loop -------------------------------------------------
@pytest.fixture(scope="module")
def pantograph():
    return resolve_device(device_file=EXAMPLES / "pantograph-2dof.yaml", strict=True)


def test_pantograph_loop_closes_and_stays_parallel(pantograph):
    mech, p = pantograph.mechanism, pantograph.params
    for q in np.random.default_rng(5).uniform(-np.pi, np.pi, (10, 2)):
        a, b, c, d = (mech.frame_pose(q, f) for f in "abcd")
        end_of_c = c[:3, 3] + p["la"] * c[:3, 0]
        joint_on_d = d[:3, 3] + p["lb"] * d[:3, 0]
        np.testing.assert_allclose(end_of_c, joint_on_d, atol=1e-14)
        np.testing.assert_allclose(c[:3, :3], a[:3, :3], atol=1e-14)
        np.testing.assert_allclose(d[:3, :3], b[:3, :3], atol=1e-14)


def _body_states(device, q: np.ndarray, qd: np.ndarray, h: float = 1e-6):
    """(mass centre, its velocity, angular velocity in body axes) of every body, by central differences."""
    mech = device.mechanism
    out = []
    for name, attach in zip(device.body_names, mech.bodies):
        r = device.body(name).r
        poses = [mech.frame_pose(q + s * h * qd, attach.frame) for s in (-1.0, 0.0, 1.0)]
        com = [t[:3, :3] @ r + t[:3, 3] for t in poses]
        rate = (poses[2][:3, :3] - poses[0][:3, :3]) / (2 * h)
        omega = poses[1][:3, :3].T @ rate
        out.append((com[1], (com[2] - com[0]) / (2 * h), np.array([omega[2, 1], omega[0, 2], omega[1, 0]])))
    return out


def test_pantograph_kinetic_and_potential_energy_from_kinematics(pantograph):
    """0.5 qd' H qd and G = dV/dq against energies summed over the bodies from forward kinematics."""
    g = np.array([0.0, 0.0, -pantograph.params["g"]])
    rng = np.random.default_rng(6)

    def potential(q):
        states = _body_states(pantograph, q, np.zeros(2))
        return -sum(pantograph.body(n).m * g @ com for n, (com, _, _) in zip(pantograph.body_names, states))

    for _ in range(5):
        q, qd = rng.uniform(-np.pi, np.pi, 2), rng.normal(size=2)
        kinetic = 0.0
        for name, (_, v, w) in zip(pantograph.body_names, _body_states(pantograph, q, qd)):
            body = pantograph.body(name)
            kinetic += 0.5 * body.m * v @ v + 0.5 * w @ body.inertia_at_com @ w
        assert abs(0.5 * qd @ mass_matrix(pantograph, q) @ qd - kinetic) < 1e-8 * kinetic
        h = 1e-6
        grad = [(potential(q + h * e) - potential(q - h * e)) / (2 * h) for e in np.eye(2)]
        assert _relative(gravity(pantograph, q), np.array(grad)) < 1e-7


def test_pantograph_energy_balance_with_damping(pantograph):
    """E(t) - E(0) = -int qd' D qd dt along a free motion with the file's joint damping."""
    damping = np.diag(pantograph.damping)

    def energy(q, qd):
        com_heights = [com[2] for com, _, _ in _body_states(pantograph, q, np.zeros(2))]
        masses = [pantograph.body(n).m for n in pantograph.body_names]
        return 0.5 * qd @ mass_matrix(pantograph, q) @ qd + pantograph.params["g"] * np.dot(masses, com_heights)

    def rhs(_, x):
        q, qd = x[:2], x[2:4]
        qdd = forward_dynamics(pantograph, q, qd, -damping @ qd)
        return np.concatenate([qd, qdd, [qd @ damping @ qd]])

    x0 = np.array([0.3, -1.2, 2.0, -1.0, 0.0])
    sol = solve_ivp(rhs, (0.0, 1.0), x0, method="DOP853", rtol=1e-11, atol=1e-12)
    assert sol.success
    start, end = sol.y[:, 0], sol.y[:, -1]
    dissipated = end[4]
    assert dissipated > 1e-3
    change = energy(end[:2], end[2:4]) - energy(start[:2], start[2:4])
    scale = abs(energy(start[:2], start[2:4]) - energy(np.zeros(2), np.zeros(2)))
    assert abs(change + dissipated) < 1e-7 * scale
