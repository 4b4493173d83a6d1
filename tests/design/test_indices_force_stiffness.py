"""The force, stiffness, frequency, wall, LN and mass indices against independent computations.

Oracles: SciPy's ``linprog`` (the force polytope's Chebyshev ball, from a finite-difference Jacobian and the motor
ratings of the file); Euler-Bernoulli cantilevers in series (a planar two-link arm of elastic links, rotations of
the handle held: ``K_C[:3, :3]``); the kinetic energy and dissipated power of handle velocities (joint rates from
the inverse kinematics) for the Cartesian mass and damping; the exact sampled-loop limit of the 1-DOF mass-damper
built from them; seed 000's Appendix C designs of LN = 0; the masses written in the device file.
"""

from __future__ import annotations

import json
import math
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.metrics.dynamic import modes
from hapticdesign.devices.device_file import device_from_mapping, load_device_file
from hapticdesign.devices.registry import preset
from hapticdesign.analysis.metrics.indices import Request, evaluate
from tests.helpers.handle_energy import cartesian_mass
from tests.helpers.planar_arm import planar_arm

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
PLANE = np.eye(3)[:, [0, 2]]  # the arm and the five-bar move in the base x-z plane
ARM_POINTS = np.array([[0.1, 0.0, 0.1], [0.12, 0.0, 0.05], [0.05, 0.0, 0.15]])


def _fd_jacobian(device, q_a: np.ndarray, h: float = 1e-6) -> np.ndarray:
    space = configuration_of(device)
    return np.column_stack([(space.pose(q_a + h * e)[:3, 3] - space.pose(q_a - h * e)[:3, 3]) / (2 * h)
                            for e in np.eye(len(q_a))])


def _chebyshev_radius(g: np.ndarray, limits: np.ndarray) -> float:
    """Largest ball ``{c + r e}`` in ``{f : |g_k . f| <= l_k}``: maximize r over (c, r) (linprog)."""
    norms = np.linalg.norm(g, axis=1)
    a_ub = np.vstack([np.column_stack([g, norms]), np.column_stack([-g, norms])])
    k = g.shape[1]
    lp = linprog(np.r_[np.zeros(k), -1.0], A_ub=a_ub, b_ub=np.r_[limits, limits],
                 bounds=[(None, None)] * k + [(0, None)], method="highs")
    return -lp.fun


@pytest.mark.parametrize("torque", ["continuous", "peak"])
def test_force_is_the_chebyshev_ball_of_the_force_polytope(torque):
    arm = planar_arm()
    arm["actuators"][0]["torque_peak"], arm["actuators"][1]["torque_peak"] = 0.1, 0.07
    device = device_from_mapping(arm)
    result = evaluate(device, ARM_POINTS, [Request("force", {"torque": torque})])
    assert result.reason is None
    rated = {"continuous": (0.03, 0.02), "peak": (0.1, 0.07)}[torque]
    limits = np.array([10.0 * rated[0], 8.0 * rated[1]])  # n_k tau_k, one motor per joint
    q_a, _ = configuration_of(device).reach(ARM_POINTS)
    for value, q in zip(result.values["force"], q_a):
        g = _fd_jacobian(device, q).T @ PLANE  # joint torques of a force f in the plane: J_v^T U f
        assert value == pytest.approx(_chebyshev_radius(g, limits), rel=1e-7)


def test_force_needs_motor_ratings():
    result = evaluate(load_device_file(EXAMPLES / "five-bar.yaml"), np.array([[0.0, 0.0, 0.18]]), ["force"])
    assert "needs one motor per actuated coordinate" in result.reason


def _planar_compliance(l1, l2, q1, elbow, rigid1, rigid2) -> np.ndarray:
    """In-plane compliance (x, z, rotation) of the tip of two cantilevers in series (Euler-Bernoulli), each clamped at
    its start: end displacement ``F_a L / EA`` along, ``F_t L^3 / (3 EI) + M L^2 / (2 EI)`` across, rotation
    ``F_t L^2 / (2 EI) + M L / (EI)``."""
    a1 = np.array([math.cos(q1), math.sin(q1)])
    a2 = np.array([math.cos(q1 + elbow), math.sin(q1 + elbow)])
    perp = lambda v: np.array([-v[1], v[0]])
    cross = lambda u, v: u[0] * v[1] - u[1] * v[0]

    def beam(axis, length, rigid, force, moment):
        ea, ei = rigid
        ft = force @ perp(axis)
        shift = axis * (force @ axis) * length / ea + perp(axis) * (ft * length**3 / (3 * ei)
                                                                   + moment * length**2 / (2 * ei))
        return shift, ft * length**2 / (2 * ei) + moment * length / ei

    columns = []
    for load in np.eye(3):
        force, moment = load[:2], load[2]
        shift2, turn2 = beam(a2, l2, rigid2, force, moment)
        r = l2 * a2
        shift1, turn1 = beam(a1, l1, rigid1, force, moment + cross(r, force))
        columns.append(np.r_[shift1 + turn1 * perp(r) + shift2, turn1 + turn2])
    return np.column_stack(columns)


