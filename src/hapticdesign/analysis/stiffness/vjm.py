"""Virtual joint method for one serial chain (seed 001 eq. 4.45-4.57, 5.98-5.123, 5.157-5.160).

All functions broadcast over leading pose axes: Jacobians are ``(..., 6, n)``.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import block_diag

from hapticdesign.errors import UserError


def joint_compliance(link_stiffnesses: list[np.ndarray]) -> np.ndarray:
    """``K_theta^-1`` of a chain: block diagonal of the links' inverse 6 x 6 stiffnesses (eq. 5.105)."""
    return block_diag(*[np.linalg.inv(k) for k in link_stiffnesses])


def compliance(J_theta: np.ndarray, C_theta: np.ndarray, joints: np.ndarray | None = None) -> np.ndarray:
    """Cartesian compliance of the chain with passive joints locked: ``J_theta K_theta^-1 J_theta^T``
    (eq. 5.119), plus the joint springs' Cartesian compliance ``joints`` when given (springs in series
    add their compliances, :mod:`hapticdesign.analysis.stiffness.joints`)."""
    C = J_theta @ C_theta @ np.swapaxes(J_theta, -1, -2)
    return C if joints is None else C + joints


def locked_stiffness(J_theta: np.ndarray, C_theta: np.ndarray, joints: np.ndarray | None = None) -> np.ndarray:
    """``K_Ci* = (J_theta K_theta^-1 J_theta^T)^-1`` (eq. 4.55, 5.119, 6.60): passive joints ignored."""
    try:
        return np.linalg.inv(compliance(J_theta, C_theta, joints))
    except np.linalg.LinAlgError:
        raise UserError("the chain's virtual-joint Jacobian is rank deficient (singular pose)") from None


def chain_stiffness(J_theta: np.ndarray, C_theta: np.ndarray, J_p: np.ndarray,
                    joints: np.ndarray | None = None) -> np.ndarray:
    """``K_Ci``: the leading block of the inverse bordered compliance matrix (eq. 5.121-5.122).

    The passive joints (Jacobian ``J_p``, columns carry no load, eq. 5.118) make the result rank
    deficient: it annihilates every passive twist, ``K_Ci J_p = 0``. ``joints`` adds the joint
    springs' Cartesian compliance to the links' (see :func:`compliance`). The rows of ``J_theta`` and
    ``J_p`` are the end point's twist (6) and, for a closed-loop device, the linearized loop closures
    below it (:mod:`hapticdesign.analysis.stiffness.device`); the block has the size of those rows.
    """
    C = compliance(J_theta, C_theta, joints)
    n, n_p = C.shape[-1], J_p.shape[-1]
    lead = np.broadcast_shapes(C.shape[:-2], J_p.shape[:-2])
    B = np.zeros(lead + (n + n_p, n + n_p))
    B[..., :n, :n] = C
    B[..., :n, n:] = J_p
    B[..., n:, :n] = np.swapaxes(J_p, -1, -2)
    try:
        return np.linalg.inv(B)[..., :n, :n]
    except np.linalg.LinAlgError:
        raise UserError("the passive-joint Jacobian is rank deficient (singular pose)") from None


def virtual_deflections(
    J_theta: np.ndarray,
    C_theta: np.ndarray,
    wrench: np.ndarray,
    J_weights: np.ndarray | None = None,
    weights: np.ndarray | None = None,
    direct_load: np.ndarray | None = None,
) -> np.ndarray:
    """``theta = K_theta^-1 (J_theta^T F_ext + J_theta_g^T G + tau_own)`` (eq. 5.117 unloaded, 5.157 loaded).

    ``J_weights`` ``(..., 6 m, n)`` stacks the mass-centre Jacobians of eq. 5.153 and ``weights``
    ``(6 m,)`` the link weights of eq. 5.154-5.156; ``direct_load`` ``(..., n)`` is a load acting on
    the virtual joints themselves (a link's own distributed weight, :func:`own_weight_load`).
    """
    load = np.swapaxes(J_theta, -1, -2) @ np.asarray(wrench, dtype=float)
    if J_weights is not None:
        load = load + np.swapaxes(J_weights, -1, -2) @ np.asarray(weights, dtype=float)
    if direct_load is not None:
        load = load + direct_load
    return load @ C_theta.T


def own_weight_load(weight_local: np.ndarray, length: float) -> np.ndarray:
    """End load of a link's own uniformly distributed weight on its virtual joint (6,).

    The virtual joint sits at the link's end with the link's root clamped (eq. 5.76-5.79), so a
    weight spread along the link does not reach it through a mass-centre Jacobian (eq. 5.149:
    the mass centre precedes the joint). The load that gives the cantilever's exact end
    displacement and rotation under the distributed weight ``W`` (link frame, x along the link)
    is the beam element's consistent load at that end: force ``W / 2`` and moment
    ``-(L / 12) x × W``; with the end compliance of eq. 4.59 it gives ``w L^4 / (8 E I)`` and
    ``w L^3 / (6 E I)`` for the transverse part and ``w L^2 / (2 E A)`` for the axial part.
    """
    W = np.asarray(weight_local, dtype=float)
    return np.concatenate([W / 2.0, -length / 12.0 * np.cross([1.0, 0.0, 0.0], W)])
