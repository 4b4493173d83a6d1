"""R-CUBE dynamics (seed 001 §5.3): M_C and B* against independent constructions."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hapticdesign.analysis.kinematics import forward_kinematics as core_fk
from hapticdesign.analysis.metrics.dynamic import modes
from hapticdesign.analysis.rcube import dynamics as D
from hapticdesign.analysis.rcube.design import final_design, uniform_design
from hapticdesign.analysis.rcube.kinematics import inverse_kinematics
from hapticdesign.model.rcube import chain_mechanism

DESIGN = final_design()
GEOM = DESIGN.geometry
OFF_CENTRE = replace(uniform_design(GEOM, 0.02, 0.01, density=2000.0), centres=(0.3, 0.6, 0.45), platform_mass=0.05)


# M_C of the final design against the kinetic energy of textbook tubes: tests/rcube/test_anchors.py


def kinetic_energy(design, r: np.ndarray, v: np.ndarray, h: float = 1e-6) -> float:
    """Nine thick-walled tubes (textbook inertia about their centres, mass rho pi (D^2 - d^2) L / 4) with
    their centres at ``centres`` along the links, plus the platform as a point mass: velocities from
    central differences of the frames along the path r + t v."""
    g = design.geometry
    q0, qp, qm = (inverse_kinematics(g, x) for x in (r, r + h * v, r - h * v))
    total = 0.5 * design.platform_mass * v @ v
    for i in range(3):
        mech = chain_mechanism(g, i, design.centres)
        for j, (link, L) in enumerate(zip(design.links, (g.l1, g.l2, g.l3))):
            D_, d_ = link.section.D, link.section.d
            m = link.density * np.pi * (D_**2 - d_**2) / 4 * L
            s = (D_ / 2) ** 2 + (d_ / 2) ** 2
            I_local = np.diag([m * s / 2, m * (3 * s + L**2) / 12, m * (3 * s + L**2) / 12])
            H0, Hp, Hm = (core_fk(mech, q[i], f"com{j + 1}") for q in (q0, qp, qm))
            vel = (Hp[:3, 3] - Hm[:3, 3]) / (2 * h)
            W = (Hp[:3, :3] - Hm[:3, :3]) / (2 * h) @ H0[:3, :3].T
            w = np.array([W[2, 1], W[0, 2], W[1, 0]])
            total += 0.5 * m * vel @ vel + 0.5 * w @ (H0[:3, :3] @ I_local @ H0[:3, :3].T) @ w
    return total


def test_off_centre_tubes_and_platform_mass_against_their_kinetic_energy():
    """Tubes off their link middles (the parallel-axis shift to the joint frames) and a shared platform mass."""
    rng = np.random.default_rng(3)
    for r in (GEOM.home, GEOM.home + rng.uniform(-0.05, 0.05, 3)):
        v = rng.normal(size=3)
        M = D.cartesian_mass_matrix(OFF_CENTRE, r)
        assert 0.5 * v @ M @ v == pytest.approx(kinetic_energy(OFF_CENTRE, r, v), rel=1e-7)


def test_a_batch_of_positions_equals_the_positions_one_by_one():
    """A batch goes through the engine's fitted model, one position through its kernel: both exact."""
    r = GEOM.home + np.random.default_rng(4).uniform(-0.05, 0.05, (2, 5, 3))
    batch = D.cartesian_mass_matrix(OFF_CENTRE, r)
    single = np.array([[D.cartesian_mass_matrix(OFF_CENTRE, x) for x in row] for row in r])
    assert batch.shape == (2, 5, 3, 3)
    assert np.allclose(batch, single, rtol=1e-12, atol=0.0)


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
    # central differences of step h = 1e-5 m: truncation ~ h^2 |d^3 M_C| / 6 and round-off ~ eps |M_C| / h,
    # both below 1e-7 of |B*| here; rtol 1e-5 leaves a wide margin and catches any wrong term
    assert np.allclose(D.nonlinear_terms(DESIGN, r, v), expected, rtol=1e-5, atol=1e-9)
    assert np.allclose(D.nonlinear_terms(DESIGN, r, np.zeros(3)), 0.0)


@pytest.mark.parametrize("design", [DESIGN, OFF_CENTRE], ids=["final", "off-centre"])
def test_nonlinear_terms_balance_the_kinetic_energy_along_a_motion(design):
    """Energy balance of M_C r_dd + B* = F (eq. 5.225): dT/dt = r_dot . (M_C r_dd + B*) along r(t), with
    T = 1/2 r_dot^T M_C r_dot differentiated in time by central differences. Their error scales with
    dt^2 (dt = 1e-4 s leaves 2.4e-6 of dT/dt), so dt = 1e-5 s leaves ~2e-8, inside rel 1e-6."""
    r0, a, w = design.geometry.home + np.array([0.01, -0.02, 0.015]), np.array([0.02, 0.03, -0.025]), np.array([3.0, 5.0, 7.0])

    def state(t):
        return r0 + a * np.sin(w * t), a * w * np.cos(w * t), -a * w**2 * np.sin(w * t)

    def energy(t):
        r, v, _ = state(t)
        return 0.5 * v @ D.cartesian_mass_matrix(design, r) @ v

    for t in (0.1, 0.4, 0.9):
        r, v, acc = state(t)
        dt = 1e-5
        dT = (energy(t + dt) - energy(t - dt)) / (2 * dt)
        power = v @ (D.cartesian_mass_matrix(design, r) @ acc + D.nonlinear_terms(design, r, v))
        assert power == pytest.approx(dT, rel=1e-6)
        assert abs(v @ D.nonlinear_terms(design, r, v)) > 1e-3 * abs(dT)  # B* carries a share of the power


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
