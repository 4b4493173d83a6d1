"""1-DOF mass-damper: the exact limit of the one-joint sampled loop (spectral radius of the exact discretization)
against the closed form, SciPy's discretization and the simulated loop, under the settings of a ``SampledLoop``."""

from pathlib import Path

import math

import mpmath
import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq
from scipy.signal import cont2discrete

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.devices.loading import resolve_device
from hapticdesign.errors import UserError
from hapticdesign.analysis.sampled_loop import (
    SampledLoop, compensated_boundary, compensated_limit, joint_limit, joint_limits, joint_loops,
)
from hapticdesign.simulation.boundary import simulated_boundary
from hapticdesign.simulation.config import Compensator, Hand, LoopConfig
from hapticdesign.simulation.impedance import ImpedanceProblem, growth_boundary

CASES = [
    (0.01, 0.5, 1e-3, 0, False),
    (0.002, 0.05, 5e-4, 0, False),
    (0.05, 1.0, 2e-3, 0, False),
    (0.02, 0.3, 1e-3, 1, False),
    (0.039, 0.5, 1e-3, 0, True),
]


@pytest.mark.parametrize("inertia, damping, period, delay, compensate", CASES)
def test_simulated_boundary_agrees_with_exact_within_one_percent(inertia, damping, period, delay, compensate):
    loop = SampledLoop(period=period, delay=delay, velocity="sampled", compensation="full" if compensate else "none")
    exact = joint_limit(inertia, damping, loop)
    simulated = simulated_boundary(inertia, damping, loop, rel_tol=2e-3, samples=3000)
    assert abs(simulated - exact) / exact < 0.01


def test_exact_boundary_is_slightly_above_two_b_over_t():
    """Without compensation the limit is about 2b/T, slightly above."""
    for inertia, damping, period in [(0.01, 0.5, 1e-3), (0.1, 0.2, 1e-3), (0.005, 0.1, 2e-4)]:
        k = joint_limit(inertia, damping, SampledLoop(period=period, delay=0, compensation="none"))
        assert 2 * damping / period < k < 1.02 * 2 * damping / period


def test_full_inertia_compensation_limit_is_b_squared_over_j():
    """Feeding the sampled acceleration forward turns u into a sum: u_k = u_(k-1) - b v_k - K q_k,
    whose exact discrete limit is K = b^2 / J (the scale of the seed's Table 4.4)."""
    for inertia, damping, period in [(0.039, 0.5, 1e-3), (0.01, 0.3, 5e-4), (0.02, 0.5, 2e-3)]:
        k = joint_limit(inertia, damping, SampledLoop.seed(period=period))
        assert k == pytest.approx(damping**2 / inertia, rel=1e-8)


@pytest.mark.parametrize("x", [0.0, 1e-9, 1e-4, 0.5, 0.999, 1.0, 3.0, 40.0])
def test_closed_form_discretization_matches_scipy_cont2discrete_at_every_damping(x):
    """The plant's zero-order hold in closed form (series below x = bT/J = 1) against SciPy's matrix exponential."""
    j, t = 0.02, 1e-3
    b = x * j / t
    phi, gamma, *_ = cont2discrete((np.array([[0, 1], [0, -b / j]]), np.array([[0], [1 / j]]), np.eye(2),
                                    np.zeros((2, 1))), t)
    loops = joint_loops(j, b, SampledLoop(period=t, delay=0, compensation="none"))  # state (q, qd)
    m0, m1 = loops.matrices(np.array([0.0]))[0], loops.matrices(np.array([1e6]))[0]  # m1[:, 0]: phi[:, 0] - 1e6 gamma
    np.testing.assert_allclose(m0[:2, :2], phi, rtol=1e-13, atol=1e-300)
    np.testing.assert_allclose((m0[:2, 0] - m1[:2, 0]) / 1e6, gamma[:, 0], rtol=1e-12)


