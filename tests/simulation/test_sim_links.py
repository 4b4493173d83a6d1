"""The links' own compliance in the wall's drive, against constructions that share no code with it.

Oracles:

- the joint-space compliance of a single elastic link on a revolute joint is the cantilever's closed form, the tip's
  ``3 E I / L^3`` times ``L^2`` (in series with a transmission's ``1 / k_t``), and of a two-link spatial arm it is
  PyNiteFEA's frame compliance at the tip, ``[K^-1]`` of its six unit load cases, carried to the joints by the arm's
  own Jacobian written here (``J^+ C J^+T``);
- the sampled loop with a full (not diagonal) drive stiffness and with a massless motor side is python-control's:
  ``control.c2d`` of the plant built here from its equations (the two-mass plant of
  ``test_sim_transmission``; for the massless side the links' plant with the encoders reading ``q + C u`` of the
  torque held over the period before), the delay as ``z^-d``, ``control.feedback`` with the wall;
- a SciPy simulation of the massless side decays below the limit and grows above it;
- as the links' modulus grows the limit returns to the rigid model's (today's numbers).
"""

from __future__ import annotations

import json
from math import cos, pi, sin
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
from hapticdesign.analysis.metrics.indices.states import HandleStates
from hapticdesign.analysis.sampled_loop import GRASP, Hand, SampledLoop
from hapticdesign.analysis.stiffness.device import cartesian_stiffness
from hapticdesign.analysis.wall_stiffness import wall_limit
from hapticdesign.devices.design_space import design_space
from hapticdesign.devices.device_file import device_from_mapping, load_device_file
from hapticdesign.interface.cli import app
from hapticdesign.model.actuators import Transmission
from tests.helpers.pynite_chain import chain_compliance
from tests.simulation.test_sim_transmission import AXIS, LEVER, LINK, PERIOD, X, _limit, _plant, _wall_gain

TUBES = Path(__file__).resolve().parents[2] / "examples" / "studies" / "five-bar-tubes.yaml"
E_AL, G_AL = 68.9e9, 26.0e9  # aluminium 6061-T6, the file's material name (ASM data sheet)
D, d = 0.02, 0.016
I_TUBE = pi / 64 * (D**4 - d**4)
AREA, J_TUBE = pi / 4 * (D**2 - d**2), pi / 32 * (D**4 - d**4)


def _arm(length: float = 0.3, actuator: dict | None = None, modulus: float = 1.0) -> dict:
    """One revolute joint turning an aluminium tube of ``length``, the handle at its tip; ``modulus`` scales the
    material's E and G."""
    material = "aluminium_6061" if modulus == 1.0 else {"E": E_AL * modulus, "G": G_AL * modulus}
    return {
        "name": "arm", "parameters": {"L": length},
        "joints": [{"name": "q1", "damping": 0.01}],
        "frames": [{"name": "arm", "transforms": [{"Rz": "q1"}]},
                   {"name": "tip", "parent": "arm", "transforms": [{"tx": "L"}]}],
        "end_effector": "tip",
        "bodies": [{"name": "arm", "frame": "arm", "m": 0.1, "rx": 0.15, "Ixx": 1e-6, "Iyy": 1e-4, "Izz": 1e-4}],
        "links": [{"name": "arm", "from": "arm", "to": "tip", "section": {"shape": "tube", "D": D, "d": d},
                   "material": material}],
        **({} if actuator is None else {"actuators": [{"joint": "q1", **actuator}]}),
    }


def _drive(device, q) -> Transmission:
    states = HandleStates(device, configuration_of(device).full(np.asarray(q, dtype=float))[None])
    return states.drive


@pytest.mark.parametrize("angle", [0.0, 0.7])
def test_one_links_joint_stiffness_is_the_cantilevers_times_its_length_squared(angle):
    L = 0.3
    drive = _drive(device_from_mapping(_arm(L)), [angle])
    assert drive.stiffness[0, 0, 0] == pytest.approx(3 * E_AL * I_TUBE / L**3 * L**2, rel=1e-10)
    assert not drive.inertia.any() and not drive.damping.any()  # no motor: a massless motor side


