"""The compiled closed-loop plant (H_a, C(q, qd) qd, G_a pose after pose) of the five-bar and the delta.

References: the closed-loop model's entries (the slow path, itself checked against Pinocchio and the
Lagrangian in test_five_bar.py / test_delta.py) at random poses; energy conservation of a
free motion without damping integrated by scipy's ``solve_ivp`` with the plant, the potential taken
from the frame poses of the mechanism (``Mechanism.frame_pose``) at the closed coordinates.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from hapticdesign.analysis.dynamics.closed_loop_plant import OK, ClosedLoopPlant, closed_loop_terms
from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.dynamics.model import velocity_products
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.errors import UserError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
FREE_MOTION = {"five-bar": ([2.0, 1.1], [1.5, -1.0]), "delta": ([0.35, 0.30, 0.40], [2.0, -1.0, 0.5])}


@pytest.fixture(scope="module", params=["five-bar", "delta"])
def device(request):
    return load_device_file(EXAMPLES / f"{request.param}.yaml")


def _home(device) -> np.ndarray:
    solver = dynamics_of(device).solver
    return solver.home[solver.closures.actuated]


def test_terms_match_the_closed_loop_model_at_random_poses(device):
    model, pi = dynamics_of(device), device.standard_parameters()
    rng = np.random.default_rng(0)
    for _ in range(10):
        qa = _home(device) + rng.uniform(-0.2, 0.2, model.n_dof)
        qd = rng.normal(size=model.n_dof)
        h, cqd, g = ClosedLoopPlant(model, pi, qa).terms(qa, qd)
        scale = np.abs(model.H(qa, pi)).max()
        np.testing.assert_allclose(h, model.H(qa, pi), rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(g, model.G(qa, pi), rtol=0, atol=1e-12 * np.abs(model.G(qa, pi)).max())
        reference = model.C(qa, pi) @ velocity_products(qd)
        np.testing.assert_allclose(cqd, reference, rtol=0, atol=1e-12 * np.abs(reference).max())


def test_warm_start_follows_a_motion(device):
    """Pose after pose from the last one: the same terms as solving each pose from home."""
    model, pi = dynamics_of(device), device.standard_parameters()
    t = np.linspace(0.0, 0.5, 501)[:, None]
    path = _home(device) + 0.2 * np.sin(2 * np.pi * (1.0 + 0.5 * np.arange(model.n_dof)) * t)
    plant = ClosedLoopPlant(model, pi, path[0])
    for qa in path[::50]:
        h, _, g = plant.terms(qa, np.zeros(model.n_dof))
        np.testing.assert_allclose(plant.q_full, model.full_coordinates(qa), rtol=0, atol=1e-10)
        np.testing.assert_allclose(h, model.H(qa, pi), rtol=0, atol=1e-10 * np.abs(h).max())
        np.testing.assert_allclose(g, model.G(qa, pi), rtol=0, atol=1e-10 * np.abs(g).max())


def test_a_jump_is_a_status_and_keeps_the_last_pose(device):
    model, pi = dynamics_of(device), device.standard_parameters()
    home = _home(device)
    plant = ClosedLoopPlant(model, pi, home)
    before = plant.q_full
    n = model.n_dof
    h, cqd, g = np.zeros((n, n)), np.zeros(n), np.zeros(n)
    far = home + np.pi / 2 * np.arange(1, n + 1)
    assert closed_loop_terms(far, np.zeros(n), plant.structure, plant.workspace, h, cqd, g) != OK
    np.testing.assert_array_equal(plant.q_full, before)
    with pytest.raises(UserError, match="at q = "):
        plant.terms(far, np.zeros(n))
    assert closed_loop_terms(home, np.zeros(n), plant.structure, plant.workspace, h, cqd, g) == OK


def _potential(device, q_full: np.ndarray) -> float:
    """``-sum m g . (p + R r)`` of every body, from the mechanism's frame poses."""
    mech = device.mechanism
    energy = 0.0
    for attachment in mech.bodies:
        body = device.body(attachment.name)
        pose = mech.frame_pose(q_full, attachment.frame)
        energy -= body.m * np.asarray(mech.gravity) @ (pose[:3, 3] + pose[:3, :3] @ body.r)
    return energy


def test_energy_is_conserved_without_damping(device):
    model, pi = dynamics_of(device), device.standard_parameters()
    qa0, qd0 = (np.array(v) for v in FREE_MOTION[device.name])
    n = model.n_dof
    plant = ClosedLoopPlant(model, pi, qa0)

    def rhs(_t, x):
        h, cqd, g = plant.terms(x[:n], x[n:])
        return np.concatenate([x[n:], np.linalg.solve(h, -cqd - g)])

    sol = solve_ivp(rhs, (0.0, 0.1), np.concatenate([qa0, qd0]), method="DOP853", rtol=1e-11, atol=1e-12,
                    t_eval=np.linspace(0.0, 0.1, 21))
    assert sol.success
    energies = []
    for x in sol.y.T:
        h, _, _ = plant.terms(x[:n], np.zeros(n))
        energies.append(0.5 * x[n:] @ h @ x[n:] + _potential(device, plant.q_full))
    kinetic = 0.5 * qd0 @ ClosedLoopPlant(model, pi, qa0).terms(qa0, qd0)[0] @ qd0
    assert np.ptp(energies) <= 1e-8 * kinetic  # integration tolerance 1e-11 over the run
    assert np.ptp(sol.y[0]) > 0.05  # it actually moved
