"""Gravity's gradient in the linearized sampled loop (issue 35): the plant's ``K_G = dG/dq`` and the compensator's
``s K_G`` on the sensed (delayed) pose, against closed forms, python-control and the simulated loop.

The pendulum: one point mass ``m`` at ``l`` from a horizontal axis, hanging at q = 0, so ``G = m g l sin q`` and its
linearized stiffness about the pose is ``m g l cos q`` (textbook). Its loop's limit is built here from scratch with
python-control: the plant ``J qdd + b qd + K_G q = u`` discretized with ``control.c2d`` (zero-order hold), the wall's
spring ``K`` and the compensator's ``- s K_G`` on the position ``d`` samples late (``z^-d``), closed with
``control.feedback``, and the spring at which the largest pole modulus reaches 1 bisected.
"""

from __future__ import annotations

import json
import math

import control
import numpy as np
import pytest
from scipy.optimize import brentq

from hapticdesign.analysis.dynamics.device import gravity_gradient, mass_matrix
from hapticdesign.analysis.sampled_loop import SampledLoop
from hapticdesign.analysis.wall_stiffness import wall_limit
from hapticdesign.devices.device_file import device_from_mapping
from hapticdesign.simulation.impedance import simulated_limit, stability_limit

M, L, B, G, PERIOD = 0.5, 0.2, 0.002, 9.81, 1e-3


def _pendulum_file(name: str, turn: str) -> dict:
    """A link turning about an axis along the base's y, its mass at ``l``, turned by ``turn`` from the base's x at
    q = 0 (``-pi/2``: hanging straight down; ``pi/2``: standing straight up)."""
    return {
        "name": name, "parameters": {"l": L},
        "joints": [{"name": "q1", "damping": B}],
        "frames": [{"name": "arm", "transforms": [{"Rx": "pi/2"}, {"Rz": turn}, {"Rz": "q1"}]},
                   {"name": "tip", "parent": "arm", "transforms": [{"tx": "l"}]}],
        "bodies": [{"name": "bob", "frame": "tip", "m": M}],
        "end_effector": "tip",
    }


def _pendulum():
    """The pendulum hanging straight down at q = 0."""
    return device_from_mapping(_pendulum_file("pendulum", "-pi/2"))


def _python_control_limit(j: float, b: float, k_g: float, share: float, delay: int, period: float = PERIOD) -> float:
    plant = control.c2d(control.ss([[0.0, 1.0], [-k_g / j, -b / j]], [[0.0], [1.0 / j]], [[1.0, 0.0]], [[0.0]]),
                        period, "zoh")
    lag = control.tf([1.0], [1.0] + [0.0] * delay, period)

    def radius(k):
        return np.abs(control.poles(control.feedback(plant * lag, k - share * k_g))).max()

    assert radius(1e-6) < 1.0
    hi = next(2.0 ** e for e in range(60) if radius(2.0 ** e) >= 1.0)
    return brentq(lambda k: radius(k) - 1.0, 1e-6, hi, xtol=1e-14, rtol=1e-12)


@pytest.mark.parametrize("q", [0.0, 0.4, -1.1])
def test_the_gradient_is_m_g_l_cos_q(q):
    device = _pendulum()
    assert mass_matrix(device, np.array([q]))[0, 0] == pytest.approx(M * L * L, rel=1e-12)
    assert gravity_gradient(device, np.array([q]))[0, 0] == pytest.approx(M * G * L * math.cos(q), rel=1e-8)


@pytest.mark.parametrize("loop, share", [(SampledLoop(compensation="none"), 0.0),
                                         (SampledLoop(compensation="none", delay=0), 0.0),
                                         (SampledLoop(compensation="none", delay=2, velocity="sampled"), 0.0),
                                         (SampledLoop(error_percent=30.0), 0.7), (SampledLoop(error_percent=60.0, delay=2), 0.4)])
