"""Actuators, joint limits and point masses in device files, against closed forms and brute force.

References written here, independent of the code under test: the pendulum and the planar 2R arm
with point masses (textbook Lagrangian dynamics, e.g. Spong, Hutchinson & Vidyasagar 2006, §7.3),
the reflected inertia ``n^2 J_r`` of a motor behind a transmission, and the Linearity Number
(seed 000 eq. 3.1-3.4) averaged over the region by composite Simpson quadrature on a fine grid.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import (
    coriolis_centrifugal,
    dynamics_of,
    forward_dynamics,
    gravity,
    mass_matrix,
)
from hapticdesign.devices.device_file import device_from_mapping, load_device_file
from hapticdesign.devices.registry import preset
from hapticdesign.devices.urdf import device_from_urdf
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
runner = CliRunner()
G = 9.81
R_TIP, M_TIP, M_MID, R_MID = 0.2, 0.02, 0.05, 0.07
J_ROTOR, RATIO = 1.0e-6, 11.6


def pendulum(**extra) -> dict:
    """A link turning about the base's -y axis in the x-z plane: tip height ``r sin q``.

    Two point masses: ``handle`` (0.02 kg) at the tip frame's origin, ``weight`` (0.05 kg) given by its
    mass-centre offset 0.07 m on the arm frame (the parallel-axis route); a motor behind an 11.6 ratio.
    """
    spec = {
        "name": "pendulum",
        "parameters": {"r": R_TIP},
        "joints": [{"name": "q1", "limits": [-1.0, 1.0], "damping": 0.01}],
        "frames": [{"name": "arm", "transforms": [{"Rx": "pi/2"}, {"Rz": "q1"}]},
                   {"name": "tip", "parent": "arm", "transforms": [{"tx": "r"}]}],
        "bodies": [{"name": "handle", "frame": "tip", "m": M_TIP},
                   {"name": "weight", "frame": "arm", "m": M_MID, "rx": R_MID}],
        "actuators": [{"joint": "q1", "rotor_inertia": J_ROTOR, "gear_ratio": RATIO, "coulomb": 0.005,
                       "damping": 0.001}],
        "end_effector": "tip",
    }
    spec.update(extra)
    return spec


def pendulum_h() -> float:
    return M_TIP * R_TIP**2 + M_MID * R_MID**2 + RATIO**2 * J_ROTOR


def pendulum_g(q: float) -> float:
    return G * math.cos(q) * (M_TIP * R_TIP + M_MID * R_MID)


@pytest.fixture(scope="module")
def pendulum_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("pendulum") / "pendulum.json"
    path.write_text(json.dumps(pendulum()))
    return path


# -- point masses and actuators: closed forms ----------------------------------------------------------
def test_point_masses_and_rotor_give_the_closed_form_pendulum(pendulum_file):
    for q, qd, qdd in [(0.3, 1.0, 2.0), (-0.8, -2.0, 0.5), (0.0, 0.0, -1.0)]:
        result = runner.invoke(app, ["dynamics", "--device", str(pendulum_file), "--q", str(q), "--qd", str(qd),
                                     "--qdd", str(qdd), "--json"])
        assert result.exit_code == 0, result.output
        out = json.loads(result.stdout)
        assert out["H"][0][0] == pytest.approx(pendulum_h(), rel=1e-12)
        assert out["G"][0] == pytest.approx(pendulum_g(q), rel=1e-12, abs=1e-15)
        assert out["tau"][0] == pytest.approx(pendulum_h() * qdd + pendulum_g(q), rel=1e-12, abs=1e-15)
        assert result.stderr == ""  # inside the limits: no warning


def test_forward_dynamics_divides_by_links_plus_reflected_inertia(pendulum_file):
    device = load_device_file(pendulum_file)
    q, tau = np.array([0.4]), np.array([0.01])
    expected = (tau[0] - pendulum_g(0.4)) / pendulum_h()
    assert forward_dynamics(device, q, np.zeros(1), tau)[0] == pytest.approx(expected, rel=1e-12)


def test_simulation_tables_carry_the_reflected_inertia(pendulum_file):
    """The rendering simulation evaluates ``basis(q) @ coefficients_for(pi)`` (simulation/tables.py)."""
    device = load_device_file(pendulum_file)
    model = dynamics_of(device)
    entries = model.basis(np.array([[0.25]])) @ model.coefficients_for(device.standard_parameters())
    assert entries[0, model.slice_h][0] == pytest.approx(pendulum_h(), rel=1e-12)
    assert entries[0, model.slice_g][0] == pytest.approx(pendulum_g(0.25), rel=1e-12)


def test_damping_adds_and_coulomb_is_carried(pendulum_file):
    device = load_device_file(pendulum_file)
    assert device.damping == pytest.approx((0.011,))
    friction_map, coulomb = device.friction
    assert friction_map.tolist() == [[1.0]] and coulomb == pytest.approx([0.005])
    assert device.reflected_inertia == pytest.approx(np.array([[RATIO**2 * J_ROTOR]]))
    assert device.joint_limits() == ((-1.0, 1.0),)
    overridden = device.with_params({"mhandle": 0.03})  # parameter overrides keep actuators and limits
    assert overridden.actuators == device.actuators and overridden.limits == device.limits
    assert mass_matrix(overridden, np.zeros(1))[0, 0] == pytest.approx(pendulum_h() + 0.01 * R_TIP**2, rel=1e-12)


def test_symbolic_equations_include_the_reflected_inertia(pendulum_file):
    from fractions import Fraction

    result = runner.invoke(app, ["eom", "--device", str(pendulum_file), "--symbolic", "none", "--part", "H",
                                 "--format", "text"])
    assert result.exit_code == 0, result.output
    label, value = result.stdout.strip().split(" = ")
    assert label == "H[1,1]"
    assert float(Fraction(value)) == pytest.approx(pendulum_h(), rel=1e-12)


def test_point_mass_passes_the_consistency_check_and_a_massless_inertia_does_not():
    device = device_from_mapping(pendulum())
    assert device.check(strict=True) == []
    bad = pendulum(bodies=[{"name": "handle", "frame": "tip", "m": 0.0, "Ixx": 1e-6, "Iyy": 1e-6, "Izz": 1e-6}])
    with pytest.raises(UserError, match="massless body with non-zero inertia"):
        device_from_mapping(bad)


def test_point_mass_metrics_closed_form(pendulum_file):
    """1 DOF: the task Jacobian is the tip speed per rad, r; M_C = H / r^2 (seed 001 eq. 4.90)."""
    result = runner.invoke(app, ["metrics", "--device", str(pendulum_file), "--q", "0.5", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert abs(out["jacobian"][0][0]) == pytest.approx(R_TIP, rel=1e-12)
    assert out["cartesian_inertia"][0][0] == pytest.approx(pendulum_h() / R_TIP**2, rel=1e-12)


# -- limits: warnings and errors ------------------------------------------------------------------------
def test_pose_outside_the_limits_is_computed_with_one_warning(pendulum_file):
    result = runner.invoke(app, ["dynamics", "--device", str(pendulum_file), "--q", "1.5", "--json"])
    assert result.exit_code == 0
    assert json.loads(result.stdout)["G"][0] == pytest.approx(pendulum_g(1.5), rel=1e-12)
    assert result.stderr.count("\n") == 1 and result.stderr.startswith("warning: q1 = 1.5 is outside its limits")
    quiet = runner.invoke(app, ["dynamics", "--device", str(pendulum_file), "--q", "1.5", "--quiet"])
    assert quiet.exit_code == 0 and quiet.stderr == ""


@pytest.mark.parametrize("change, message", [
    ({"joints": [{"name": "q1", "limits": [1.0, -1.0]}]}, "joints[0] (q1).limits: need low < high"),
    ({"joints": [{"name": "q1", "limits": [0.5]}]}, "joints[0].limits"),
    ({"actuators": [{"joint": "q9"}]}, "actuators[0].joint: unknown joint 'q9'"),
    ({"actuators": [{"joint": "q1"}, {"joint": "q1"}]}, "joint q1 has two actuators"),
    ({"actuators": [{"joint": "q1", "gear_ratio": 0}]}, "actuators[0].gear_ratio"),
    ({"actuators": [{"joint": "q1", "rotor_inertia": -1e-6}]}, "actuators[0].rotor_inertia"),
    ({"actuators": [{"joint": "q1", "inertia": 1e-6}]}, "actuators[0].inertia: unknown key"),
    ({"actuators": [{"joint": "q1", "torque_continuous": -0.03}]}, "actuators[0].torque_continuous"),
    ({"actuators": [{"joint": "q1", "torque_peak": 0}]}, "actuators[0].torque_peak"),
    ({"actuators": [{"joint": "q1", "torque_continuous": 0.03, "torque_peak": 0.01}]},
     "actuators[0].torque_peak: 0.01 N m is below torque_continuous"),
    ({"actuators": [{"joint": "q1", "encoder_cpr": 0}]}, "actuators[0].encoder_cpr"),
    ({"actuators": [{"joint": "q1", "encoder_cpr": 512.5}]}, "actuators[0].encoder_cpr"),
    ({"actuators": [{"joint": "q1", "encoder_cpr": 512, "quadrature": 3}]}, "actuators[0].quadrature"),
])
def test_bad_limits_and_actuators_are_one_line_errors(tmp_path, change, message):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(pendulum(**change)))
    result = runner.invoke(app, ["dynamics", "--device", str(path), "--q", "0"])
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and message in result.stderr, result.stderr


def test_motor_ratings_and_encoder_reach_the_model(tmp_path):
    """1024 lines x4 behind an 11.6 ratio: 4096 * 11.6 / (2 pi) counts per joint radian."""
    path = tmp_path / "rated.json"
    motor = {"joint": "q1", "gear_ratio": RATIO, "torque_continuous": 0.0286, "torque_peak": 0.129, "encoder_cpr": 1024}
    path.write_text(json.dumps(pendulum(actuators=[motor])))
    (actuator,) = load_device_file(path).actuators
    assert (actuator.torque_continuous, actuator.torque_peak, actuator.encoder_cpr, actuator.quadrature) == (
        0.0286, 0.129, 1024, 4)
    assert actuator.counts_per_radian == pytest.approx(1024 * 4 * RATIO / (2 * math.pi), rel=1e-15)


URDF = """<robot name="two">
  <link name="base"/><link name="a"><inertial><mass value="0.3"/><origin xyz="0.1 0 0"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><mass value="0.2"/><origin xyz="0.1 0 0"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c"><inertial><mass value="0.1"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 1 0"/>
    <limit lower="-0.7" upper="1.1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0.2 0 0"/><axis xyz="0 1 0"/></joint>
  <joint name="j3" type="prismatic"><parent link="b"/><child link="c"/><origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.05" effort="1" velocity="1"/></joint>
