"""1-DOF mass-damper: exact boundary (spectral radius of the exact discretization) vs the simulated loop."""

import numpy as np
import pytest
from scipy.signal import cont2discrete

from hapticdesign.errors import UserError
from hapticdesign.simulation.boundary import MassDamper, closed_loop_matrix, exact_boundary, simulated_boundary

CASES = [
    (0.01, 0.5, 1e-3, 0, False),
    (0.002, 0.05, 5e-4, 0, False),
    (0.05, 1.0, 2e-3, 0, False),
    (0.02, 0.3, 1e-3, 1, False),
    (0.039, 0.5, 1e-3, 0, True),
]


@pytest.mark.parametrize("inertia, damping, period, delay, compensate", CASES)
def test_simulated_boundary_agrees_with_exact_within_one_percent(inertia, damping, period, delay, compensate):
    system = MassDamper(inertia, damping, period, delay, compensate_inertia=compensate)
    exact = exact_boundary(system)
    simulated = simulated_boundary(system, rel_tol=2e-3, samples=3000)
    assert abs(simulated - exact) / exact < 0.01


def test_exact_boundary_is_slightly_above_two_b_over_t():
    """Without compensation the limit is about 2b/T, slightly above (CONVENTIONS.md)."""
    for inertia, damping, period in [(0.01, 0.5, 1e-3), (0.1, 0.2, 1e-3), (0.005, 0.1, 2e-4)]:
        k = exact_boundary(MassDamper(inertia, damping, period))
        assert 2 * damping / period < k < 1.02 * 2 * damping / period


def test_full_inertia_compensation_limit_is_b_squared_over_j():
    """Feeding the sampled acceleration forward turns u into a sum: u_k = u_(k-1) - b v_k - K q_k,
    whose exact discrete limit is K = b^2 / J (the scale of the seed's Table 4.4)."""
    for inertia, damping, period in [(0.039, 0.5, 1e-3), (0.01, 0.3, 5e-4), (0.02, 0.5, 2e-3)]:
        k = exact_boundary(MassDamper(inertia, damping, period, compensate_inertia=True))
        assert k == pytest.approx(damping**2 / inertia, rel=1e-8)


def test_discretization_matches_scipy_cont2discrete():
    j, b, t = 0.01, 0.5, 1e-3
    phi, gamma, *_ = cont2discrete((np.array([[0, 1], [0, -b / j]]), np.array([[0], [1 / j]]), np.eye(2), np.zeros((2, 1))), t)
    m = closed_loop_matrix(MassDamper(j, b, t), 0.0)
    assert np.allclose(m[:2, :2], phi, rtol=1e-12, atol=1e-15)
    m1 = closed_loop_matrix(MassDamper(j, b, t), 1.0)
    assert np.allclose(m1[:2, 0] - m[:2, 0], -gamma[:, 0], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("kwargs", [dict(inertia=0.0, damping=0.5, period=1e-3), dict(inertia=0.01, damping=0.5, period=0.0),
                                    dict(inertia=0.01, damping=-0.1, period=1e-3)])
def test_bad_mass_damper_raises(kwargs):
    with pytest.raises(UserError):
        MassDamper(**kwargs)