def test_a_transmission_and_the_link_are_in_series():
    L, k_t = 0.3, 2.0e3
    drive = _drive(device_from_mapping(_arm(L, {"rotor_inertia": 1e-6, "gear_ratio": 10.0, "damping": 0.002,
                                                "transmission_stiffness": k_t})), [0.2])
    assert drive.stiffness[0, 0, 0] == pytest.approx(1.0 / (1.0 / k_t + L / (3 * E_AL * I_TUBE)), rel=1e-10)
    assert drive.inertia[0, 0, 0] == pytest.approx(100 * 1e-6) and drive.damping[0, 0, 0] == pytest.approx(0.002)


def _two_link_arm() -> dict:
    """A spatial arm (as tests/devices/test_device_stiffness.py's): q1 about z, an aluminium upper arm, q2 about
    the elbow's y axis, a steel rod forearm, the handle at its tip."""
    return {
        "name": "arm-2r", "parameters": {"h": 0.05, "l1": 0.25, "l2": 0.2},
        "joints": [{"name": "q1"}, {"name": "q2"}],
        "frames": [{"name": "shoulder", "transforms": [{"tz": "h"}, {"Rz": "q1"}]},
                   {"name": "elbow", "parent": "shoulder", "transforms": [{"tx": "l1"}]},
                   {"name": "forearm", "parent": "elbow", "transforms": [{"Ry": "q2"}]},
                   {"name": "tip", "parent": "forearm", "transforms": [{"tx": "l2"}]}],
        "end_effector": "tip",
        "bodies": [{"name": "upper", "frame": "shoulder", "m": 0.2, "rx": 0.125},
                   {"name": "fore", "frame": "forearm", "m": 0.1, "rx": 0.1}],
        "links": [{"name": "upper", "from": "shoulder", "to": "elbow", "section": {"shape": "tube", "D": D, "d": d},
                   "material": "aluminium_6061"},
                  {"name": "fore", "from": "forearm", "to": "tip", "section": {"shape": "rod", "D": 0.008},
                   "material": "steel"}],
    }


def test_a_two_link_arms_joint_compliance_is_pyNites_carried_to_the_joints():
    q1, q2, h, l1, l2 = 0.4, -0.6, 0.05, 0.25, 0.2
    shoulder = np.array([0.0, 0.0, h])
    radial = np.array([cos(q1), sin(q1), 0.0])
    elbow = shoulder + l1 * radial
    forearm = np.array([cos(q2) * cos(q1), cos(q2) * sin(q1), -sin(q2)])
    tip = elbow + l2 * forearm
    rod = 0.008
    compliance = chain_compliance([shoulder, elbow, tip],
                                    [(AREA, I_TUBE, J_TUBE), (pi / 4 * rod**2, pi / 64 * rod**4, pi / 32 * rod**4)],
                                    [(E_AL, G_AL), (200e9, 200e9 / 2.6)])[:3, :3]
    # the tip's velocity per joint rate: q1 turns the tip about z, q2 turns the forearm about the elbow's y axis
    y_elbow = np.array([-sin(q1), cos(q1), 0.0])
    jacobian = np.column_stack([np.cross([0.0, 0.0, 1.0], tip - shoulder), np.cross(y_elbow, tip - elbow)])
    pinv = np.linalg.pinv(jacobian)
    expected = pinv @ compliance @ pinv.T
    found = np.linalg.inv(_drive(device_from_mapping(_two_link_arm()), [q1, q2]).stiffness[0])
    np.testing.assert_allclose(found, expected, rtol=1e-7, atol=1e-7 * np.abs(expected).max())