def test_the_pendulums_limit_is_python_controls_loop_with_its_gravity_stiffness(loop, share):
    """Without compensation (``s = 0``) or with a wrong model (``s = 1 - E/100``: the bob sits on the tip frame with no
    mass-centre offset, so a model whose mass is ``1 - E/100`` times the bob's feeds that share of ``m g l sin q``;
    written here, not read from the loop), at the hanging pose and tilted."""
    device = _pendulum()
    for q in (0.0, 0.6):
        k_g = M * G * L * math.cos(q)
        pose = np.array([q])
        ours = wall_limit(np.array([[1.0], [0.0], [0.0]]), mass_matrix(device, pose), device.damping_matrix, loop,
                          np.array([1.0, 0.0, 0.0]), gravity_gradient(device, pose))
        expected = _python_control_limit(M * L * L, B, k_g, share, loop.delay)
        assert ours == pytest.approx(expected, rel=1e-7)
        without = _python_control_limit(M * L * L, B, 0.0, 0.0, loop.delay)
        assert abs(expected / without - 1.0) > 1e-6  # 10 times the tolerance: leaving gravity out would fail


def test_the_undercompensated_pendulums_simulated_limit_is_the_exact_one():
    """A gravity compensator whose model is 60 % light (``s = 0.4``), no friction, no quantization: the loop is linear
    about the hanging pose, so the simulated growth boundary (bisected to 1e-3) is the exact limit with the plant's
    ``m g l`` and the compensator's late ``0.4 m g l`` in it (a joint wall resting 1 mrad from the start; the
    compensator's share moves the limit by far more than the tolerance)."""
    device = _pendulum()
    loop = SampledLoop(error_percent=60.0)
    exact = stability_limit(device, loop, equilibrium=1e-3).stiffness
    simulated = simulated_limit(device, loop, equilibrium=1e-3, rel_tol=1e-3, duration=4.0, friction=False)
    assert simulated == pytest.approx(exact, rel=2e-3)
    k_g = M * G * L * math.cos(1e-3)
    assert exact == pytest.approx(_python_control_limit(M * L * L, B, k_g, 0.4, 1), rel=1e-7)
    assert abs(exact / _python_control_limit(M * L * L, B, 0.0, 0.0, 1) - 1.0) > 0.05


def _offset_pendulum():
    """The pendulum with its mass centre given in the arm's frame (``rx = l``), so a modelling error, which scales the
    mass centres too, gives the compensator ``f^3 m l^2`` and ``f^2 m g l cos q`` (``f = 1 - E/100``), not ``f``
    times the device's."""
    return device_from_mapping({
        "name": "offset pendulum", "joints": [{"name": "q1", "damping": B}],
        "frames": [{"name": "arm", "transforms": [{"Rx": "pi/2"}, {"Rz": "-pi/2"}, {"Rz": "q1"}]}],
        "bodies": [{"name": "bob", "frame": "arm", "m": M, "rx": L}],
        "end_effector": "arm",
    })


def test_a_gravity_compensators_model_error_enters_as_its_model_devices_gradient():
    """Gravity compensation with a 30 % modelling error: the compensator's late gravity stiffness is its model
    device's, ``0.7^2 m g l`` at the hanging pose (python-control's loop), not ``0.7 m g l`` (whose limit is about 10 %
    higher). At the hanging pose the model's leftover gravity torque is 0, so the wall holds the pendulum at its
    spring's rest."""
    device, loop = _offset_pendulum(), SampledLoop(error_percent=30.0)
    for q in (0.0,):
        exact = stability_limit(device, loop, equilibrium=q).stiffness
        k_g = M * G * L * math.cos(q)
        assert exact == pytest.approx(_python_control_limit(M * L * L, B, k_g, 0.7 ** 2, 1), rel=1e-7)
        assert abs(exact / _python_control_limit(M * L * L, B, k_g, 0.7, 1) - 1.0) > 0.05


def test_a_full_compensators_model_error_is_the_simulated_compensators():
    """Full compensation with a 20 % modelling error on the offset pendulum, no friction: the simulated growth
    boundary (whose compensator is the model device, ``H_m = 0.8^3 m l^2``) is the exact limit built with the model
    device's inertia and gravity gradient; the uniform share ``0.8 H`` gives less than a third of it."""
    device, loop = _offset_pendulum(), SampledLoop(compensation="full", error_percent=20.0)
    exact = stability_limit(device, loop, equilibrium=1e-3).stiffness
    simulated = simulated_limit(device, loop, equilibrium=1e-3, rel_tol=1e-3, duration=4.0, friction=False)
    assert simulated == pytest.approx(exact, rel=2e-3)
    pose = np.array([1e-3])
    uniform = wall_limit(np.array([[1.0], [0.0], [0.0]]), mass_matrix(device, pose), device.damping_matrix, loop,
                         np.array([1.0, 0.0, 0.0]), gravity_gradient(device, pose))
    assert uniform < 0.5 * exact


