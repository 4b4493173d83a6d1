"""Modified R-CUBE stiffness by the virtual joint method (seed 001 §5.2).

Per chain: Jacobians ``J_theta (6x18)``, ``J_p (6x4)``, ``J_a (6x1)`` of the platform frame
(eq. 5.93-5.97) from :func:`hapticdesign.model.rcube.stiffness_chain_mechanism`; unloaded mode
``K_Ci`` from the bordered compliance matrix (eq. 5.121-5.122), ``K_C = sum K_Ci`` (eq. 5.123);
loaded mode with the link weights (eq. 5.139-5.160); direct and iterative solutions (Fig. 5.6-5.8).
Wrenches are ``(F_x, F_y, F_z, M_x, M_y, M_z)`` in the base frame, at the platform point.

Joint and bearing compliance (beyond the seed, which takes the joints as ideal): each of a chain's
five joints may carry a spring (:class:`hapticdesign.analysis.stiffness.joints.JointStiffness`) whose
Cartesian compliance adds to the links' before the passive joints are eliminated (eq. 5.121-5.122).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.linalg import block_diag

from hapticdesign.analysis.kinematics import poses_and_jacobians
from hapticdesign.analysis.rcube.design import RCubeDesign
from hapticdesign.analysis.rcube.kinematics import inverse_kinematics, require_regular
from hapticdesign.analysis.stiffness import vjm
from hapticdesign.analysis.stiffness.joints import spring_compliance
from hapticdesign.errors import UserError
from hapticdesign.model.rcube import (
    ACTIVE_INDEX,
    N_VIRTUAL,
    PASSIVE_SLICE,
    stiffness_chain_mechanism,
    stiffness_coordinates,
)

JOINT_FRAMES = ("link1", "k1", "link2", "link3", "k3")
"""Frames of the stiffness chain whose z axis is the axis of joints ``phi_i1 .. phi_i5`` (eq. 5.5-5.14)."""

ITERATION_TOLERANCE = 1e-12
MAX_ITERATIONS = 100


@dataclass(frozen=True)
class ChainJacobians:
    """``J_theta (..., 6, 18)``, ``J_p (..., 6, 4)`` and ``J_a (..., 6)`` of one chain (eq. 5.94-5.96)."""

    theta: np.ndarray
    passive: np.ndarray
    active: np.ndarray


@lru_cache(maxsize=64)
def joint_compliance(design: RCubeDesign) -> np.ndarray:
    """``K_theta^-1`` (18 x 18) of one chain from the three link stiffnesses (eq. 4.59, 5.105); cached,
    read-only."""
    out = vjm.joint_compliance([link.stiffness(L) for link, L in zip(design.links, design.lengths)])
    out.flags.writeable = False
    return out


def joint_stiffness(design: RCubeDesign) -> np.ndarray:
    """``K_theta`` (18 x 18) of one chain (eq. 5.105)."""
    return block_diag(*[link.stiffness(L) for link, L in zip(design.links, design.lengths)])


def chain_jacobians(design: RCubeDesign, chain: int, q_chain, theta=None, frame: str = "platform") -> ChainJacobians:
    """Jacobians of ``frame`` with respect to virtual, passive and active joints (eq. 5.87-5.97)."""
    mech = stiffness_chain_mechanism(design.geometry, chain, design.centres)
    _, J = poses_and_jacobians(mech, stiffness_coordinates(q_chain, theta), frame)
    return ChainJacobians(J[..., :N_VIRTUAL], J[..., PASSIVE_SLICE], J[..., ACTIVE_INDEX])


def joint_spring_compliance(design: RCubeDesign, chain: int, q_chain, theta=None) -> np.ndarray | None:
    """Cartesian compliance at the platform point of the chain's joint springs, ``(..., 6, 6)``;
    ``None`` when every joint is rigid (the seed's model)."""
    if design.rigid_joints:
        return None
    mech = stiffness_chain_mechanism(design.geometry, chain, design.centres)
    Q = stiffness_coordinates(q_chain, theta)
    frames = [poses_and_jacobians(mech, Q, name)[0] for name in JOINT_FRAMES]
    platform = poses_and_jacobians(mech, Q, "platform")[0][..., :3, 3]
    return spring_compliance(frames, platform, list(design.joints))


def _require_rigid_joints(design: RCubeDesign, what: str) -> None:
    if not design.rigid_joints:
        raise UserError(f"joint compliance is modelled in the unloaded direct solution only, not in {what}")


def _joint_angles(design: RCubeDesign, position) -> np.ndarray:
    q = inverse_kinematics(design.geometry, position)
    require_regular(design.geometry, q)
    return q


def chain_stiffness_matrices(design: RCubeDesign, position, passive: bool = True) -> np.ndarray:
    """``K_Ci`` of the three chains, ``(..., 3, 6, 6)``, unloaded mode, direct solution.

    ``passive=True`` eliminates the passive joints (eq. 5.121-5.122, rank deficient);
    ``passive=False`` gives ``K_Ci* = (J_theta K_theta^-1 J_theta^T)^-1`` (eq. 5.119, 6.60).
    """
    q = _joint_angles(design, position)
    C_theta = joint_compliance(design)
    out = []
    for i in range(3):
        J = chain_jacobians(design, i, q[..., i, :])
        C_joints = joint_spring_compliance(design, i, q[..., i, :])
        out.append(vjm.chain_stiffness(J.theta, C_theta, J.passive, C_joints) if passive
                   else vjm.locked_stiffness(J.theta, C_theta, C_joints))
    return np.stack(out, axis=-3)


def cartesian_stiffness(design: RCubeDesign, position, passive: bool = True) -> np.ndarray:
    """``K_C = sum_i K_Ci`` (eq. 5.123), ``(..., 6, 6)``."""
    return chain_stiffness_matrices(design, position, passive).sum(axis=-3)


def link_weights(design: RCubeDesign) -> np.ndarray:
    """``G_i`` (eq. 5.154-5.156): weights of links 1-3 and a third of the platform, 24-vector."""
    g = np.asarray(design.gravity, dtype=float)
    masses = list(design.link_masses()) + [design.platform_mass / 3.0]
    return np.concatenate([np.concatenate([m * g, np.zeros(3)]) for m in masses])


def weight_jacobians(design: RCubeDesign, chain: int, q_chain, theta=None) -> np.ndarray:
    """``J_theta_g`` (eq. 5.149-5.153): mass-centre Jacobians on the virtual joints, ``(..., 24, 18)``.

    Link 1's mass centre precedes the first virtual joint, so its block is zero (eq. 5.149).
    """
    blocks = [chain_jacobians(design, chain, q_chain, theta, f"com{j}").theta for j in (1, 2, 3)]
    blocks.append(chain_jacobians(design, chain, q_chain, theta, "platform").theta)
    return np.concatenate(blocks, axis=-2)


def own_weight_loads(design: RCubeDesign, chain: int, q_chain, theta=None) -> np.ndarray:
    """Each link's own distributed weight on its virtual joint (18,), in the joint's coordinates.

    Eq. 5.149-5.153 load a virtual joint only with the weights beyond it; a link's own weight,
    spread along the link, bends the link too (:func:`hapticdesign.analysis.stiffness.vjm.own_weight_load`).
    """
    mech = stiffness_chain_mechanism(design.geometry, chain, design.centres)
    Q = stiffness_coordinates(q_chain, theta)
    g = np.asarray(design.gravity, dtype=float)
    parts = []
    for j, (m, L) in enumerate(zip(design.link_masses(), design.lengths)):
        R = poses_and_jacobians(mech, Q, f"link{j + 1}")[0][:3, :3]  # link frame: x along the link
        parts.append(vjm.own_weight_load(R.T @ (m * g), L))
    return np.concatenate(parts)


def chain_deflections(design: RCubeDesign, chain: int, q_chain, wrench, loaded: bool = False, theta=None) -> np.ndarray:
    """Virtual-joint deflections ``theta_i`` of one chain (eq. 5.117 unloaded, eq. 5.157 loaded).

    Loaded mode: the weights beyond each virtual joint through the mass-centre Jacobians
    (eq. 5.149-5.157) plus each link's own distributed weight (:func:`own_weight_loads`).
    """
    J = chain_jacobians(design, chain, q_chain, theta)
    if loaded:
        return vjm.virtual_deflections(
            J.theta, joint_compliance(design), wrench, weight_jacobians(design, chain, q_chain, theta), link_weights(design),
            own_weight_loads(design, chain, q_chain, theta),
        )
    return vjm.virtual_deflections(J.theta, joint_compliance(design), wrench)


def loaded_chain_stiffness_matrices(
    design: RCubeDesign, position, wrench=None, iterative: bool = False
) -> np.ndarray:
    """Loaded mode ``K_Cgf,i`` (eq. 5.157-5.158): the Jacobians re-evaluated at the deflected pose.

    The direct solution evaluates eq. 5.157 with the undeflected Jacobians (Fig. 5.6); the
    iterative one repeats it with the Jacobians of the last deflection until the deflections
    change by less than ``ITERATION_TOLERANCE`` (force equilibrium, Fig. 5.7).
    """
    _require_rigid_joints(design, "the loaded mode")
    q = _joint_angles(design, np.asarray(position, dtype=float))
    C_theta = joint_compliance(design)
    wrench = _check_wrench(np.zeros(6) if wrench is None else wrench)
    out = []
    for i in range(3):
        theta = _chain_equilibrium(design, i, q[i], wrench, True, iterative)
        J = chain_jacobians(design, i, q[i], theta)
        out.append(vjm.chain_stiffness(J.theta, C_theta, J.passive))
    return np.stack(out)


def _check_wrench(wrench) -> np.ndarray:
    w = np.asarray(wrench, dtype=float)
    if w.shape == (3,):
        w = np.concatenate([w, np.zeros(3)])
    if w.shape != (6,) or not np.all(np.isfinite(w)):
        raise UserError(f"a wrench is 3 forces or 6 forces and moments, finite, got {wrench!r}")
    return w


def _chain_equilibrium(design, chain, q_chain, wrench, loaded, iterative) -> np.ndarray:
    theta = chain_deflections(design, chain, q_chain, wrench, loaded)
    if not iterative:
        return theta
    for _ in range(MAX_ITERATIONS):
        new = chain_deflections(design, chain, q_chain, wrench, loaded, theta)
        if np.max(np.abs(new - theta)) < ITERATION_TOLERANCE:
            return new
        theta = new
    raise UserError("the force-equilibrium iteration did not converge (load too large for a linear model)")


def platform_deflection(design: RCubeDesign, position, wrench, method: str = "direct") -> np.ndarray:
    """Platform deflection ``Delta kappa = K_C^-1 F_ext`` (6,) under a wrench at one position.

    ``direct``: unloaded ``K_C`` at the undeflected pose (Fig. 5.6). ``pose``: pose equilibrium of
    the whole manipulator (Fig. 5.8): each chain's share ``F_i = K_Ci Delta kappa`` deflects its
    virtual and passive joints (eq. 5.121); ``K_C`` is rebuilt at those deflected chain
    configurations and the platform deflection re-solved until it changes by less than
    ``ITERATION_TOLERANCE``.
    """
    w = _check_wrench(wrench)
    if method == "direct":
        return np.linalg.solve(cartesian_stiffness(design, position), w)
    if method != "pose":
        raise UserError(f"unknown solution method {method!r}; choose direct or pose")
    _require_rigid_joints(design, "the pose equilibrium")
    q = _joint_angles(design, np.asarray(position, dtype=float))
    C_theta = joint_compliance(design)
    thetas = [np.zeros(N_VIRTUAL) for _ in range(3)]
    passive_shift = [np.zeros(4) for _ in range(3)]
    kappa = np.zeros(6)
    for _ in range(MAX_ITERATIONS):
        Ks, parts = [], []
        for i in range(3):
            Q = stiffness_coordinates(q[i], thetas[i])
            Q[PASSIVE_SLICE] += passive_shift[i]
            mech = stiffness_chain_mechanism(design.geometry, i, design.centres)
            _, J = poses_and_jacobians(mech, Q)
            parts.append((J[:, :N_VIRTUAL], J[:, PASSIVE_SLICE]))
            Ks.append(vjm.chain_stiffness(J[:, :N_VIRTUAL], C_theta, J[:, PASSIVE_SLICE]))
        new_kappa = np.linalg.solve(sum(Ks), w)
        for i, (J_theta, J_p) in enumerate(parts):
            F_i = Ks[i] @ new_kappa
            thetas[i] = C_theta @ (J_theta.T @ F_i)
            residual = new_kappa - J_theta @ thetas[i]
            passive_shift[i] = np.linalg.lstsq(J_p, residual, rcond=None)[0]
        if np.max(np.abs(new_kappa - kappa)) < ITERATION_TOLERANCE:
            return new_kappa
        kappa = new_kappa
    raise UserError("the pose-equilibrium iteration did not converge (load too large for a linear model)")
