"""Properties any correct equations of motion must have (seed 000 §2.4, Appendix A.2)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tests.conftest import random_standard_parameters
from hapticdesign.analysis.dynamics.device import dynamics_of, forward_dynamics, inverse_dynamics


@pytest.mark.parametrize("name", ["phantom3", "phantom6"])
def test_mass_matrix_positive_definite_and_passivity(name, request):
    device = request.getfixturevalue(name)
    model = dynamics_of(device)
    rng = np.random.default_rng(7)
    n = model.n_dof
    for _ in range(5):
        pi = random_standard_parameters(rng, len(device.body_names))
        q = rng.uniform(-np.pi, np.pi, n)
        qd = rng.normal(size=n)
        h = model.H(q, pi)
        assert np.allclose(h, h.T, atol=1e-15)
        assert np.linalg.eigvalsh(h)[0] > 0
        eps = 1e-6
        hdot = (model.H(q + eps * qd, pi) - model.H(q - eps * qd, pi)) / (2 * eps)
        n_mat = hdot - 2 * model.C_cvt(q, qd, pi)
        assert np.abs(n_mat + n_mat.T).max() <= 1e-7 * np.abs(hdot).max()


@pytest.mark.parametrize("name", ["phantom3", "phantom6"])
def test_christoffel_from_finite_differences(name, request):
    """C's columns hold Gamma_ijj and 2 Gamma_ijk built from dH/dq (eq. 2.50; Appendix A.2's code computes them so)."""
    device = request.getfixturevalue(name)
    model = dynamics_of(device)
    rng = np.random.default_rng(3)
    n = model.n_dof
    pi = random_standard_parameters(rng, len(device.body_names))
    q = rng.uniform(-np.pi, np.pi, n)
    eps = 1e-6
    dh = np.stack([(model.H(q + eps * e, pi) - model.H(q - eps * e, pi)) / (2 * eps) for e in np.eye(n)], axis=-1)
    c = model.C(q, pi)
    for i in range(n):
        for col, (j, k) in enumerate(model.pairs):
            gamma = 0.5 * (dh[i, j, k] + dh[i, k, j] - dh[j, k, i])
            expected = gamma if j == k else 2 * gamma
            assert c[i, col] == pytest.approx(expected, abs=1e-8 * np.abs(dh).max())


def test_energy_balance_without_gravity(phantom3):
    """With g = 0 and no torque, kinetic energy 1/2 qd^T H qd is conserved by forward dynamics."""
    device = phantom3.with_params({"g": 0.0})
    rng = np.random.default_rng(11)
    pi = random_standard_parameters(rng, len(device.body_names))
    model = dynamics_of(device)

    def rhs(_t, x):
        q, qd = x[:3], x[3:]
        return np.concatenate([qd, model.forward(q, qd, np.zeros(3), pi)])

    x0 = np.concatenate([rng.uniform(-1, 1, 3), rng.normal(size=3)])
    sol = solve_ivp(rhs, (0, 2.0), x0, rtol=1e-11, atol=1e-12)
    energy = [0.5 * x[3:] @ model.H(x[:3], pi) @ x[3:] for x in sol.y.T]
    assert np.ptp(energy) <= 1e-8 * energy[0]


def test_work_energy_with_gravity(phantom3):
    """d/dt (kinetic + potential) = 0 without torque: the gravity torque derives from a potential."""
    rng = np.random.default_rng(5)
    model = dynamics_of(phantom3)
    pi = random_standard_parameters(rng, 5)
    q0 = rng.uniform(-1, 1, 3)
    path = np.linspace(0, 1, 2001)[:, None] * rng.normal(size=3) + q0
    g = model.G(path, pi)
    work = np.sum(np.einsum("pi,pi->p", g[1:] + g[:-1], np.diff(path, axis=0)) / 2)
    # potential difference between the end points, integrated along another path
    detour = np.concatenate([np.linspace(q0, q0 + [0, 1, 0], 1001), np.linspace(q0 + [0, 1, 0], path[-1], 1001)])
    gd = model.G(detour, pi)
    work_detour = np.sum(np.einsum("pi,pi->p", gd[1:] + gd[:-1], np.diff(detour, axis=0)) / 2)
    assert work == pytest.approx(work_detour, rel=1e-5, abs=1e-9)


def test_vectorized_over_poses_and_parameter_sets(phantom6):
    model = dynamics_of(phantom6)
    rng = np.random.default_rng(2)
    pis = np.stack([random_standard_parameters(rng, 8) for _ in range(3)])
    qs = rng.uniform(-3, 3, (4, 6))
    batch = model.H(qs, pis)
    assert batch.shape == (3, 4, 6, 6)
    for s in range(3):
        for p in range(4):
            assert np.allclose(batch[s, p], model.H(qs[p], pis[s]), rtol=1e-13, atol=1e-16)


def test_inverse_forward_roundtrip(phantom6):
    rng = np.random.default_rng(9)
    q, qd, qdd = rng.normal(size=(3, 6))
    tau = inverse_dynamics(phantom6, q, qd, qdd)
    assert np.allclose(forward_dynamics(phantom6, q, qd, tau), qdd, rtol=1e-9, atol=1e-9)
