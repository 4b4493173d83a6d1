"""The equations of motion of a device: its compiled model and H, C, C_cvt, G, tau, qdd as free functions.

:func:`dynamics_of` gives the regressor model of a device's geometry (cached per builder and
kinematic parameters, so every device that differs only in inertial parameters shares it). With
actuators, H carries the constant reflected rotor inertia (seed 000 eq. 2.50 plus ``sum n^2 J_r a a^T``);
the regressor in the inertial parameters is the same object's. The other functions evaluate that
model at the device's standard parameters (seed 000 eq. 2.50-2.52); :func:`tree_mass_matrix` gives
H of a tree straight from the compiled kernel, without fitting that model.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from hapticdesign.analysis.configuration import configuration_for
from hapticdesign.analysis.dynamics.closed_loop import ClosedLoopModel
from hapticdesign.analysis.dynamics.kernel import regressor_kernel
from hapticdesign.analysis.dynamics.model import DynamicsModel, EquationsOfMotion, has_trigonometric_basis
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device, MechanismBuilder
from hapticdesign.model.mechanism import Mechanism


def dynamics_of(device: Device) -> EquationsOfMotion:
    """The compiled regressor model of the device's equations of motion (cached per geometry; a closed-loop
    device's takes its configuration space, :func:`~hapticdesign.analysis.configuration.configuration_of`)."""
    base = _model(device.builder, device.kinematic_values())
    if not device.actuators:
        return base
    extra = device.reflected_inertia
    return _with_rotors(base, tuple(map(tuple, extra.tolist()))) if np.any(extra) else base


def mass_matrix(device: Device, q: np.ndarray) -> np.ndarray:
    """H (eq. 2.50) at one pose (N,) or many (P, N)."""
    return dynamics_of(device).H(q, device.standard_parameters())


def mass_matrix_at(device: Device, q_full: np.ndarray) -> np.ndarray:
    """H over the actuated coordinates, the reflected rotor inertia included, at closed full poses ``q_full``
    (P, N) (from :meth:`~hapticdesign.analysis.configuration.Configuration.reach` or ``full``): (P, n_a, n_a), from
    :func:`_terms_at` (no continuation from home)."""
    return _terms_at(device, np.atleast_2d(np.asarray(q_full, dtype=float)))[0] + device.reflected_inertia


