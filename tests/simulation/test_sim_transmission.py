"""A compliant transmission in the sampled loop, against constructions that share no code with it.

The oracle is the two-mass plant built here from its equations: the motor coordinates ``phi`` (rotors ``M_r`` and the
motors' damping ``B_m``) and the links' ``q`` (the rest of the inertia, the hand), the cables' ``K_t`` between them,
the torque on the motors and the encoders on the motors; ``control.c2d`` with a zero-order hold, the delay as
``z^-d``, the backward-difference damper as a discrete transfer function, and ``control.feedback`` with the wall's
spring; the limit is bisected on the largest pole modulus. A simulation of the continuous plant under the held
torque (SciPy's ``solve_ivp``) decays below the limit and grows above it, and a stiffer and stiffer transmission
returns the rigid limit.
"""

from __future__ import annotations

from pathlib import Path

import control
import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp
from typer.testing import CliRunner

from hapticdesign.analysis.configuration import configuration_of, handle_pose
from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.metrics.indices import Request, evaluate, evaluate_designs
from hapticdesign.analysis.sampled_loop import GRASP, Hand, SampledLoop
from hapticdesign.analysis.wall_stiffness import wall_limit
from hapticdesign.devices.design_space import design_space
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app
from hapticdesign.model.actuators import Transmission

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
PERIOD = 1e-3
LEVER = 0.2  # m: the handle 0.2 m from the joint, the wall along x
AXIS = np.array([[LEVER], [0.0], [0.0]])
X = np.array([1.0, 0.0, 0.0])

# One capstan-driven joint, Phantom-like: rotor 1.08e-6 kg m^2 through 13.3 (n^2 J_r = 1.91e-4 kg m^2), a link of
# 3.4e-3 kg m^2, the motor's damping 0.0005 N m s/rad.
ROTOR, LINK, MOTOR_DAMPING = 13.3 ** 2 * 1.08e-6, 3.4e-3, 0.0005


def _plant(rotor, link, motor_damping, link_damping, spring, link_stiffness=None):
    """The continuous two-mass plant over (phi, q, phi', q'), torque on the motors, the motors' angles out."""
    n = rotor.shape[0]
    zero = np.zeros((n, n))
    mass = np.block([[rotor, zero], [zero, link]])
    damping = np.block([[motor_damping, zero], [zero, link_damping]])
    kq = zero if link_stiffness is None else link_stiffness
    stiffness = np.block([[spring, -spring], [-spring, spring + kq]])
    a = np.block([[np.zeros((2 * n, 2 * n)), np.eye(2 * n)],
                  [-np.linalg.solve(mass, stiffness), -np.linalg.solve(mass, damping)]])
    b = np.vstack([np.zeros((2 * n, n)), np.linalg.solve(mass, np.vstack([np.eye(n), zero]))])
    c = np.hstack([np.eye(n), np.zeros((n, 3 * n))])
    return control.ss(a, b, c, np.zeros((n, n)))


def _wall_gain(plant_c, w: np.ndarray, drift: int = 0):
    """``w^T P(z) w`` of the held plant, with ``drift`` free motions along the wall (each a pole at z = 1 over a zero
    at z = 1, neither seen nor driven by the wall) divided out. Other motions the wall neither sees nor drives stay
    as common roots of the numerator and the denominator: poles the spring does not move."""
    plant = control.c2d(plant_c, PERIOD, "zoh")
    tf = control.tf(control.ss(plant.A, plant.B @ w[:, None], w[None, :] @ plant.C, 0, PERIOD))
    num, den = np.asarray(tf.num[0][0]), np.asarray(tf.den[0][0])
    for _ in range(drift):
        (num, r_num), (den, r_den) = np.polydiv(num, [1.0, -1.0]), np.polydiv(den, [1.0, -1.0])
        assert np.abs(r_num).max() <= 1e-9 * np.abs(num).max() and np.abs(r_den).max() <= 1e-9
    return control.tf(num, den, PERIOD)


def _limit(gain, delay: int, wall_damping: float = 0.0) -> float:
    """The smallest wall spring at which python-control's closed loop of ``gain`` under ``(K + B_w (1 - z^-1) / T)
    z^-d`` has a pole on or outside the unit circle (0 when it has one for every spring)."""
    def radius(k):
        law = control.tf([k + wall_damping / PERIOD, -wall_damping / PERIOD], [1.0] + [0.0] * (delay + 1), PERIOD)
        return np.abs(control.poles(control.feedback(gain, law))).max()

    trials = 10.0 ** np.arange(-6, 7)
    stable = [k for k in trials if radius(k) < 1.0]
    if not stable:  # unstable for every spring (a damper that excites the transmission's mode)
        return 0.0
    lo, hi = stable[0], 2.0 * stable[0]
    while radius(hi) < 1.0:
        lo, hi = hi, 2.0 * hi
    while hi - lo > 1e-10 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if radius(mid) < 1.0 else (lo, mid)
    return 0.5 * (lo + hi)