def test_discretization_matches_scipy_cont2discrete():
    j, b, t = 0.01, 0.5, 1e-3
    phi, gamma, *_ = cont2discrete((np.array([[0, 1], [0, -b / j]]), np.array([[0], [1 / j]]), np.eye(2), np.zeros((2, 1))), t)
    loops = joint_loops(j, b, SampledLoop(period=t, delay=0, compensation="none"))
    m, m1 = loops.matrices(np.array([0.0]))[0], loops.matrices(np.array([1.0]))[0]
    assert np.allclose(m[:2, :2], phi, rtol=1e-12, atol=1e-15)
    assert np.allclose(m1[:2, 0] - m[:2, 0], -gamma[:, 0], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("kwargs", [dict(inertia=0.0, damping=0.5, period=1e-3), dict(inertia=0.01, damping=0.5, period=0.0),
                                    dict(inertia=0.01, damping=-0.1, period=1e-3)])
def test_bad_mass_damper_raises(kwargs):
    with pytest.raises(UserError):
        joint_limit(kwargs["inertia"], kwargs["damping"], SampledLoop(period=kwargs["period"]))


@pytest.mark.parametrize("inertia, damping, period", [(0.04, 0.5, 1e-3), (0.01, 0.2, 5e-4), (0.2, 0.05, 1e-3)])
@pytest.mark.parametrize("fraction", [1.0, 0.99, 0.9, 0.5, 0.0])
def test_closed_form_with_compensator_error_is_the_spectral_radius_boundary(inertia, damping, period, fraction):
    """K* = b^2 (1-a)(1-ac) / [J (1-a)(1-ac) - T a b (1-c)], a = exp(-bT/J), against eigenvalues."""
    loop = (SampledLoop.seed(period=period, error_percent=100.0 * (1.0 - fraction)) if fraction else
            SampledLoop.seed(period=period, compensation="none"))
    assert compensated_boundary(inertia, damping, period, fraction) == pytest.approx(joint_limit(inertia, damping, loop),
                                                                                     rel=1e-8)


def _own_spectral_limit(j: float, b: float, t: float, c: float) -> float:
    """Independent oracle: the loop ``u_k = c (u_(k-1) - b v_k) - K q_k`` on the plant discretized with
    ``scipy.linalg.expm``; the largest K with every eigenvalue inside the unit circle (0 if none)."""
    e = expm(np.array([[0.0, 1.0, 0.0], [0.0, -b / j, 1.0 / j], [0.0, 0.0, 0.0]]) * t)
    phi, gamma = e[:2, :2], e[:2, 2]

    def radius(k: float) -> float:
        law = np.array([-k, -c * b, c])
        m = np.zeros((3, 3))
        m[:2, :2] = phi
        m[:2] += np.outer(gamma, law)
        m[2] = law
        return float(np.max(np.abs(np.linalg.eigvals(m))))

    lo = 1e-9 * b * b / j
    if radius(lo) >= 1.0:
        return 0.0
    hi = 2.0 * lo
    while radius(hi) < 1.0:
        lo, hi = hi, 2.0 * hi
    return brentq(lambda k: radius(k) - 1.0, lo, hi, xtol=1e-14, rtol=1e-12)


@pytest.mark.parametrize("x", [1e-3, 0.01, 0.1, 0.5, 1.0, 2.0, 3.9, 3.99, 4.01, 4.1, 5.0, 7.0, 10.0])
def test_closed_form_is_the_spectral_radius_limit_for_x_up_to_10_and_errors_of_10_percent(x):
    """min(K*, K_-1), or 0 when a c >= 1, equals the eigenvalue limit for x = bT/J up to 10 and
    E = -10 ... 10 % (never negative, never the complex-pair K* where a real pole leaves first)."""
    j, t = 0.01, 1e-3
    b = x * j / t
    for error in (-10.0, -5.0, -1.0, -0.1, 0.0, 0.1, 1.0, 5.0, 10.0):
        c = 1.0 - error / 100.0
        expected = _own_spectral_limit(j, b, t, c)
        found = compensated_boundary(j, b, t, c)
        assert found >= 0.0
        if expected == 0.0:
            assert found == 0.0 and c > 1.0 and math.log(c) >= x * (1 - 1e-9)
        else:
            assert found == pytest.approx(expected, rel=1e-8)


def test_complex_pair_form_holds_up_to_x_4_and_a_real_pole_binds_beyond():
    """At c = 1 K* = b^2/J exactly up to x = 4 (f(4) = 2 (1 + 3 e^-4)); at J = 0.01, b = 5, T = 0.01
    (x = 5) the real pole at z = -1 sets the limit, well below b^2/J = 2500."""
    j, t = 0.01, 0.01
    below = compensated_limit(j, 3.99 * j / t, t, 1.0)
    assert below.bound == "complex pair" and below.stiffness == pytest.approx((3.99 * j / t) ** 2 / j, rel=1e-12)
    assert compensated_limit(j, 4.01 * j / t, t, 1.0).bound == "real pole at z = -1"
    beyond = compensated_limit(j, 5.0, t, 1.0)
    assert beyond.bound == "real pole at z = -1"
    assert beyond.stiffness == pytest.approx(_own_spectral_limit(j, 5.0, t, 1.0), rel=1e-9)
    assert beyond.stiffness == pytest.approx(1674.04, abs=0.01)


def test_overestimated_inertia_has_no_stable_spring_when_a_c_reaches_1():
    """c = 1.05 at x = 0.0128 (J = 0.039, b = 0.5, T = 1 ms): a c > 1, every spring is unstable: 0, not
    the negative value of K* (whose denominator argument no longer applies)."""
    j, b, t, c = 0.039, 0.5, 1e-3, 1.05
    limit = compensated_limit(j, b, t, c)
    assert limit.stiffness == 0.0 and limit.bound == "no stable spring"
    assert _own_spectral_limit(j, b, t, c) == 0.0
    a = math.exp(-b * t / j)
    plain = b * b * (1 - a) * (1 - a * c) / (j * (1 - a) * (1 - a * c) - t * a * b * (1 - c))
    assert plain < 0


@pytest.mark.parametrize("x", [1e-9, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3])
@pytest.mark.parametrize("c", [1.0, 0.999, 0.99, 0.9, 0.0])
def test_closed_form_keeps_full_precision_for_small_x(x, c):
    """K* at small x against the same expression in 60-digit arithmetic (mpmath): no rounding loss."""
    j, t = 0.01, 1e-3
    b = x * j / t
    with mpmath.workdps(60):
        jm, bm, tm, cm = (mpmath.mpf(v) for v in (j, b, t, c))
        a = mpmath.exp(-bm * tm / jm)
        reference = bm ** 2 * (1 - a) * (1 - a * cm) / (jm * (1 - a) * (1 - a * cm) - tm * a * bm * (1 - cm))
    assert compensated_boundary(j, b, t, c) == pytest.approx(float(reference), rel=1e-13)


def test_closed_form_limits():
    j, b, t = 0.04, 0.5, 1e-3
    assert compensated_boundary(j, b, t, 1.0) == pytest.approx(b * b / j, rel=1e-12)
    near = compensated_boundary(j, b, t, 0.999) - b * b / j
    assert near == pytest.approx(0.001 * b / t, rel=0.02)
    assert compensated_boundary(j, b, t, 0.0) == pytest.approx(2 * b / t, rel=0.01)


@pytest.mark.parametrize("error_percent", [1.0, 20.0])
def test_simulated_loop_with_compensator_error_meets_the_closed_form(error_percent):
    j, b, t = 0.039, 0.5, 1e-3
    c = 1 - error_percent / 100
    simulated = simulated_boundary(j, b, SampledLoop.seed(period=t, error_percent=error_percent), rel_tol=1e-4,
                                   samples=4000)
    assert simulated == pytest.approx(compensated_boundary(j, b, t, c), rel=2e-3)


def test_hand_on_a_one_dof_device_meets_the_exact_discrete_analysis():
    """A hand (mass m_h, damping b_h, stiffness k_h at radius r) adds m_h r^2 to the plant's inertia
    (not to the compensator's model), b_h r^2 to its damping and a physical spring k_h r^2: the
    simulated growth boundary of the device equals the spectral-radius boundary of that 1-DOF loop."""
    device = resolve_device(None, Path(__file__).with_name("one_link.yaml"), None)
    j = mass_matrix(device, np.zeros(1))[0, 0]
    assert j == pytest.approx(0.007, rel=1e-12)
    r2 = 0.15 ** 2
    hand = Hand(mass=0.4, damping=2.0, stiffness=40.0)
    config = LoopConfig(loop=SampledLoop.seed(hand=hand), compensator=Compensator(coriolis=False, gravity=False))
    simulated = growth_boundary(ImpedanceProblem(device, 1, config=config))
    at_joint = Hand(hand.mass * r2, hand.damping * r2, hand.stiffness * r2)  # the hand seen at the joint
    exact = joint_limit(j, 0.3, SampledLoop.seed(hand=at_joint))
    assert simulated == pytest.approx(exact, rel=2e-3)
    without_mass = joint_limit(j, 0.3, SampledLoop.seed(hand=Hand(0.0, at_joint.damping, at_joint.stiffness)))
    assert abs(without_mass - exact) > 0.2 * exact


def _random_joints(rng, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Inertias and dampings over two decades each."""
    return 10 ** rng.uniform(-3, -1, count), 10 ** rng.uniform(-2, 0, count)


@pytest.mark.parametrize("delay", [0, 1, 2, 3])
@pytest.mark.parametrize("compensate", [False, True])
def test_batched_limits_are_each_joints_limit(delay, compensate):
    """One batched search over random joints gives each joint's own limit, searched alone, to 1e-9 (a virtual damper
    and a 5 % model error in the compensated case), and, uncompensated, python-control's loop of each joint to 1e-8."""
    j, b = _random_joints(np.random.default_rng(10 * delay + compensate), 4)
    loop = SampledLoop(period=5e-4, delay=delay, velocity="sampled", compensation="full" if compensate else "none",
                       error_percent=5.0 if compensate else 0.0, wall_damping=0.005)
    batched = joint_limits(j, b, loop)
    for inertia, damping, limit in zip(j, b, batched):
        assert limit == pytest.approx(joint_limit(inertia, damping, loop), rel=1e-9)
        if not compensate:  # python-control's loop of the joint, built here
            assert limit == pytest.approx(_python_control_joint_limit(inertia, damping, 5e-4, delay, 0.005), rel=1e-8)


def _python_control_joint_limit(j: float, b: float, period: float, delay: int, wall_damping: float) -> float:
    """The stable spring of an uncompensated joint ``J qdd + b qd = u`` (zero-order hold, ``control.c2d``) whose
    sampled position and velocity reach the wall ``u = -(K q + B_w qd)`` ``delay`` samples late (``z^-d``), closed
    with ``control.feedback``: the spring at which the largest pole modulus reaches 1 (brentq)."""
    import control

    plant = control.c2d(control.ss([[0.0, 1.0], [0.0, -b / j]], [[0.0], [1.0 / j]], np.eye(2), [[0.0], [0.0]]),
                        period, "zoh")
    late = plant * control.ss(control.tf([1.0], [1.0] + [0.0] * delay, period)) if delay else plant

    def radius(k: float) -> float:
        return float(np.abs(control.poles(control.feedback(late, np.array([[k, wall_damping]])))).max())

    hi = next(2.0 ** e for e in range(-10, 80) if radius(2.0 ** e) >= 1.0)
    return brentq(lambda k: radius(k) - 1.0, hi / 2.0 if radius(hi / 2.0) < 1.0 else 1e-9, hi, xtol=1e-14,
                  rtol=1e-12)


def test_grouped_search_gives_each_groups_smallest_limit():
    """The smallest limit per group (joints leave the search once another joint of their group is unstable below
    their stable spring) equals the smallest of the joints searched alone; under a compensator over-estimating the
    inertia by 5 %, a joint at x = bT/J below ln 1.05 has no stable spring (0) and settles its group at 0, and joints
    stable up to ``k_max`` give inf."""
    rng = np.random.default_rng(3)
    j = np.concatenate([10 ** rng.uniform(-3, -2.7, 11), [0.039, 1e-3, 1e-3]])
    b = np.concatenate([10 ** rng.uniform(0.3, 0.7, 11), [0.5, 50.0, 50.0]])
    loop = SampledLoop.seed(period=1e-4, delay=1, error_percent=-5.0)
    groups = np.array([0] * 5 + [1] * 6 + [1] + [2] * 2)
    alone = np.array([joint_limit(i, d, loop, k_max=1e5) for i, d in zip(j, b)])
    smallest = joint_limits(j, b, loop, groups, k_max=1e5)
    expected = [alone[groups == g].min() for g in range(3)]
    np.testing.assert_allclose(smallest, expected, rtol=1e-12)
    assert 0.0 < smallest[0] < math.inf and smallest[1] == 0.0 and smallest[2] == math.inf