def _terms_at(device: Device, q_full: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """H (P, n_a, n_a) and G (P, n_a) at closed full poses (P, N), the rotors left out: a tree's from the compiled
    kernel (:func:`tree_terms`, no fitted model), a closed loop's from :meth:`~.closed_loop.ClosedLoopModel.terms_at`."""
    kinematic, params = device.kinematic_values(), device.standard_parameters()
    mechanism = configuration_for(device.builder, kinematic).mechanism
    if has_trigonometric_basis(mechanism):
        return tree_terms(mechanism, q_full, params)
    return _model(device.builder, kinematic).terms_at(q_full, params)


def tree_mass_matrix(mechanism: Mechanism, q: np.ndarray, parameters: np.ndarray) -> np.ndarray:
    """H (eq. 2.50) of a tree mechanism at poses ``(..., N)``: :func:`tree_terms`' H."""
    return tree_terms(mechanism, q, parameters)[0]


def tree_terms(mechanism: Mechanism, q: np.ndarray, parameters: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """H (..., N, N) and G (..., N) (eq. 2.50) of a tree mechanism at poses ``(..., N)`` for standard inertial
    parameters ``(10 x bodies,)``, straight from the compiled regressor kernel: exact like :func:`mass_matrix`,
    without fitting the model of :func:`dynamics_of` (the cheaper choice for a geometry at a few poses)."""
    if not has_trigonometric_basis(mechanism):
        raise UserError("a mechanism with closed loops needs the loop solver: use mass_matrix")
    q = np.asarray(q, dtype=float)
    n = mechanism.n_dof
    if q.shape[-1:] != (n,) or not np.all(np.isfinite(q)):
        raise UserError(f"expected finite joint coordinates (..., {n}), got an array of shape {q.shape}")
    c = mechanism.compiled
    yh, yg = regressor_kernel(np.ascontiguousarray(q.reshape(-1, n)), *c.tree.arrays, c.tree.body_node, c.gravity)
    return (yh @ parameters).reshape(q.shape + (n,)), (yg @ parameters).reshape(q.shape)


def coriolis_centrifugal(device: Device, q: np.ndarray) -> np.ndarray:
    """C of eq. 2.50, N x N(N+1)/2, the coefficients of the velocity products ``thetadot^2``."""
    return dynamics_of(device).C(q, device.standard_parameters())


def coriolis_matrix(device: Device, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """C_cvt of eq. 2.51-2.52, N x N, with ``C_cvt qd`` the Coriolis and centrifugal torques."""
    return dynamics_of(device).C_cvt(q, qd, device.standard_parameters())


def gravity(device: Device, q: np.ndarray) -> np.ndarray:
    """G, the gravity torques of eq. 2.50."""
    return dynamics_of(device).G(q, device.standard_parameters())


GRADIENT_STEP = 1e-6
"""The step (rad or m) of :func:`gravity_gradient`'s central differences: G is smooth (trigonometric in the angles),
so their truncation error, about ``step^2 |G'''| / 6``, is far below their rounding error (about 1e-10 of G)."""


def gravity_gradient(device: Device, q: np.ndarray) -> np.ndarray:
    """``K_G = dG/dq`` (n_a, n_a), the stiffness gravity adds to the linearized plant at the actuated pose ``q``
    (``K_G[i, j] = dG_i / dq_j``; :func:`gravity_gradient_at` of the closed pose)."""
    space = configuration_for(device.builder, device.kinematic_values())
    return gravity_gradient_at(device, space.full(np.atleast_2d(np.asarray(q, dtype=float))))[0]


def gravity_gradient_at(device: Device, q_full: np.ndarray) -> np.ndarray:
    """``dG/dq_a`` (P, n_a, n_a) at closed full poses (P, N), by central differences of G over ``+-``
    :data:`GRADIENT_STEP` along each actuated coordinate's motion ``T e_j`` (the passive coordinates follow to first
    order; the second-order miss of the closure is even in the step and cancels in the difference): a tree's G from
    :func:`_terms_at`, as :func:`mass_matrix_at`)."""
    space = configuration_for(device.builder, device.kinematic_values())
    q_full = np.atleast_2d(np.asarray(q_full, dtype=float))
    steps = GRADIENT_STEP * np.swapaxes(space.velocity_transform(q_full), 1, 2)  # (P, n_a, N)
    poses = np.concatenate([q_full[:, None, :] + steps, q_full[:, None, :] - steps], axis=1)
    poses = poses.reshape(-1, q_full.shape[1])
    torques = _terms_at(device, poses)[1]
    n = steps.shape[1]
    torques = torques.reshape(len(q_full), 2, n, -1)  # (P, +-, j, i)
    return np.swapaxes((torques[:, 0] - torques[:, 1]) / (2.0 * GRADIENT_STEP), 1, 2)


def inverse_dynamics(device: Device, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    """``tau = H qdd + C qd^2 + G`` (eq. 2.50)."""
    return dynamics_of(device).inverse(q, qd, qdd, device.standard_parameters())


def forward_dynamics(device: Device, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """``qdd = H^-1 (tau - C qd^2 - G)``."""
    return dynamics_of(device).forward(q, qd, tau, device.standard_parameters())


@lru_cache(maxsize=16)
def _model(builder: MechanismBuilder, kinematic: tuple[tuple[str, float], ...]):
    space = configuration_for(builder, kinematic)
    return DynamicsModel(space.mechanism) if has_trigonometric_basis(space.mechanism) else ClosedLoopModel(space)


@lru_cache(maxsize=16)
def _with_rotors(base, reflected: tuple[tuple[float, ...], ...]):
    return base.with_constant_inertia(np.array(reflected))