def _one_joint(spring: float):
    return Transmission(np.array([[ROTOR]]), np.array([[MOTOR_DAMPING]]), np.array([[spring]]))


def _joint_plant(spring: float, hand: Hand | None):
    """The 1-DOF two-mass plant with the hand on the link side (its mass, damping, stiffness times LEVER^2)."""
    hand = hand or Hand()
    r2 = LEVER ** 2
    return _plant(np.array([[ROTOR]]), np.array([[LINK + hand.mass * r2]]), np.array([[MOTOR_DAMPING]]),
                  np.array([[hand.damping * r2]]), np.array([[spring]]), np.array([[hand.stiffness * r2]]))


def _joint_limit(spring: float | None, loop: SampledLoop) -> float:
    return wall_limit(AXIS, np.array([[ROTOR + LINK]]), np.array([[MOTOR_DAMPING]]), loop, X,
                      transmission=None if spring is None else _one_joint(spring))


@pytest.mark.parametrize("hand", [None, GRASP])
@pytest.mark.parametrize("spring", [20.0, 200.0, 2000.0])
@pytest.mark.parametrize("delay, wall_damping", [(1, 0.0), (2, 0.0), (1, 0.05), (1, 2.0)])
def test_the_two_mass_joint_is_python_controls_loop(hand, spring, delay, wall_damping):
    loop = SampledLoop(period=PERIOD, delay=delay, wall_damping=wall_damping, hand=hand)
    expected = _limit(_wall_gain(_joint_plant(spring, hand), np.array([LEVER])), delay, wall_damping)
    assert _joint_limit(spring, loop) == pytest.approx(expected, rel=1e-6, abs=1e-9)


def test_a_stiff_transmission_returns_the_rigid_limit_and_a_soft_one_sets_the_wall():
    loop = SampledLoop(hand=GRASP)
    rigid = _joint_limit(None, loop)
    errors = [abs(_joint_limit(k, loop) / rigid - 1.0) for k in (1e3, 1e5, 1e7)]
    assert errors[-1] < 1e-4 and errors[0] > errors[1] > errors[2]
    assert _joint_limit(20.0, loop) < 0.5 * rigid  # with a hand, a soft transmission sets the wall


def _simulated_peaks(stiffness: float, spring: float, seconds: float = 3.0) -> tuple[float, float]:
    """The largest motor excursion in the first and the last half second of the wall's loop (one sample of delay,
    no damper, the hand of GRASP on the link side), the continuous two-mass plant integrated by SciPy across each
    held torque from a push of the link."""
    r2 = LEVER ** 2
    link, link_damping, link_stiffness = LINK + GRASP.mass * r2, GRASP.damping * r2, GRASP.stiffness * r2
    k_joint = stiffness * r2

    def rates(_t, x, held):
        phi, q, dphi, dq = x
        cable = spring * (phi - q)
        return [dphi, dq, (held - MOTOR_DAMPING * dphi - cable) / ROTOR,
                (cable - link_damping * dq - link_stiffness * q) / link]

    state, held, sensed_before = np.array([0.0, 0.0, 0.0, 0.05]), 0.0, 0.0
    peaks = []
    for _ in range(int(round(seconds / PERIOD))):
        sensed = state[0]
        state = solve_ivp(rates, (0.0, PERIOD), state, args=(held,), rtol=1e-10, atol=1e-14).y[:, -1]
        held, sensed_before = -k_joint * sensed_before, sensed  # the torque from the sample before (delay 1)
        peaks.append(abs(state[0]))
    half = int(round(0.5 / PERIOD))
    return max(peaks[:half]), max(peaks[-half:])


def test_a_simulation_decays_below_the_limit_and_grows_above_it():
    spring = 20.0
    limit = _joint_limit(spring, SampledLoop(hand=GRASP))
    first, last = _simulated_peaks(0.7 * limit, spring)
    assert last < 0.6 * first
    first, last = _simulated_peaks(1.4 * limit, spring)
    assert last > 2.0 * first


@pytest.fixture(scope="module")
def five_bar():
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    point = np.array([0.01, 0.0, 0.19])
    q = handle_pose(device, point).q
    return device, point, configuration_of(device).jacobian(q)[:3], mass_matrix(device, q)


@pytest.mark.parametrize("hand", [None, GRASP])
def test_the_n_joint_compliant_loop_is_python_controls(five_bar, hand):
    """Two joints, each a capstan (rotor 2e-5 kg m^2, 0.004 N m s/rad at the motor, 300 N m/rad), every joint free
    under a wall along a skew direction, with and without the hand on the link side."""
    _, _, jv, h = five_bar
    rotor, bm, kt = 2e-5 * np.eye(2), 0.004 * np.eye(2), 300.0 * np.eye(2)
    u = np.array([0.6, 0.0, 0.8])
    hand_ = hand or Hand()
    jtj = jv.T @ jv
    plant = _plant(rotor, h - rotor + hand_.mass * jtj, bm, hand_.damping * jtj, kt, hand_.stiffness * jtj)
    mine = wall_limit(jv, h, bm, SampledLoop(hand=hand), u, transmission=Transmission(rotor, bm, kt))
    w = jv.T @ u
    assert mine == pytest.approx(_limit(_wall_gain(plant, w, 1 if hand is None else 0), 1), rel=1e-6)


