"""R-CUBE dynamics (seed 001 §5.3): M_C and B* against independent constructions."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.metrics.dynamic import modes
from hapticdesign.analysis.rcube import dynamics as D
from hapticdesign.analysis.rcube.design import final_design

DESIGN = final_design()
GEOM = DESIGN.geometry


# M_C against the kinetic energy of textbook tubes: tests/rcube/test_anchors.py


def test_cartesian_mass_matrix_is_symmetric_positive_definite():
    rng = np.random.default_rng(11)
    for _ in range(3):
        M_C = D.cartesian_mass_matrix(DESIGN, GEOM.home + rng.uniform(-0.05, 0.05, 3))
        assert np.allclose(M_C, M_C.T) and np.all(np.linalg.eigvalsh(M_C) > 0)


def test_home_mass_matrix_has_the_symmetric_structure_of_eq_7_6():
    M = D.cartesian_mass_matrix(DESIGN, GEOM.home)
    assert M[0, 0] == pytest.approx(M[1, 1]) == pytest.approx(M[2, 2])
    off = M[~np.eye(3, dtype=bool)]
    assert np.allclose(off, off[0]) and off[0] < 0.0  # eq. 7.6: equal negative couplings


def test_nonlinear_terms_equal_the_cartesian_lagrangian():
    """B* (eq. 5.224, 5.228) = dM_C/dt r_dot - 1/2 d(r_dot^T M_C r_dot)/dr."""
    r = GEOM.home + np.array([0.02, -0.01, 0.03])
    v = np.array([0.3, -0.2, 0.4])
    h = 1e-5
    dM = [(D.cartesian_mass_matrix(DESIGN, r + h * e) - D.cartesian_mass_matrix(DESIGN, r - h * e)) / (2 * h) for e in np.eye(3)]
    M_dot = sum(vk * dMk for vk, dMk in zip(v, dM))
    expected = M_dot @ v - 0.5 * np.array([v @ dMk @ v for dMk in dM])
    assert np.allclose(D.nonlinear_terms(DESIGN, r, v), expected, rtol=1e-5, atol=1e-9)
    assert np.allclose(D.nonlinear_terms(DESIGN, r, np.zeros(3)), 0.0)


def test_seed_dynamic_matrix_from_the_printed_m_c_and_k_c_eq_7_9_to_7_13():
    """The metric code applied to the seed's printed M_C (eq. 7.6) and K_C* (eq. 7.8)."""
    M_C = np.full((3, 3), -0.0039) + np.eye(3) * (0.0429 + 0.0039)
    K = np.eye(3) * 209110.0
    m = modes(M_C, K)
    assert m.D[0, 0] == pytest.approx(4.9664e6, rel=2e-3)
    assert m.D[0, 1] == pytest.approx(0.5002e6, rel=1e-2)  # -0.0039 is printed to two digits
    assert m.norm == pytest.approx(8.6888e6, rel=1e-3)
    assert m.frequencies == pytest.approx([2113.3, 2113.3, 2442.7], rel=1e-3)
    assert np.abs(m.vectors[:, 2]) == pytest.approx([0.5774] * 3, abs=1e-4)
    assert m.vectors[:, :2].T @ np.ones(3) == pytest.approx([0, 0], abs=1e-9)