</robot>"""


def test_urdf_limits_are_read_and_make_the_default_region():
    device = device_from_urdf(URDF)
    assert device.joint_limits() == ((-0.7, 1.1), None, (0.0, 0.05))
    assert device.check(strict=True) == []  # link c is a point mass
    from hapticdesign.analysis.linearity.region import Region
    from hapticdesign.analysis.linearity.form import device_form

    pi = device.standard_parameters()
    explicit = Region({0: (-0.7, 1.1), 2: (0.0, 0.05)})  # j2 continuous: the full turn
    assert device_form(device).ln(pi) == pytest.approx(device_form(device, explicit).ln(pi), rel=1e-14)


@pytest.mark.parametrize("limit, message", [
    ('<limit lower="1" upper="-1" effort="1" velocity="1"/>', "needs lower < upper"),
    ('<limit lower="a" upper="1" effort="1" velocity="1"/>', "<limit>: lower='a' is not 1 numbers"),
])
def test_bad_urdf_limits_are_one_line_errors(limit, message):
    text = URDF.replace('<limit lower="-0.7" upper="1.1" effort="1" velocity="1"/>', limit)
    with pytest.raises(UserError, match=message):
        device_from_urdf(text)


def test_urdf_limit_without_bounds_means_no_limit():
    text = URDF.replace('<limit lower="-0.7" upper="1.1" effort="1" velocity="1"/>', '<limit effort="1" velocity="1"/>')
    assert device_from_urdf(text).joint_limits()[0] is None


# -- LN over a limited region against brute force --------------------------------------------------------
L1, L2, M1, M2 = 0.25, 0.18, 0.3, 0.15


def arm_2r(limits1, limits2) -> dict:
    """A planar 2R arm in a vertical plane with point masses at the elbow and the tip, and two motors."""
    return {
        "name": "arm-2r",
        "parameters": {"l1": L1, "l2": L2},
        "joints": [{"name": "q1", **({"limits": list(limits1)} if limits1 else {})},
                   {"name": "q2", **({"limits": list(limits2)} if limits2 else {})}],
        "frames": [{"name": "upper", "transforms": [{"Rx": "pi/2"}, {"Rz": "q1"}]},
                   {"name": "elbow", "parent": "upper", "transforms": [{"tx": "l1"}, {"Rz": "q2"}]},
                   {"name": "tip", "parent": "elbow", "transforms": [{"tx": "l2"}]}],
        "bodies": [{"name": "e", "frame": "elbow", "m": M1}, {"name": "t", "frame": "tip", "m": M2}],
        "actuators": [{"joint": "q1", "rotor_inertia": 2e-6, "gear_ratio": 10}, {"joint": "q2", "rotor_inertia": 1e-6,
                                                                                "gear_ratio": 12}],
        "end_effector": "tip",
    }


def arm_entries(q1: np.ndarray, q2: np.ndarray) -> tuple[list, list, list]:
    """Closed-form H (with the motors' 10^2 x 2e-6 and 12^2 x 1e-6), C (seed form, pairs 11, 12, 22), G."""
    c2, s2 = np.cos(q2), np.sin(q2)
    h11 = M1 * L1**2 + M2 * (L1**2 + L2**2 + 2 * L1 * L2 * c2) + 100 * 2e-6
    h12 = M2 * (L2**2 + L1 * L2 * c2)
    h22 = M2 * L2**2 + 144 * 1e-6
    h = -M2 * L1 * L2 * s2  # tau1 = h (2 qd1 qd2 + qd2^2), tau2 = -h qd1^2
    zero = np.zeros_like(q1 + q2)
    g1 = G * ((M1 + M2) * L1 * np.cos(q1) + M2 * L2 * np.cos(q1 + q2))
    g2 = G * M2 * L2 * np.cos(q1 + q2)
    return [h11 + zero, h12 + zero, h12 + zero, h22 + zero], [zero, 2 * h + zero, h + zero, -h + zero, zero, zero], [g1, g2]


def simpson(low: float, high: float, intervals: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the composite Simpson rule for the mean over [low, high]."""
    x = np.linspace(low, high, intervals + 1)
    w = np.ones(intervals + 1)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    return x, w / w.sum()


def brute_force_ln(range1, range2, intervals: int = 400) -> float:
    """Seed 000 eq. 3.1-3.3 with unit weights: variances of H and G entries, mean square of C entries."""
    x1, w1 = simpson(*range1, intervals)
    x2, w2 = simpson(*range2, intervals)
    q1, q2 = np.meshgrid(x1, x2, indexing="ij")
    w = np.outer(w1, w2)
    h, c, g = arm_entries(q1, q2)

    def mean(f):
        return float(np.sum(w * f))

    return (sum(mean(e**2) - mean(e) ** 2 for e in h + g) + sum(mean(e**2) for e in c))


@pytest.mark.parametrize("limits1, limits2, region, expected1, expected2", [
    ((-0.5, 1.2), (0.3, 2.0), None, (-0.5, 1.2), (0.3, 2.0)),
    (None, (0.3, 2.0), None, (0.0, 2 * math.pi), (0.3, 2.0)),          # full turn where no limit is given
    ((-0.5, 1.2), (0.3, 2.0), "q2=-1:0.5", (-0.5, 1.2), (-1.0, 0.5)),  # --region overrides that joint only
])
def test_ln_over_limits_equals_brute_force_average(tmp_path, limits1, limits2, region, expected1, expected2):
    """Composite Simpson's error on a mean is h^4 max|f''''| / 180, with |f''''| <= 16 max|f| for entries of at most
    second harmonic order: <= 6e-9 max|f| at h = 2 pi/400. The tolerance 1e-8 sits above that bound."""
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(arm_2r(limits1, limits2)))
    args = ["ln", "--device", str(path), "--json"] + (["--region", region] if region else [])
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["ln"] == pytest.approx(brute_force_ln(expected1, expected2), rel=1e-8)


def test_torus_region_ignores_the_limits(tmp_path):
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(arm_2r((-0.5, 1.2), (0.3, 2.0))))
    result = runner.invoke(app, ["ln", "--device", str(path), "--region", "torus", "--json"])
    assert result.exit_code == 0, result.output
    full = (0.0, 2 * math.pi)
    assert json.loads(result.stdout)["ln"] == pytest.approx(brute_force_ln(full, full), rel=1e-8)


# -- the Phantom with its motors --------------------------------------------------------------------------
def test_phantom_motors_adds_the_reflected_inertia_to_the_preset():
    """Values from the file's stated source (mahilab/Phantom, PhantomModel.hpp): Jm 1.08e-6, ratios 13.3, 11.2, 11.2.
    Its third motor turns the distal link's absolute angle q3 = -(theta2 + theta3) (the literature map of
    tests/dynamics/test_literature_phantom.py), so by hand its n^2 J_r reaches H22, H23 and H33, its damping
    the same entries of the damping matrix, and its friction acts on theta2' + theta3'."""
    motors, plain = load_device_file(EXAMPLES / "phantom-3dof-motors.yaml"), preset("phantom-3dof")
    r1, r2 = 13.3**2 * 1.08e-6, 11.2**2 * 1.08e-6
    reflected = np.array([[r1, 0, 0], [0, 2 * r2, r2], [0, r2, r2]])
    q = np.random.default_rng(5).uniform(-np.pi, np.pi, (20, 3))
    np.testing.assert_allclose(mass_matrix(motors, q) - mass_matrix(plain, q), np.broadcast_to(reflected, (20, 3, 3)), rtol=0, atol=1e-15)
    np.testing.assert_allclose(coriolis_centrifugal(motors, q), coriolis_centrifugal(plain, q), rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(gravity(motors, q), gravity(plain, q), rtol=1e-13, atol=1e-16)
    assert motors.damping == pytest.approx((0.5005, 0.5010, 0.3505))
    np.testing.assert_allclose(motors.damping_matrix, [[0.5005, 0, 0], [0, 0.5010, 0.0005], [0, 0.0005, 0.3505]],
                               rtol=1e-15, atol=1e-18)
    friction_map, coulomb = motors.friction
    np.testing.assert_array_equal(np.abs(friction_map), [[1, 0, 0], [0, 1, 0], [0, 1, 1]])
    assert coulomb == pytest.approx([0.01, 0.01, 0.01])
    np.testing.assert_allclose(motors.joint_limits(), np.radians([(-90, 90), (-119, 124), (-65, 55)]), rtol=1e-15)
    assert motors.limit_warnings(np.radians([0, -100, 50])) == []  # q3 = 50 deg, inside the motor's travel
    travel = motors.limit_warnings(np.radians([0, 20, 20]))  # q3 = -40 deg, below the travel's -29 deg
    assert len(travel) == 1 and "-theta2 - theta3" in travel[0] and "travel" in travel[0]


def test_coupled_motor_in_the_simulation_equals_the_scipy_loop():
    """The kernel's friction and damping on ``a^T qd`` against the SciPy loop (tests/helpers/reference.py, which sums
    ``A^T (f tanh(A qd / v))`` with NumPy): the Phantom with its motors, type 2, 0.3 s. The friction's slope
    ``f / v`` makes the plant stiff near rest (time constant about 1e-4 s), so RK4 takes 1e-5-s steps here."""
    from hapticdesign.simulation.config import LoopConfig, Wall
    from hapticdesign.simulation.criteria import type_paths
    from hapticdesign.simulation.loop import simulate
    from tests.helpers.reference import simulate_adaptive

    motors = load_device_file(EXAMPLES / "phantom-3dof-motors.yaml")
    config = LoopConfig(duration=0.3, step=1e-5, wall=Wall(1, 20.0, equilibrium=0.01))
    paths = {0: type_paths(2, 3, 1)[0]}
    fast, slow = simulate(motors, config, paths), simulate_adaptive(motors, config, paths, rtol=1e-10, atol=1e-12)
    assert fast.status == slow.status == 0
    assert np.abs(fast.q[:, 2]).max() > 1e-3  # the third joint moved, so its motor's rate theta2' + theta3' varied
    assert np.abs(fast.q - slow.q).max() < 1e-9


def test_phantom_motors_ln_on_the_torus_equals_the_preset():
    """A constant added to H has no variance: LN (eq. 3.1-3.4) cannot see the reflected inertia."""
    from hapticdesign.analysis.linearity.region import Region
    from hapticdesign.analysis.linearity.form import device_form

    motors, plain = load_device_file(EXAMPLES / "phantom-3dof-motors.yaml"), preset("phantom-3dof").with_params(
        {"m2": 0.2, "r3z": -0.02})
    motors = motors.with_params({"m2": 0.2, "r3z": -0.02})
    torus = Region()
    assert device_form(motors, torus).ln(motors.standard_parameters()) == pytest.approx(
        device_form(plain, torus).ln(plain.standard_parameters()), rel=1e-12)


@pytest.mark.parametrize("drives, message", [
    ("theta2; import os", "cannot read"),
    ("theta9 + theta3", "unknown joint 'theta9'"),
    ("pi", "names no coordinate"),
    ("1e308*theta2 + theta3", "coefficients must be finite"),
])
def test_bad_motor_combinations_are_one_line(tmp_path, drives, message):
    text = (EXAMPLES / "phantom-3dof-motors.yaml").read_text().replace("{drives: -theta2 - theta3,",
                                                                        f"{{drives: '{drives}',")
    path = tmp_path / "motors.yaml"
    path.write_text(text)
    result = runner.invoke(app, ["dynamics", "--device", str(path), "--q", "0,0,0"])
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and message in result.stderr, result.stderr
