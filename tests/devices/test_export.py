"""Exports checked in established libraries. URDF of a tree in Pinocchio: its ``crba`` and ``rnea`` equal our
H and ``C qd + G``. MJCF in MuJoCo: on trees its mass matrix and bias forces equal ours; on closed loops its
constrained accelerations under a torque equal ours (the R-CUBE's welds included).

Oracles: MuJoCo's ``mj_fullM``, ``qfrc_bias``, its constraint Jacobian ``efc_J`` and its own constrained
``qacc``. The export has more joints than the device has coordinates (couplings such as the Phantom's
``q2 - q3`` are joints of their own, tied by tendons), with ``qpos = T q``: ours must be ``T^T M T`` and
``T^T qfrc_bias`` (T constant, so no T-dot term). The exported frames between two joints carry
MuJoCo's ``boundmass`` 1e-9 kg and ``boundinertia`` 1e-12 kg m^2 (it refuses moving bodies without mass):
that bounds the agreement, to 1e-8 kg m^2 on H (25 such bodies at most, 0.5 m from the axes at most) and
1e-7 N m on the bias (their weight on those arms).

MuJoCo's equality constraints are soft: with impedance d its constraint force is short of the ideal one by
a factor of order (1 - d). Its accelerations approach ours as d -> 1 (checked on the five-bar and the delta,
each tenfold step of 1 - d making the error at least 5 times smaller, and within 10 (1 - d) = 1e-3 at
MuJoCo's stiffest d = 0.9999: measured 5.7e-5 on the five-bar, 7.1e-4 on the delta); the ideal (hard) limit, solved from
MuJoCo's M, qfrc_bias and efc_J, equals ours within 1e-6 (relative).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from hapticdesign.analysis.dynamics.device import coriolis_matrix, forward_dynamics, gravity, mass_matrix
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.devices.export import to_mjcf, to_urdf

mujoco = pytest.importorskip("mujoco")


def test_urdf_of_a_tree_equals_pinocchios_dynamics():
    pin = pytest.importorskip("pinocchio")
    device = _load("arm-3r.toml")
    model = pin.buildModelFromXML(to_urdf(device).text)
    model.gravity.linear[:] = device.mechanism.gravity
    data = model.createData()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, qd = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)
        qp, vp = np.zeros(model.nq), np.zeros(model.nv)
        for k, name in enumerate(device.mechanism.coordinates):
            joint = model.joints[model.getJointId(name)]
            qp[joint.idx_q: joint.idx_q + joint.nq] = [np.cos(q[k]), np.sin(q[k])] if joint.nq == 2 else [q[k]]
            vp[joint.idx_v] = qd[k]
        M = pin.crba(model, data, qp)
        M = np.triu(M) + np.triu(M, 1).T
        assert np.allclose(M, mass_matrix(device, q), rtol=1e-12, atol=1e-14)
        bias = pin.rnea(model, data, qp, vp, np.zeros(model.nv))
        assert np.allclose(bias, coriolis_matrix(device, q, qd) @ qd + gravity(device, q), rtol=1e-12, atol=1e-13)
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"


def _load(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_device_file(EXAMPLES / name if isinstance(name, str) else name)


@pytest.mark.parametrize("name", ["arm-3r.toml", "phantom-3dof-motors.yaml", "phantom-premium.yaml"])
def test_tree_mass_matrix_and_bias_equal_mujocos(name):
    device = _load(name)
    export = to_mjcf(device)
    model = mujoco.MjModel.from_xml_string(export.text)
    data = mujoco.MjData(model)
    T = export.transform()
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd = rng.uniform(-1, 1, device.n_dof), rng.uniform(-2, 2, device.n_dof)
        data.qpos[:], data.qvel[:] = T @ q, T @ qd
        mujoco.mj_forward(model, data)
        M = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, M)
        assert np.allclose(T.T @ M @ T, mass_matrix(device, q), rtol=0, atol=1e-8)
        assert np.allclose(T.T @ data.qfrc_bias, coriolis_matrix(device, q, qd) @ qd + gravity(device, q), rtol=0,
                           atol=1e-7)


def _accelerations(device, impedance: str | None = None, bound_mass: float | None = None):
    """Ours, MuJoCo's own and the hard-constraint limit from MuJoCo's matrices, at home under a torque (with
    another constraint impedance or another bound on the massless frames' mass if given)."""
    text = to_mjcf(device).text
    if impedance is not None:
        text = text.replace('solimp="0.9999 0.9999 0.001 0.5 2"', f'solimp="{impedance}"')
    if bound_mass is not None:
        assert text.count('boundmass="1e-09" boundinertia="1e-12"') == 1
        text = text.replace('boundmass="1e-09" boundinertia="1e-12"',
                            f'boundmass="{bound_mass:g}" boundinertia="{bound_mass * 1e-3:g}"')
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    tau = np.linspace(0.005, -0.003, device.n_dof)
    dofs = [model.joint(name).dofadr[0] for name in device.mechanism.actuated_coordinates]
    data.qfrc_applied[dofs] = tau
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    J = data.efc_J.reshape(-1, model.nv)[: data.ne]
    kkt = np.block([[M, J.T], [J, np.zeros((len(J), len(J)))]])
    rhs = np.concatenate([data.qfrc_applied - data.qfrc_bias, np.zeros(len(J))])
    hard = np.linalg.lstsq(kkt, rhs, rcond=None)[0][: model.nv]
    ours = forward_dynamics(device, np.array(device.mechanism.loops.home), np.zeros(device.n_dof), tau)
    return ours, data.qacc[dofs].copy(), hard[dofs]


@pytest.mark.parametrize("name", ["five-bar.yaml", "delta.yaml", "falcon.yaml", "rcube.yaml"])
def test_closed_loop_accelerations_equal_the_hard_constraint_limit_of_mujocos_model(name):
    ours, _, hard = _accelerations(_load(name))
    assert np.abs(hard - ours).max() <= 1e-6 * np.abs(ours).max()


def test_rcube_weld_export_differs_from_ours_by_the_bound_mass_only():
    """The R-CUBE closes its loops with two welds (whole pose) over 12 passive joints and carries only 77.7 g of
    tubes, so MuJoCo's 1e-9 kg on each massless frame shows (measured 5e-7 relative): a tenfold smaller bound
    makes the difference about tenfold smaller, down to 1e-8 at 1e-11 kg."""
    device = _load("rcube.yaml")
    model = mujoco.MjModel.from_xml_string(to_mjcf(device).text)
    assert list(model.eq_type) == [mujoco.mjtEq.mjEQ_WELD] * 2
    errors = []
    for bound in (1e-9, 1e-10, 1e-11):
        ours, _, hard = _accelerations(device, bound_mass=bound)
        errors.append(np.abs(hard - ours).max() / np.abs(ours).max())
    assert errors[1] < errors[0] / 5 and errors[2] < errors[1] / 5
    assert errors[2] < 1e-8


@pytest.mark.parametrize("name", ["five-bar.yaml", "delta.yaml"])
def test_mujocos_soft_constrained_accelerations_approach_ours(name):
    device = _load(name)
    errors = []
    for d in ("0.99", "0.999", "0.9999"):
        ours, soft, _ = _accelerations(device, f"{d} {d} 0.001 0.5 2")
        errors.append(np.abs(soft - ours).max() / np.abs(ours).max())
    assert errors[1] < errors[0] / 5 and errors[2] < errors[1] / 5
    assert errors[2] < 1e-3


PEAK = 0.129  # N m at the motor: the Maxon RE 25's stall torque, as examples/devices/phantom-premium.yaml states it
PREMIUM_RATIOS = (13.3, 11.2, 11.2)
PREMIUM_LIMITS_DEG = ((-90, 90), (-124, 119), (-29, 214))


def test_mjcf_carries_the_phantoms_joint_limits_and_peak_torques_and_mujoco_clamps_to_them():
    """Joint ranges from the file's limits, ``ctrlrange``/``forcerange`` +-tau_p at the motor, and the
    joint's ``actuatorfrcrange`` +-n tau_p: MuJoCo's own ``qfrc_actuator`` saturates at n tau_p."""
    device = _load("phantom-premium.yaml")
    model = mujoco.MjModel.from_xml_string(to_mjcf(device).text)
    data = mujoco.MjData(model)
    for k, name in enumerate(("q1", "q2", "q3")):
        joint = model.joint(name)
        assert np.allclose(joint.range, np.radians(PREMIUM_LIMITS_DEG[k]), rtol=1e-15)
        assert model.jnt_limited[joint.id]
        assert np.allclose(model.jnt_actfrcrange[joint.id], [-PREMIUM_RATIOS[k] * PEAK, PREMIUM_RATIOS[k] * PEAK])
        motor = model.actuator(f"motor{k + 1}")
        assert np.allclose(motor.ctrlrange, [-PEAK, PEAK]) and np.allclose(motor.forcerange, [-PEAK, PEAK])
        assert motor.gear[0] == PREMIUM_RATIOS[k]
    dofs = [model.joint(n).dofadr[0] for n in ("q1", "q2", "q3")]
    for ctrl, expected in ((np.array([0.05, -0.02, 0.1]), np.array([0.05, -0.02, 0.1])),
                           (np.array([1.0, -3.0, 0.5]), np.array([PEAK, -PEAK, PEAK]))):
        data.ctrl[:] = ctrl
        mujoco.mj_forward(model, data)
        assert np.allclose(data.qfrc_actuator[dofs], np.array(PREMIUM_RATIOS) * expected, rtol=1e-12)


def _with_peak_torques(tmp_path):
    """phantom-3dof-motors.yaml with the RE 25's peak torque on its three motors (the third on -theta2 - theta3)."""
    text = (EXAMPLES / "phantom-3dof-motors.yaml").read_text()
    assert text.count("damping: 0.0005}") == 3
    path = tmp_path / "peaks.yaml"
    path.write_text(text.replace("damping: 0.0005}", f"damping: 0.0005, torque_peak: {PEAK}}}"))
    return _load(path)


def test_mjcf_of_a_coupled_motor_limits_its_tendon(tmp_path):
    """The third motor turns -theta2 - theta3 within [-29, 214] deg: its tendon's range and force range."""
    model = mujoco.MjModel.from_xml_string(to_mjcf(_with_peak_torques(tmp_path)).text)
    tendon = model.tendon("drive3")
    assert np.allclose(model.tendon_range[tendon.id], np.radians([-29, 214]), rtol=1e-15)
    assert model.tendon_limited[tendon.id]
    assert np.allclose(model.tendon_actfrcrange[tendon.id], [-11.2 * PEAK, 11.2 * PEAK])
    assert np.allclose(model.jnt_range[model.joint("theta3").id], np.radians([-65, 55]), rtol=1e-15)


def test_urdf_carries_joint_limits_and_efforts_read_by_pinocchio(tmp_path):
    """Pinocchio's limits: the file's ranges, effort n tau_p on joints with a motor of their own, 0 on theta3
    (its motor turns a combination, which URDF cannot state)."""
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromXML(to_urdf(_with_peak_torques(tmp_path)).text)
    expected = {"theta1": ((-90, 90), 13.3 * PEAK), "theta2": ((-119, 124), 11.2 * PEAK), "theta3": ((-65, 55), 0.0)}
    for name, (span, effort) in expected.items():
        joint = model.joints[model.getJointId(name)]
        assert model.lowerPositionLimit[joint.idx_q] == pytest.approx(np.radians(span[0]), rel=1e-15)
        assert model.upperPositionLimit[joint.idx_q] == pytest.approx(np.radians(span[1]), rel=1e-15)
        assert model.effortLimit[joint.idx_v] == pytest.approx(effort, rel=1e-15)


def _coast_error(device, text: str, velocity: np.ndarray, duration: float = 0.2) -> tuple[float, object]:
    """The largest difference (rad) between MuJoCo's coast of ``text`` from home at ``velocity`` (the passive
    joints' velocities solved from MuJoCo's own constraint Jacobian) and ours (``forward_dynamics`` integrated
    by SciPy's DOP853), after ``duration`` seconds."""
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    names = device.mechanism.actuated_coordinates
    dofs = [model.joint(name).dofadr[0] for name in names]
    others = [i for i in range(model.nv) if i not in dofs]
    J = data.efc_J.reshape(-1, model.nv)[: data.ne]
    data.qvel[dofs] = velocity
    data.qvel[others] = np.linalg.lstsq(J[:, others], -J[:, dofs] @ velocity, rcond=None)[0]
    for _ in range(round(duration / model.opt.timestep)):
        mujoco.mj_step(model, data)
    n = device.n_dof
    home = np.array(device.mechanism.loops.home)
    damping = np.asarray(device.damping)
    ours = solve_ivp(lambda t, y: np.concatenate([y[n:], forward_dynamics(device, y[:n], y[n:], -damping * y[n:])]),
                     (0.0, duration), np.concatenate([home, velocity]), method="DOP853", rtol=1e-11, atol=1e-12)
    mujocos = data.qpos[[model.joint(name).qposadr[0] for name in names]]
    return float(np.abs(mujocos - ours.y[:n, -1]).max()), model


def test_falcons_coast_in_mujoco_follows_ours_with_the_exported_constraint_stiffness():
    """The Falcon (no damping, no gravity) coasts 0.2 s from home at (1, 0.25, -0.5) rad/s: MuJoCo integrates
    the export, SciPy integrates our forward dynamics. The export's ``solref`` is twice its timestep (the
    stiffest MuJoCo keeps), ten times shorter than MuJoCo's default 0.02 s: the coast stays within 1e-3 rad of
    ours (measured 3.3e-4), more than ten times closer than with the default (measured 8.2e-3)."""
    device = _load("falcon.yaml")
    text = to_mjcf(device).text
    velocity = np.array([1.0, 0.25, -0.5])
    exported, model = _coast_error(device, text, velocity)
    assert np.all(model.eq_solref[:, 0] == 2 * model.opt.timestep) and np.all(model.eq_solref[:, 1] == 1.0)
    default, _ = _coast_error(device, text.replace(f'solref="{2 * model.opt.timestep:g} 1" ', ""), velocity)
    assert exported < 1e-3
    assert default > 10 * exported


@pytest.mark.parametrize("name", ["a\x01b", "a\ufffeb", "a\ud800b"])
def test_a_python_built_device_whose_name_xml_forbids_is_refused_in_one_line(name):
    """Issue 33: no device file can hold such a name (the reader refuses it), but a Device built in Python can; the
    export refuses it instead of writing a malformed MJCF or URDF (ElementTree writes control characters as they
    are, and a lone surrogate cannot be encoded)."""
    from dataclasses import replace

    from hapticdesign.errors import UserError

    device = replace(load_device_file(EXAMPLES / "arm-3r.toml"), name=name)
    for export in (to_mjcf, to_urdf):
        with pytest.raises(UserError, match=f"U\\+{ord(name[1]):04X}, which XML forbids"):
            export(device)