def _massless_gain(mass, damping, stiffness, compliance, w):
    """``w^T P(z) w`` of the links' plant held over each period, its encoders reading ``q + C u_prev``: the state
    ``(q, q', u_prev)``, ``u_prev`` the torque held over the period before."""
    n = mass.shape[0]
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(mass, stiffness), -np.linalg.solve(mass, damping)]])
    b = np.vstack([np.zeros((n, n)), np.linalg.inv(mass)])
    held = control.c2d(control.ss(a, b, np.hstack([np.eye(n), np.zeros((n, n))]), np.zeros((n, n))), PERIOD, "zoh")
    big_a = np.block([[held.A, np.zeros((2 * n, n))], [np.zeros((n, 3 * n))]])
    big_b = np.vstack([held.B, np.eye(n)])
    big_c = np.hstack([np.eye(n), np.zeros((n, n)), compliance])
    return control.tf(control.ss(big_a, big_b @ w[:, None], w[None, :] @ big_c, 0, PERIOD))


def _joint_massless(compliance: float, loop: SampledLoop) -> float:
    return wall_limit(AXIS, np.array([[LINK]]), np.array([[0.0005]]), loop, X,
                      transmission=Transmission(np.zeros((1, 1)), np.zeros((1, 1)), np.array([[1.0 / compliance]])))


@pytest.mark.parametrize("hand", [None, GRASP])
@pytest.mark.parametrize("compliance", [1e-4, 1e-3, 3e-2])
@pytest.mark.parametrize("delay, wall_damping", [(1, 0.0), (2, 0.0), (1, 0.05)])
def test_a_massless_motor_side_is_python_controls_loop(hand, compliance, delay, wall_damping):
    """One joint, no rotor: the encoder reads the link's angle plus the spring's stretch under the held torque."""
    loop = SampledLoop(period=PERIOD, delay=delay, wall_damping=wall_damping, hand=hand)
    h = hand or Hand()
    r2 = LEVER ** 2
    gain = _massless_gain(np.array([[LINK + h.mass * r2]]), np.array([[0.0005 + h.damping * r2]]),
                          np.array([[h.stiffness * r2]]), np.array([[compliance]]), np.array([LEVER]))
    assert _joint_massless(compliance, loop) == pytest.approx(_limit(gain, delay, wall_damping), rel=1e-6, abs=1e-9)