def test_the_analytic_growth_check_holds_the_pendulum_where_gravity_and_the_spring_balance():
    """No compensation, one sample of delay at 50 Hz (so gravity's stiffness matters), a joint wall resting 1 rad
    from the hanging pose: gravity holds the pendulum short of the spring's rest, at ``K (x - 1) + m g l sin x = 0``
    (SciPy's brentq), and its growth boundary is the spring at which python-control's loop linearized there (``m g l
    cos x``) loses stability (a fixed point in K, brentq again). The analytic method's growth check, bisected,
    finds that spring; linearized at the spring's rest instead it would be 0.4 % off."""
    from scipy.optimize import bisect

    from hapticdesign.simulation.analytic import AnalyticProblem
    from hapticdesign.simulation.config import Compensator, LoopConfig

    rest, period = 1.0, 0.02
    config = LoopConfig(loop=SampledLoop.seed(period=period, delay=1), compensator=Compensator(False, False, False))
    problem = AnalyticProblem(_pendulum(), 1, 0, rest, config=config)

    def limit_where_held(k: float) -> float:
        x = brentq(lambda q: k * (q - rest) + M * G * L * math.sin(q), -1.0, rest, xtol=1e-15)
        return _python_control_limit(M * L * L, B, M * G * L * math.cos(x), 0.0, 1, period)

    expected = brentq(lambda k: limit_where_held(k) - k, 1e-3, 1.0, xtol=1e-14)
    found = bisect(lambda k: 1.0 if problem.grows(k) else -1.0, 1e-3, 1.0, xtol=1e-13)
    assert found == pytest.approx(expected, rel=1e-7)
    at_rest = _python_control_limit(M * L * L, B, M * G * L * math.cos(rest), 0.0, 1, period)
    assert abs(at_rest / expected - 1.0) > 1e-3


def _python_control_radius(j: float, b: float, k_g: float, share: float, delay: int, period: float = PERIOD):
    """The largest pole modulus of python-control's loop of the pendulum under a spring ``K`` (a function of K)."""
    plant = control.c2d(control.ss([[0.0, 1.0], [-k_g / j, -b / j]], [[0.0], [1.0 / j]], [[1.0, 0.0]], [[0.0]]),
                        period, "zoh")
    lag = control.tf([1.0], [1.0] + [0.0] * delay, period)
    return lambda k: np.abs(control.poles(control.feedback(plant * lag, k - share * k_g))).max()


@pytest.mark.parametrize("up, share, delay", [(True, 0.0, 1), (True, 0.0, 0), (False, 1.4, 1)])
def test_gravity_pulling_off_the_wall_leaves_a_stable_interval(up, share, delay):
    """The pendulum standing up (``K_G = -m g l``) without compensation, or hanging with a model 40 % too heavy
    compensating its gravity (net ``-0.4 m g l``): springs softer than gravity's pull are unstable, stiff ones too, so
    the stable springs are an interval. Both ends are the crossings of python-control's largest pole modulus through
    1 (sign changes on a grid, each closed by SciPy's brentq); the grouped search (the worst of two walls, the second
    acting through 0.95, so its interval is the first's over 0.9025) gives their intersection."""
    from hapticdesign.analysis.sampled_loop import handle_intervals

    k_g = (-1.0 if up else 1.0) * M * G * L
    low, high = _python_control_interval(k_g, share, delay)
    loop = SampledLoop(compensation="none" if share == 0.0 else "gravity", delay=delay,
                       error_percent=100.0 * (1.0 - share) if share else 0.0, velocity="sampled")
    axis, mass = np.array([[[1.0], [0.0], [0.0]]]), np.array([[[M * L * L]]])
    found = handle_intervals(axis, mass, np.array([[B]]), np.array([[1.0]]), loop, gravity=np.array([[[k_g]]]))
    assert found[0][0] == pytest.approx(low, rel=1e-7) and found[1][0] == pytest.approx(high, rel=1e-7)
    both = handle_intervals(np.repeat(axis, 2, 0), np.repeat(mass, 2, 0), np.array([[B]]), np.array([[1.0], [0.95]]),
                            loop, groups=np.array([0, 0]), gravity=np.array([[[k_g]], [[k_g]]]))
    assert both[0][0] == pytest.approx(low / 0.9025, rel=1e-7) and both[1][0] == pytest.approx(high, rel=1e-7)


