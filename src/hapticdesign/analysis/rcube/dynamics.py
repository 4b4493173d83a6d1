"""Modified R-CUBE dynamics (seed 001 §5.3): Cartesian inertia ``M_C`` and nonlinear terms ``B*``.

Each chain's kinetic energy ``1/2 q_i_dot^T M_i q_i_dot`` (eq. 5.207-5.209) uses the mass-centre
Jacobians of :func:`hapticdesign.model.rcube.chain_mechanism` (eq. 5.182-5.195) and tube inertias
(eq. 5.229-5.230). Gravity is left out as in the seed (§5.3).
"""

from __future__ import annotations

import numpy as np

from hapticdesign.model.rcube import chain_mechanism
from hapticdesign.analysis.rcube.batch_kinematics import poses_and_jacobians
from hapticdesign.analysis.rcube.design import RCubeDesign
from hapticdesign.analysis.rcube.kinematics import (
    chain_jacobian,
    inverse_kinematics,
    jacobian_rate,
    passive_rates,
    require_regular,
)

DERIVATIVE_STEP = 1e-6


def tube_inertia(mass: float, length: float, D: float, d: float) -> np.ndarray:
    """Principal moments about the tube's mass centre, link axis first (x along the link).

    ``I_x = m (R^2 + r^2) / 2`` and ``I_y = I_z = m (l^2 / 12 + (R^2 + r^2) / 4)``. Eq. 5.229
    prints ``l^2 / 3``, the moment about the link's end; with the mass placed at the link's
    middle (eq. 5.182-5.184) the moment about the mass centre is the consistent one (the end
    moment follows by the parallel-axis term ``m l^2 / 4``, eq. 6.85).
    """
    rr = (D / 2) ** 2 + (d / 2) ** 2
    transverse = mass * (length**2 / 12.0 + rr / 4.0)
    return np.array([mass * rr / 2.0, transverse, transverse])


def chain_mass_matrix(design: RCubeDesign, chain: int, q_chain) -> np.ndarray:
    """Joint-space inertia ``M_i = sum_j J_gij^T M_ij J_gij`` of one chain (eq. 5.199-5.208), ``(..., 3, 3)``."""
    mech = chain_mechanism(design.geometry, chain, design.centres)
    q = np.asarray(q_chain, dtype=float)
    M = np.zeros(q.shape[:-1] + (3, 3))
    masses = design.link_masses()
    for j, (link, length, m) in enumerate(zip(design.links, design.lengths, masses)):
        poses, J = poses_and_jacobians(mech, q, f"com{j + 1}")
        R = poses[..., :3, :3]
        inertia = (R * tube_inertia(m, length, link.section.D, link.section.d)[..., None, :]) @ np.swapaxes(R, -1, -2)
        Jv, Jw = J[..., :3, :], J[..., 3:, :]
        M += m * np.swapaxes(Jv, -1, -2) @ Jv + np.swapaxes(Jw, -1, -2) @ inertia @ Jw
    if design.platform_mass > 0.0:
        _, J = poses_and_jacobians(mech, q, "platform")
        Jv = J[..., :3, :]
        M += design.platform_mass / 3.0 * np.swapaxes(Jv, -1, -2) @ Jv
    return M


def chain_cartesian_mass(design: RCubeDesign, chain: int, q_chain) -> np.ndarray:
    """``M_Ci = J_i^-T M_i J_i^-1`` (eq. 5.223)."""
    J = chain_jacobian(design.geometry, chain, q_chain)
    Jinv = np.linalg.inv(J)
    return np.swapaxes(Jinv, -1, -2) @ chain_mass_matrix(design, chain, q_chain) @ Jinv


def cartesian_mass_matrix(design: RCubeDesign, position) -> np.ndarray:
    """``M_C* = sum_i M_Ci`` (eq. 5.227) at platform positions ``(..., 3)``; a platform mass is shared."""
    q = inverse_kinematics(design.geometry, position)
    require_regular(design.geometry, q)
    return sum(chain_cartesian_mass(design, i, q[..., i, :]) for i in range(3))


def nonlinear_terms(design: RCubeDesign, position, velocity) -> np.ndarray:
    """``B* = sum_i B_i`` (eq. 5.224, 5.228) at a platform position and velocity ``(3,)``.

    ``B_i = J_i^-T d/dt(M_i J_i^-1) r_dot - 1/2 J_i^-T sum_k (r_dot^T J_i^-T dM_i/dq_ik J_i^-1 r_dot) e_k``;
    the derivatives of ``M_i`` are central differences with step ``DERIVATIVE_STEP``.
    """
    r = np.asarray(position, dtype=float)
    r_dot = np.asarray(velocity, dtype=float)
    q = inverse_kinematics(design.geometry, r)
    qd = passive_rates(design.geometry, q, r_dot)
    total = np.zeros(3)
    h = DERIVATIVE_STEP
    for i in range(3):
        qi, qdi = q[i], qd[i]
        J = chain_jacobian(design.geometry, i, qi)
        Jinv_T = np.linalg.inv(J).T
        dM = np.stack([
            (chain_mass_matrix(design, i, qi + h * e) - chain_mass_matrix(design, i, qi - h * e)) / (2 * h)
            for e in np.eye(3)
        ])
        M_dot = np.tensordot(qdi, dM, axes=1)
        # d/dt(M_i J_i^-1) r_dot = M_dot q_dot - M_i J_i^-1 J_dot q_dot, since r_dot = J_i q_dot
        J_dot = jacobian_rate(design.geometry, i, qi, qdi)
        M = chain_mass_matrix(design, i, qi)
        term = M_dot @ qdi - M @ np.linalg.solve(J, J_dot @ qdi)
        quadratic = np.array([qdi @ dM[k] @ qdi for k in range(3)])
        total += Jinv_T @ (term - 0.5 * quadratic)
    return total