@pytest.fixture(scope="module")
def five_bar():
    device = load_device_file(Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml")
    q = handle_pose(device, np.array([0.01, 0.0, 0.19])).q
    return configuration_of(device).jacobian(q)[:3], mass_matrix(device, q)


SKEW = np.array([0.6, 0.0, 0.8])
FULL = np.array([[300.0, -120.0], [-120.0, 180.0]])  # a drive stiffness whose joints are coupled (N m/rad)


@pytest.mark.parametrize("hand", [None, GRASP])
def test_a_full_drive_stiffness_is_python_controls_two_mass_loop(five_bar, hand):
    jv, h = five_bar
    rotor, bm = 2e-5 * np.eye(2), 0.004 * np.eye(2)
    hand_ = hand or Hand()
    jtj = jv.T @ jv
    plant = _plant(rotor, h - rotor + hand_.mass * jtj, bm, hand_.damping * jtj, FULL, hand_.stiffness * jtj)
    mine = wall_limit(jv, h, bm, SampledLoop(hand=hand), SKEW, transmission=Transmission(rotor, bm, FULL))
    assert mine == pytest.approx(_limit(_wall_gain(plant, jv.T @ SKEW, 1 if hand is None else 0), 1), rel=1e-6)


@pytest.mark.parametrize("hand", [None, GRASP])
def test_a_massless_two_joint_drive_is_python_controls_loop(five_bar, hand):
    jv, h = five_bar
    damping = 0.01 * np.eye(2)
    hand_ = hand or Hand()
    jtj = jv.T @ jv
    compliance = np.linalg.inv(FULL)
    gain = _massless_gain(h + hand_.mass * jtj, damping + hand_.damping * jtj, hand_.stiffness * jtj, compliance,
                          jv.T @ SKEW)
    if hand is None:  # the drift along the wall: a pole and a zero at z = 1, as in _wall_gain
        num, den = np.polydiv(gain.num[0][0], [1.0, -1.0])[0], np.polydiv(gain.den[0][0], [1.0, -1.0])[0]
        gain = control.tf(num, den, PERIOD)
    mine = wall_limit(jv, h, damping, SampledLoop(hand=hand), SKEW,
                      transmission=Transmission(np.zeros((2, 2)), np.zeros((2, 2)), FULL))
    assert mine == pytest.approx(_limit(gain, 1), rel=1e-6)


def _held_run(stiffness: float, compliance: float, seconds: float = 3.0) -> tuple[float, float]:
    """The largest encoder excursion in the first and the last half second of the wall's loop (one sample of
    delay, the hand of GRASP), the link integrated by SciPy across each held torque from a push, the encoder reading
    the link's angle plus the spring's stretch under the torque held over the period before."""
    r2 = LEVER ** 2
    inertia, damping, spring = LINK + GRASP.mass * r2, 0.0005 + GRASP.damping * r2, GRASP.stiffness * r2

    def rates(_t, x, held):
        return [x[1], (held - damping * x[1] - spring * x[0]) / inertia]

    state, held, held_before, sensed_before = np.array([0.0, 0.05]), 0.0, 0.0, 0.0
    peaks = []
    for _ in range(int(round(seconds / PERIOD))):
        sensed = state[0] + compliance * held_before
        state = solve_ivp(rates, (0.0, PERIOD), state, args=(held,), rtol=1e-10, atol=1e-14).y[:, -1]
        held_before, held = held, -stiffness * r2 * sensed_before  # the torque from the sample before (delay 1)
        sensed_before = sensed
        peaks.append(abs(sensed))
    half = int(round(0.5 / PERIOD))
    return max(peaks[:half]), max(peaks[-half:])


def test_a_simulated_massless_drive_decays_below_the_limit_and_grows_above_it():
    compliance = 3e-2
    limit = _joint_massless(compliance, SampledLoop(hand=GRASP))
    first, last = _held_run(0.7 * limit, compliance)
    assert last < 0.6 * first
    first, last = _held_run(1.4 * limit, compliance)
    assert last > 2.0 * first


@pytest.mark.parametrize("actuator", [None, {"rotor_inertia": 2e-6, "gear_ratio": 10.0, "damping": 0.002}])
def test_stiffer_and_stiffer_links_return_the_rigid_limit(actuator):
    """The same arm with its modulus scaled: the limit tends to the rigid model's (the wall without a drive)."""
    loop = SampledLoop(hand=GRASP)

    def limits(modulus):
        device = device_from_mapping(_arm(0.3, actuator, modulus))
        states = HandleStates(device, np.array([[0.3]]))
        rigid = wall_limit(states.J_v[0], states.H[0], states.B[0], loop)
        return rigid, wall_limit(states.J_v[0], states.H[0], states.B[0], loop, transmission=states.drive)

    errors = []
    for modulus in (1e1, 1e2, 1e3, 1e4):
        rigid, compliant = limits(modulus)
        errors.append(abs(compliant / rigid - 1.0))
    assert errors[-1] < 1e-4 and errors[0] > errors[1] > errors[2] > errors[3]


def _tubes(tmp_path: Path, **changes) -> Path:
    data = yaml.safe_load(TUBES.read_text())
    data.update(changes)
    path = tmp_path / "tubes.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_the_kmax_index_of_elastic_tubes_is_python_controls_two_mass_loop(tmp_path):
    """The five-bar of aluminium tubes (no gravity, the oracle's plant has none): its joints' spring is the VJM's
    K_C (checked against PyNiteFEA in tests/devices) carried to the joints here, the rotors on the motor side."""
    device = load_device_file(_tubes(tmp_path, g=0.0))
    point = np.array([0.01, 0.0, 0.17])
    pose = handle_pose(device, point)
    jv = configuration_of(device).jacobian(pose.q)[:3]
    h = mass_matrix(device, pose.q)
    pinv = np.linalg.pinv(jv)
    spring = np.linalg.inv(pinv @ np.linalg.inv(cartesian_stiffness(device, pose.q))[:3, :3] @ pinv.T)
    rotor = 100 * 1.1e-6 * np.eye(2)
    plant = _plant(rotor, h - rotor, np.zeros((2, 2)), 0.001 * np.eye(2), spring)
    value = evaluate(device, point[None], [Request("kmax", {"direction": SKEW}, "along")]).values["along"][0]
    assert value == pytest.approx(_limit(_wall_gain(plant, jv.T @ SKEW, 1), 1), rel=1e-6)


def test_a_study_of_elastic_tubes_takes_their_compliance_through_the_batched_path():
    """Designs of the tubes' diameters through the compiled batch give what each design's own device gives, and a
    thinner tube its own limit."""
    space = design_space(TUBES, ["links.prox1.D", "links.prox2.D"])
    designs = [{"links.prox1.D": D_, "links.prox2.D": D_} for D_ in (0.009, 0.012, 0.02)]
    point = np.array([0.0, 0.0, 0.17])
    batched = evaluate_designs(space, designs, point[None], [Request("kmax", {"hand": "light"}, "kmax")])
    assert space.cache.get("batch"), "the compiled path serves the links"
    one = [evaluate(space.device(x), point[None], [Request("kmax", {"hand": "light"}, "kmax")]).values["kmax"][0]
           for x in designs]
    np.testing.assert_allclose([b.values["kmax"][0] for b in batched], one, rtol=1e-9)
    assert len(set(np.round(one, 6))) == 3


def _json(args) -> dict:
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    return json.loads(result.output)


def test_spec_and_impedance_range_say_which_compliances_they_include():
    tubes = _json(["spec", "--device", str(TUBES), "--no-simulate", "--no-workspace", "--json"])
    assert tubes["renderable_stiffness"]["compliance"] == "links"
    rigid = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"
    assert _json(["spec", "--device", str(rigid), "--no-simulate", "--no-workspace",
                  "--json"])["renderable_stiffness"]["compliance"] == "rigid"
    out = _json(["impedance-range", "--device", str(TUBES), "--wall-direction", "1,0,0", "--json"])
    assert out["compliance"] == "links"


@pytest.mark.parametrize("changes, fragment", [
    ({"joint_stiffness": {"q1": 1e3}, "transmission": 500.0}, "give the drives' compliance once"),
    ({"motor_damping": 0.002}, "needs a rotor inertia"),
])
def test_a_drive_stated_twice_or_a_damped_massless_motor_is_one_line(tmp_path, changes, fragment):
    data = yaml.safe_load(TUBES.read_text())
    for actuator in data["actuators"]:
        if "transmission" in changes:
            actuator["transmission_stiffness"] = changes["transmission"]
        if "motor_damping" in changes:
            actuator.update(rotor_inertia=0.0, damping=changes["motor_damping"])
    if "joint_stiffness" in changes:
        data["joint_stiffness"] = changes["joint_stiffness"]
    path = tmp_path / "drive.yaml"
    path.write_text(yaml.safe_dump(data))
    result = CliRunner().invoke(app, ["spec", "--device", str(path), "--no-simulate", "--no-workspace", "--json"])
    lines = [line for line in result.output.strip().splitlines() if line]
    assert result.exit_code == 2 and len(lines) == 1 and lines[0].startswith("error:"), result.output
    assert fragment in lines[0]
    reason = evaluate(load_device_file(path), np.array([[0.0, 0.0, 0.17]]), ["kmax"]).reason
    assert reason is not None and fragment in reason  # the kmax index of a study refuses it alike
