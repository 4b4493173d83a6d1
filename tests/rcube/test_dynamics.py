"""R-CUBE dynamics (seed 001 §5.3): M_C and B* against independent constructions."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.kinematics import forward_kinematics as core_fk
from hapticdesign.analysis.metrics.dynamic import modes
from hapticdesign.analysis.rcube import dynamics as D
from hapticdesign.analysis.rcube.design import final_design
from hapticdesign.analysis.rcube.kinematics import inverse_kinematics
from hapticdesign.model.rcube import chain_mechanism

DESIGN = final_design()
GEOM = DESIGN.geometry


def kinetic_energy_by_differences(r, v, h=1e-6):
    """Rigid-body kinetic energy from finite differences of the mass-centre frames (no Jacobians)."""
    total = 0.0
    q_plus, q_minus = inverse_kinematics(GEOM, r + h * v), inverse_kinematics(GEOM, r - h * v)
    for i in range(3):
        mech = chain_mechanism(GEOM, i)
        for j, (link, L, m) in enumerate(zip(DESIGN.links, DESIGN.lengths, DESIGN.link_masses())):
            Hp, Hm = core_fk(mech, q_plus[i], f"com{j + 1}"), core_fk(mech, q_minus[i], f"com{j + 1}")
            H0 = core_fk(mech, inverse_kinematics(GEOM, r)[i], f"com{j + 1}")
            vel = (Hp[:3, 3] - Hm[:3, 3]) / (2 * h)
            W = (Hp[:3, :3] - Hm[:3, :3]) / (2 * h) @ H0[:3, :3].T
            w = np.array([W[2, 1], W[0, 2], W[1, 0]])
            I_world = H0[:3, :3] @ np.diag(D.tube_inertia(m, L, link.section.D, link.section.d)) @ H0[:3, :3].T
            total += 0.5 * m * vel @ vel + 0.5 * w @ I_world @ w
    return total


def test_cartesian_mass_matrix_gives_the_kinetic_energy():
    rng = np.random.default_rng(11)
    for _ in range(3):
        r = GEOM.home + rng.uniform(-0.05, 0.05, 3)
        v = rng.normal(size=3)
        M_C = D.cartesian_mass_matrix(DESIGN, r)
        assert 0.5 * v @ M_C @ v == pytest.approx(kinetic_energy_by_differences(r, v), rel=1e-6)
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


def test_total_link_mass_table_7_9():
    # Table 7.8's tubes at a laminate density of 1.79 g/cm^3: 77.7 g
    assert DESIGN.total_link_mass() == pytest.approx(0.0777, abs=5e-5)


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