def _tube(D, d, E=68.9e9):
    return E * math.pi * (D**2 - d**2) / 4, E * math.pi * (D**4 - d**4) / 64


def test_stiffness_and_frequency_of_a_two_link_arm_of_elastic_links():
    device = device_from_mapping(planar_arm(0.2, 0.15, 2.0, link_bodies=True))
    result = evaluate(device, ARM_POINTS, ["stiffness", "frequency"])
    assert result.reason is None
    q_a, _ = configuration_of(device).reach(ARM_POINTS)
    for k, (q, point) in enumerate(zip(q_a, ARM_POINTS)):
        compliance = _planar_compliance(0.2, 0.15, q[0], 2.0 + q[1], _tube(0.012, 0.010), _tube(0.008, 0.0))
        held = np.linalg.inv(compliance)[:2, :2]  # the handle's rotation held: K_C[:3, :3] in the plane
        assert result.values["stiffness"][k] == pytest.approx(np.linalg.eigvalsh(held)[0], rel=1e-9)
        lam = cartesian_mass(device, point, PLANE)
        assert result.values["frequency"][k] == pytest.approx(modes(lam, held).frequencies[0], rel=1e-6)


def test_kmax_worst_direction_is_below_every_direction():
    """The worst direction's limit is at or below the limit along x, z and the diagonal (each the n-joint loop,
    checked against python-control's closed loop in tests/simulation/test_sim_handle_loop.py)."""
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    point = np.array([0.01, 0.0, 0.19])
    options = {"period": 0.0005, "delay": 2, "wall_damping": 0.5, "velocity": "sampled"}
    requests = [Request("kmax", {**options, "direction": PLANE @ u}, name) for name, u in
                (("x", [1, 0]), ("z", [0, 1]), ("diagonal", [1, 1]))] + [Request("kmax", options)]
    result = evaluate(device, point[None], requests)
    assert result.reason is None
    assert result.values["kmax"][0] <= min(result.values[k][0] for k in ("x", "z", "diagonal")) * (1 + 1e-9)


def test_kmax_refuses_a_direction_off_the_plane():
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    result = evaluate(device, np.array([[0.0, 0.0, 0.18]]), [Request("kmax", {"direction": [0.0, 1.0, 0.0]})])
    assert "not one the handle moves in" in result.reason


def test_ln_vanishes_for_the_seeds_linear_designs():
    designs = json.loads(resources.files("hapticdesign.studies").joinpath("data/seed000_appendix_c_designs.json")
                         .read_text())
    phantom = preset("phantom-3dof")
    point = configuration_of(phantom).pose(np.array([0.1, 0.3, -0.2]))[:3, 3]
    unbalanced = phantom.with_params({"r3x": phantom.params["r3x"] + 0.05})  # a mass centre off: not linear
    assert evaluate(unbalanced, point[None], ["ln"]).values["ln"][0] > 1e-6
    for design in designs[:3]:
        value = evaluate(phantom.with_params(design["params"]), point[None], ["ln"]).values["ln"][0]
        assert value < 1e-12


def test_mass_counts_the_moving_bodies():
    five_bar = load_device_file(EXAMPLES / "five-bar.yaml")
    assert evaluate(five_bar, np.array([[0.0, 0.0, 0.18]]), ["mass"]).values["mass"][0] == pytest.approx(0.215)
    arm = planar_arm()
    arm["frames"].append({"name": "stator", "transforms": [{"tz": -0.02}]})
    arm["bodies"].append({"name": "s", "frame": "stator", "m": 0.5})
    result = evaluate(device_from_mapping(arm), ARM_POINTS[:1], ["mass"])
    assert result.values["mass"][0] == pytest.approx(0.3 + 0.2)  # the stator on the base does not move
