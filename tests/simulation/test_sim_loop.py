"""The numba loop against the plain solve_ivp loop, and its bad-input handling."""

import numpy as np
import pytest

from hapticdesign.analysis.dynamics.device import inverse_dynamics
from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError
from hapticdesign.analysis.sampled_loop import SampledLoop
from hapticdesign.simulation.config import Compensator, Hand, LoopConfig, Sensors, Wall
from hapticdesign.simulation.loop import joint_index, simulate
from hapticdesign.simulation.paths import Chirp, Held, Sine
from tests.helpers.reference import simulate_adaptive

NONLINEAR = {"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05, "Ixz3": 1e-3, "r2az": 0.02}


@pytest.mark.parametrize("control", ["fixed", "adaptive"])
@pytest.mark.parametrize("paths", [{1: Held(0.0), 2: Held(0.0)}, {1: Sine(0.52, 3 * np.pi), 2: Sine(0.52, 3 * np.pi)}])
def test_rk4_loop_matches_scipy_solve_ivp(paths, control):
    device = preset("phantom-3dof").with_params(NONLINEAR)
    config = LoopConfig(duration=0.3, wall=Wall(0, 5.0, equilibrium=0.01), counts=2**16, step_control=control,
                        loop=SampledLoop.seed(delay=1, error_percent=20, wall_damping=0.01))
    fast = simulate(device, config, paths)
    slow = simulate_adaptive(device, config, paths)
    # the fixed step takes every plant step; the adaptive one mostly one step per 10-step sample period
    assert fast.steps == 3000 if control == "fixed" else fast.steps < 600
    assert fast.q.shape == slow.q.shape
    assert np.abs(fast.q - slow.q).max() < 1e-9
    assert np.abs(fast.u - slow.u).max() < 1e-6 * max(1.0, np.abs(slow.u).max())
    assert np.abs(fast.tau_c - slow.tau_c).max() < 1e-6 * max(1.0, np.abs(slow.tau_c).max())


def test_free_joints_fall_unless_gravity_is_compensated():
    """With every joint free the uncompensated arm falls under gravity; the compensated one stays at rest."""
    device = preset("phantom-3dof").with_params({"m3": 0.1, "r3z": 0.05})
    config = LoopConfig(duration=2.0, wall=Wall(0, 0.0, equilibrium=0.0), safety_limit=None,
                        compensator=Compensator(False, False, False))
    trace = simulate(device, config)
    assert np.all(np.isfinite(trace.q))
    assert np.abs(trace.q[-1] - trace.q[0]).max() > 0.05
    # the compensator holds G exactly at rest (zero initial acceleration, seed eq. 4.3)
    held = simulate(device, LoopConfig(duration=2.0, wall=Wall(0, 0.0, equilibrium=0.0), safety_limit=None))
    assert np.abs(held.q).max() < 1e-9


def test_prescribed_joint_constraint_torque_is_inverse_dynamics():
    """All joints on a path with no compensation and no wall: tau_c = H qdd + C qd^2 + G + b qd."""
    device = preset("phantom-3dof").with_params(NONLINEAR)
    chirp = Chirp(0.3, 0.5, 3.0, 1.0)
    config = LoopConfig(duration=1.0, wall=Wall(0, 0.0, equilibrium=0.0), safety_limit=None,
                        compensator=Compensator(False, False, False), record_stride=7)
    trace = simulate(device, config, {0: chirp, 1: chirp, 2: chirp})
    q, qd, qdd = chirp.sample(trace.t)
    for i in range(0, len(trace.t), 50):
        qv = np.full(3, q[i])
        expected = inverse_dynamics(device, qv, np.full(3, qd[i]), np.full(3, qdd[i])) + np.array(device.damping) * qd[i]
        assert np.allclose(trace.tau_c[i], expected, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize(
    "settings, message",
    [
        (dict(loop=dict(period=0.0)), "period must be a positive number"),
        (dict(loop=dict(period=-1e-3)), "period must be a positive number"),
        (dict(step=3e-4), "does not divide"),
        (dict(counts=0), "counts per revolution"),
        (dict(loop=dict(error_percent=150)), "error percentage"),
        (dict(step_control="variable"), "unknown step control 'variable'"),
        (dict(step_control="adaptive", tolerance=float("nan")), "tolerance must be a positive number"),
        (dict(step_control="adaptive", tolerance=0.0), "tolerance must be a positive number"),
        (dict(duration=float("nan")), "simulated time must be a positive number"),
        (dict(loop=dict(wall_damping=-1.0)), "wall damping must be a finite number >= 0"),
        (dict(loop=dict(delay=-1)), "sensor delay must be a non-negative"),
        (dict(hand=dict(mass=-1.0)), "hand's mass, damping and stiffness must be finite and non-negative"),
    ],
)
def test_bad_loop_settings_are_refused_when_configured(settings, message):
    parts = {"loop": SampledLoop.seed, "hand": Hand}
    with pytest.raises(UserError, match=message):
        LoopConfig(**{key: parts[key](**value) if key in parts else value for key, value in settings.items()})


def test_the_former_places_of_the_loop_settings_are_taken_one_release_with_a_warning():
    hand = Hand(0.1, 2.0, 200.0)
    with pytest.warns(FutureWarning) as caught:
        old = LoopConfig(sensors=Sensors(5e-4, 4096, 2), compensator=Compensator(False, True, True, 7.0),
                         wall=Wall(1, 3.0, 0.2, 0.01), hand=hand)
    assert len(caught) == 4 and all("will be removed" in str(w.message) for w in caught)
    new = LoopConfig(loop=SampledLoop.seed(period=5e-4, delay=2, error_percent=7.0, wall_damping=0.2, hand=hand),
                     counts=4096, compensator=Compensator(inertial=False), wall=Wall(1, 3.0, equilibrium=0.01))
    assert old == new


def test_an_unknown_wall_joint_is_refused_by_the_run():
    with pytest.raises(UserError, match="unknown joint"):
        simulate(preset("phantom-3dof"), LoopConfig(wall=Wall(joint=5)))


def test_joint_names():
    device = preset("phantom-3dof")
    assert joint_index(device, "theta2") == 1 and joint_index(device, "3") == 2
    with pytest.raises(UserError, match="unknown joint"):
        joint_index(device, "theta7")
    with pytest.raises(UserError, match="unknown joint"):
        joint_index(device, 0)


def test_diverging_run_is_a_result_not_a_crash():
    config = LoopConfig(duration=2.0, wall=Wall(0, 5000.0, equilibrium=0.01), safety_limit=None)
    trace = simulate(preset("phantom-3dof"), config, {1: Held(0.0), 2: Held(0.0)})
    assert trace.diverged or np.abs(trace.q[:, 0]).max() > 1.0


@pytest.mark.parametrize("control", ["fixed", "adaptive"])
def test_safety_switch_and_excursion_stop_at_the_same_plant_step_as_the_scipy_loop(control):
    """Both loops check the excursion at every plant step: equal trip time, stop time and peak (an
    adaptive step that would pass the limit inside is retried to end on that plant step)."""
    device = preset("phantom-3dof").with_params(NONLINEAR)
    paths = {1: Held(0.0), 2: Held(0.0)}
    tripping = LoopConfig(duration=1.5, wall=Wall(0, 30.0, equilibrium=0.01), safety_limit=0.0217, step_control=control)
    fast, slow = simulate(device, tripping, paths), simulate_adaptive(device, tripping, paths)
    assert fast.trip_time is not None and fast.trip_time == pytest.approx(slow.trip_time, abs=1e-12)
    assert abs(fast.trip_time * 1e3 - round(fast.trip_time * 1e3)) > 1e-6  # between two samples
    stopping = LoopConfig(duration=1.5, wall=Wall(0, 30.0, equilibrium=0.01), stop_excursion=0.012, step_control=control)
    fast, slow = simulate(device, stopping, paths), simulate_adaptive(device, stopping, paths)
    assert fast.stopped_at_excursion and slow.stopped_at_excursion
    assert fast.end_time == pytest.approx(slow.end_time, abs=1e-12)
    assert fast.peak == pytest.approx(slow.peak, rel=1e-7) and fast.peak >= 0.012


@pytest.mark.parametrize("control", ["fixed", "adaptive"])
def test_coulomb_friction_and_group_errors_match_the_scipy_loop(control):
    """Friction in the plant and a seeded per-group modelling error: both loops agree."""
    device = preset("phantom-3dof").with_params(NONLINEAR)
    compensator = Compensator(group_errors=(("mass", 5.0), ("inertia", 10.0)), error_seed=3)
    config = LoopConfig(duration=0.3, wall=Wall(0, 5.0, equilibrium=0.01), compensator=compensator,
                        loop=SampledLoop.seed(wall_damping=0.01),
                        coulomb=(0.004, 0.002, 0.001), step_control=control)
    paths = {1: Sine(0.52, 3 * np.pi), 2: Sine(0.52, 3 * np.pi)}
    fast, slow = simulate(device, config, paths), simulate_adaptive(device, config, paths, rtol=1e-10, atol=1e-12)
    assert np.abs(fast.q - slow.q).max() < 1e-8
    frictionless = simulate(device, LoopConfig(duration=0.3, wall=Wall(0, 5.0, equilibrium=0.01), compensator=compensator,
                                               loop=SampledLoop.seed(wall_damping=0.01)),
                            paths)
    assert np.abs(frictionless.q - fast.q).max() > 1e-5  # the friction is felt


def test_coulomb_friction_holds_a_joint_below_its_breakaway_torque():
    """A free joint under a constant torque smaller than its Coulomb friction barely creeps
    (velocity below the smoothing scale v_f), and slides when the torque exceeds it."""
    from hapticdesign.simulation.config import FRICTION_VELOCITY

    device = preset("phantom-3dof")
    paths = {1: Held(0.0), 2: Held(0.0)}
    base = dict(duration=1.0, compensator=Compensator(False, False, False), safety_limit=None)
    # the wall at equilibrium 0.01 with K = 1 pushes with 0.01 N m at the start
    held = simulate(device, LoopConfig(**base, wall=Wall(0, 1.0, equilibrium=0.01), coulomb=(0.05, 0, 0)), paths)
    slid = simulate(device, LoopConfig(**base, wall=Wall(0, 1.0, equilibrium=0.01), coulomb=(0.002, 0, 0)), paths)
    assert np.abs(held.qd[:, 0]).max() < FRICTION_VELOCITY
    assert np.abs(slid.qd[:, 0]).max() > 3 * FRICTION_VELOCITY


def test_adaptive_steps_shrink_where_the_plant_is_stiff():
    """Coulomb friction ``F_c tanh(qd / v_f)`` is stiff near rest (slope F_c / v_f): the error control
    takes shorter steps there than on the frictionless plant, and both runs stay on SciPy's."""
    device = preset("phantom-3dof").with_params(NONLINEAR)
    paths = {1: Held(0.0), 2: Held(0.0)}
    damped = dict(wall=Wall(0, 5.0, equilibrium=0.01), loop=SampledLoop.seed(wall_damping=0.01))
    smooth = LoopConfig(duration=0.5, step_control="adaptive", **damped)
    stiff = LoopConfig(duration=0.5, step_control="adaptive", coulomb=(0.02, 0.0, 0.0), **damped)
    runs = [(simulate(device, c, paths), simulate_adaptive(device, c, paths, rtol=1e-10, atol=1e-12)) for c in (smooth, stiff)]
    for fast, slow in runs:
        assert np.abs(fast.q - slow.q).max() < 1e-8
    assert runs[0][0].steps == 500  # one step per sample period
    assert runs[1][0].steps > 600