def test_the_wall_holds_an_uncompensated_pendulum_where_gravity_and_the_spring_balance():
    """No compensation at 50 Hz, a joint wall resting 1 rad from the hanging pose: gravity holds the pendulum at
    ``K (x - 1) + m g l sin x = 0`` (SciPy's brentq), so the exact limit is the fixed point of python-control's limit
    of the loop linearized there (brentq again, 1e-7), not the limit at the spring's rest (0.4 % off); the simulated
    growth boundary (the nonlinear loop, bisected to 1e-3) agrees."""
    rest, period = 1.0, 0.02
    loop = SampledLoop(period=period, compensation="none")
    found = stability_limit(_pendulum(), loop, equilibrium=rest)

    def held(k: float) -> float:
        return brentq(lambda q: k * (q - rest) + M * G * L * math.sin(q), -1.0, rest, xtol=1e-15)

    def limit_where_held(k: float) -> float:
        return _python_control_limit(M * L * L, B, M * G * L * math.cos(held(k)), 0.0, 1, period)

    expected = brentq(lambda k: limit_where_held(k) - k, 1e-3, 1.0, xtol=1e-14)
    assert found.stiffness == pytest.approx(expected, rel=1e-7)
    assert found.pose[0] == pytest.approx(held(expected), abs=1e-9)
    at_rest = _python_control_limit(M * L * L, B, M * G * L * math.cos(rest), 0.0, 1, period)
    assert abs(at_rest / expected - 1.0) > 3e-3
    simulated = simulated_limit(_pendulum(), loop, equilibrium=rest, rel_tol=1e-3, duration=20.0, friction=False)
    assert simulated == pytest.approx(expected, rel=2e-3)


UPRIGHT = _pendulum_file("upright pendulum", "pi/2")
"""The pendulum standing up: its bob straight above the axis at q = 0."""


def _upright_interval() -> tuple[float, float]:
    """python-control's stable joint springs of the uncompensated upright pendulum, one sample late."""
    return _python_control_interval(-M * G * L, 0.0, 1)


def _python_control_interval(k_g: float, share: float, delay: int) -> tuple[float, float]:
    """The pendulum's stable springs (gravity's stiffness ``k_g``, the compensator's share of it, the delay): the
    sign changes of python-control's largest pole modulus - 1 on a grid, each closed by SciPy's brentq."""
    radius = _python_control_radius(M * L * L, B, k_g, share, delay)
    grid = np.geomspace(1e-3, 1e4, 400)
    sign = np.array([radius(k) >= 1.0 for k in grid])
    changes = np.flatnonzero(sign[1:] != sign[:-1])
    assert len(changes) == 2 and sign[0] and sign[-1]
    low, high = (brentq(lambda k: radius(k) - 1.0, grid[i], grid[i + 1], xtol=1e-13, rtol=1e-12) for i in changes)
    return low, high


def test_the_spec_sheet_states_the_upright_pendulums_stable_interval():
    """The spec sheet of the pendulum standing up (its bob straight above the axis at q = 0, ``K_G = -m g l``),
    uncompensated: the handle moves along one line, a wall's ``K`` acts on the joint as ``K l^2``, so the exact row's
    ends are python-control's joint interval (grid sign changes closed by brentq) over ``l^2``, and the page says
    "stable from ... to ..."."""
    from hapticdesign.studies.spec import spec_sheet
    from hapticdesign.studies.spec_page import value_text

    upright = device_from_mapping(UPRIGHT)
    pose = np.array([0.0])
    assert gravity_gradient(upright, pose)[0, 0] == pytest.approx(-M * G * L, rel=1e-8)
    low, high = _upright_interval()
    sheet = spec_sheet(upright, pose, SampledLoop(compensation="none"), workspace=False, simulate=False)
    row = sheet["renderable_stiffness"]
    assert row["exact_lower"] == pytest.approx(low / L ** 2, rel=1e-6)
    assert row["exact"] == pytest.approx(high / L ** 2, rel=1e-6)
    text = value_text(sheet, "renderable_stiffness")
    assert text.startswith(f"exact stable from {low / L ** 2:.4g} to {high / L ** 2:.4g};")