def _compliant_file(tmp_path: Path, stiffness: float | None) -> Path:
    data = yaml.safe_load((EXAMPLES / "five-bar.yaml").read_text())
    data["g"] = 0.0  # no gravity: the oracle's plant has none
    data["actuators"] = [{"joint": name, "rotor_inertia": 2e-6, "gear_ratio": 10.0, "damping": 0.004,
                          **({} if stiffness is None else {"transmission_stiffness": stiffness})}
                         for name in ("q1", "q2")]
    path = tmp_path / f"five-bar-{stiffness}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_a_device_files_transmission_reaches_the_kmax_index(tmp_path, five_bar):
    _, point, _, _ = five_bar
    compliant = load_device_file(_compliant_file(tmp_path, 300.0))
    q = handle_pose(compliant, point).q
    jv, h = configuration_of(compliant).jacobian(q)[:3], mass_matrix(compliant, q)
    rotor = 100 * 2e-6 * np.eye(2)
    u = np.array([0.6, 0.0, 0.8])
    value = evaluate(compliant, point[None], [Request("kmax", {"direction": u}, "along")]).values["along"][0]
    plant = _plant(rotor, h - rotor, 0.004 * np.eye(2), 0.01 * np.eye(2), 300.0 * np.eye(2))  # the joints' 0.01
    assert value == pytest.approx(_limit(_wall_gain(plant, jv.T @ u, 1), 1), rel=1e-6)


def test_a_study_varies_the_transmission_through_the_batched_path(tmp_path, five_bar):
    """A study's designs (lengths and the cables' stiffness as variables) through the compiled batch give what each
    design's own device gives, and the softer cable its own limit."""
    _, point, _, _ = five_bar
    path = _compliant_file(tmp_path, 300.0)
    space = design_space(path, ["l1", "actuators.q1.transmission_stiffness", "actuators.q2.transmission_stiffness"])
    designs = [{"l1": 0.1, "actuators.q1.transmission_stiffness": k, "actuators.q2.transmission_stiffness": k}
               for k in (50.0, 300.0, 3000.0)]
    batched = evaluate_designs(space, designs, point[None], ["kmax"])
    assert space.cache.get("batch"), "the compiled path serves the transmission"
    one = [evaluate(space.device(d), point[None], ["kmax"]).values["kmax"][0] for d in designs]
    np.testing.assert_allclose([b.values["kmax"][0] for b in batched], one, rtol=1e-9)
    assert len(set(np.round(one, 6))) == 3


def test_a_transmission_on_some_motors_only_is_refused(tmp_path):
    path = _compliant_file(tmp_path, 300.0)
    data = yaml.safe_load(path.read_text())
    del data["actuators"][1]["transmission_stiffness"]
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(UserError, match="transmission_stiffness"):
        load_device_file(path).transmission


@pytest.mark.parametrize("value, fragment", [(".nan", "expected a finite number"), (".inf", "expected a finite number"),
                                             ("-1", "greater than 0"), ("0", "greater than 0"),
                                             ("'abc'", "must be a number"), ("1e308", "the motors resonate"),
                                             ("[1, 2]", "transmission_stiffness")])
def test_a_hostile_transmission_stiffness_is_one_line(tmp_path, value, fragment):
    """A stiffness that is no number, not positive, or so large that the loop's exact discretization would overflow
    (the rigid model is its answer there): one line, exit 2, through the spec sheet."""
    text = (EXAMPLES / "phantom-premium.yaml").read_text().replace(
        "encoder_cpr: 1024, coulomb", f"encoder_cpr: 1024, transmission_stiffness: {value}, coulomb")
    path = tmp_path / "phantom.yaml"
    path.write_text(text)
    result = CliRunner().invoke(app, ["spec", "--device", str(path), "--no-simulate", "--no-workspace", "--json"])
    lines = [line for line in result.output.strip().splitlines() if line]
    assert result.exit_code == 2 and len(lines) == 1 and lines[0].startswith("error:"), result.output
    assert fragment in lines[0]


@pytest.mark.parametrize("name", ["nope", "ｌｉｇｈｔ", "", "<img src=x>"])
def test_an_unknown_hand_is_one_line(name):
    result = CliRunner().invoke(app, ["spec", "--device", str(EXAMPLES / "phantom-premium.yaml"), "--no-simulate",
                                      "--no-workspace", "--json", "--hand", name])
    lines = [line for line in result.output.strip().splitlines() if line]
    assert result.exit_code == 2 and len(lines) == 1 and "unknown hand" in lines[0], result.output