def test_the_spec_sheet_of_a_hanging_pendulum_has_no_lower_end():
    """Hanging (``K_G = m g l``), uncompensated: stable from the smallest spring, ``exact_lower`` 0 and the row's
    ``exact`` python-control's limit over ``l^2``."""
    from hapticdesign.studies.spec import spec_sheet

    row = spec_sheet(_pendulum(), np.array([0.0]), SampledLoop(compensation="none"), workspace=False,
                     simulate=False)["renderable_stiffness"]
    assert row["exact_lower"] == 0.0
    assert row["exact"] == pytest.approx(_python_control_limit(M * L * L, B, M * G * L, 0.0, 1) / L ** 2, rel=1e-6)


def test_the_spec_command_states_the_upright_pendulums_lower_end(tmp_path):
    """``spec --json`` of the upright pendulum's device file, uncompensated: ``exact_lower`` and ``exact`` are
    python-control's joint interval over ``l^2``."""
    from typer.testing import CliRunner

    from hapticdesign.interface.cli import app

    path = tmp_path / "upright.json"
    path.write_text(json.dumps(UPRIGHT))
    result = CliRunner().invoke(app, ["spec", "--device", str(path), "--compensation", "none", "--no-simulate",
                                      "--json"])
    assert result.exit_code == 0, result.output
    row = json.loads(result.stdout)["renderable_stiffness"]
    low, high = _upright_interval()
    assert row["exact_lower"] == pytest.approx(low / L ** 2, rel=1e-6)
    assert row["exact"] == pytest.approx(high / L ** 2, rel=1e-6)


TILT = 0.6
"""The tilted pendulum's angle from hanging at q = 0 (rad): gravity's torque ``m g l sin(TILT + q)`` is not 0 there."""


@pytest.mark.parametrize("compensation, error, share", [("none", 0.0, 0.0), ("gravity", 50.0, 0.5)])
def test_a_cartesian_wall_holds_a_tilted_pendulum_where_its_spring_and_the_leftover_gravity_balance(
        compensation, error, share):
    """A Cartesian wall (N/m) along the handle's motion at q = 0 (the tangent ``n = (cos t, 0, sin t)`` of the tilted
    pendulum, ``t`` = :data:`TILT`), resting there, at 50 Hz: the handle's coordinate along ``n`` is ``l sin q``, so
    the wall's joint row is ``w = l cos q`` (``|w| = l``, not 1) and its spring acts on the joint as ``K w^2``. The
    gravity the compensator leaves (all of it, or the half a 50 % light model leaves: the bob sits on the tip frame,
    so the model's gravity is ``0.5 m g l sin``) pushes the handle into the spring, which holds it where ``K l^2 x +
    (1 - s) m g l sin(t + x) = 0`` (the wall's row at its rest, SciPy's brentq), and the exact limit is the fixed
    point of python-control's limit of the loop linearized there (``m g l cos(t + x)``, the compensator's late ``s``
    share, the spring ``K l^2 cos^2 x``; brentq again). Dividing the rest's Newton step by ``|w|`` instead of ``|w|^2``
    (a joint wall's ``|w| = 1`` hides it) moves the rest and the limit by more than 10 %."""
    period = 0.02
    direction = (math.cos(TILT), 0.0, math.sin(TILT))
    device = device_from_mapping(_pendulum_file("tilted pendulum", f"-pi/2 + {TILT}"))
    loop = SampledLoop(period=period, compensation=compensation, error_percent=error)
    found = stability_limit(device, loop, equilibrium=0.0, direction=direction)

    def held(k: float) -> float:
        return brentq(lambda x: k * L ** 2 * x + (1.0 - share) * M * G * L * math.sin(TILT + x), -TILT, 0.0,
                      xtol=1e-15)

    def limit_where_held(k: float) -> float:
        x = held(k)
        joint = _python_control_limit(M * L * L, B, M * G * L * math.cos(TILT + x), share, 1, period)
        return joint / (L * math.cos(x)) ** 2

    expected = brentq(lambda k: limit_where_held(k) - k, 1e-2, 1e3, xtol=1e-14)
    assert found.stiffness == pytest.approx(expected, rel=1e-7)
    assert found.pose[0] == pytest.approx(held(expected), abs=1e-9)
    at_rest = _python_control_limit(M * L * L, B, M * G * L * math.cos(TILT), share, 1, period) / L ** 2
    assert abs(at_rest / expected - 1.0) > 0.05  # leaving the leftover gravity's push out would fail
