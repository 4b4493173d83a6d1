"""Modified R-CUBE dynamics (seed 001 §5.3): Cartesian inertia ``M_C`` and nonlinear terms ``B*``.

Each chain is a device of the dynamics engine (:mod:`hapticdesign.analysis.dynamics.device`): the
chain of eq. 5.5-5.18 (:data:`hapticdesign.model.rcube.CHAIN_BUILDERS`) carrying its three tubes
(eq. 5.229-5.230) and its share of the platform. The engine gives the chain's joint-space inertia
``M_i = sum_j J_gij^T M_ij J_gij`` (eq. 5.199-5.208, over the mass-centre Jacobians of
eq. 5.182-5.195; kinetic energy ``1/2 q_i_dot^T M_i q_i_dot``, eq. 5.207-5.209) and its Christoffel
symbols, both exact. Gravity is left out as in the seed (§5.3).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from hapticdesign.analysis.dynamics.cartesian import cartesian_inertia
from hapticdesign.analysis.dynamics.device import coriolis_matrix, dynamics_of, mass_matrix, tree_mass_matrix
from hapticdesign.analysis.rcube.design import RCubeDesign
from hapticdesign.analysis.rcube.kinematics import (
    chain_jacobian,
    inverse_kinematics,
    jacobian_rate,
    passive_rates,
    require_regular,
)
from hapticdesign.model.device import Device
from hapticdesign.model.rcube import CHAIN_BODIES, CHAIN_BUILDERS, CHAIN_KINEMATIC, N_CHAINS


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


@lru_cache(maxsize=64)
def chain_devices(design: RCubeDesign) -> tuple[Device, ...]:
    """The design's three chains as devices (cached per design; the engine caches per geometry).

    Tube ``j`` (mass eq. 5.230) sits on the joint frame ``link_j``, whose x axis runs along the
    link: mass centre ``(lg_j, 0, 0)`` with ``lg_j = centres[j] l_j`` (eq. 5.182-5.184) and
    principal moments :func:`tube_inertia` about it on the frame's axes (the frame is the tube's
    principal frame, so no rotation is needed). The device's standard parameters move the inertia
    to the frame origin by the parallel-axis theorem (:mod:`hapticdesign.model.inertia`). Each chain
    carries a third of the platform mass as a point mass at the platform frame.
    """
    g = design.geometry
    params = {"l1": g.l1, "l2": g.l2, "l3": g.l3, "S": g.S, "mp": design.platform_mass / N_CHAINS}
    tubes = zip(CHAIN_BODIES, design.links, design.lengths, design.link_masses(), design.centres)
    for (body, _), link, length, mass, centre in tubes:
        axial, transverse, _ = tube_inertia(mass, length, link.section.D, link.section.d)
        params |= {f"m{body}": mass, f"r{body}x": centre * length,
                   f"Ixx{body}": axial, f"Iyy{body}": transverse, f"Izz{body}": transverse}
    return tuple(
        Device(f"rcube-chain{i + 1}", f"R-CUBE chain {i + 1} (seed 001 eq. 5.199-5.209)", CHAIN_KINEMATIC,
               CHAIN_BUILDERS[i], dict(params))
        for i in range(N_CHAINS)
    )


@lru_cache(maxsize=64)
def _chain_parameters(design: RCubeDesign) -> tuple[tuple[Device, np.ndarray], ...]:
    """Each chain's device and its standard inertial parameters (read-only; the chains carry the same bodies)."""
    devices = chain_devices(design)
    parameters = devices[0].standard_parameters()
    parameters.flags.writeable = False
    return tuple((device, parameters) for device in devices)


def _joint_inertia(device: Device, parameters: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``M_i`` at chain angles ``(..., 3)``: one pose straight from the engine's kernel (an optimization
    candidate is seen once, so fitting its model would not pay), a batch of poses from the engine's
    fitted model of the geometry (fitted once, then cheaper per pose). Both are exact."""
    if q.ndim == 1:
        return tree_mass_matrix(device.mechanism, q, parameters)
    return dynamics_of(device).H(q.reshape(-1, 3), parameters).reshape(q.shape + (3,))


def chain_mass_matrix(design: RCubeDesign, chain: int, q_chain) -> np.ndarray:
    """Joint-space inertia ``M_i = sum_j J_gij^T M_ij J_gij`` of one chain (eq. 5.199-5.208), ``(..., 3, 3)``."""
    device, parameters = _chain_parameters(design)[chain]
    return _joint_inertia(device, parameters, np.asarray(q_chain, dtype=float))


def chain_cartesian_mass(design: RCubeDesign, chain: int, q_chain) -> np.ndarray:
    """``M_Ci = J_i^-T M_i J_i^-1`` (eq. 5.223)."""
    J = chain_jacobian(design.geometry, chain, q_chain)
    return cartesian_inertia(chain_mass_matrix(design, chain, q_chain), J)


def cartesian_mass_matrix(design: RCubeDesign, position) -> np.ndarray:
    """``M_C* = sum_i M_Ci`` (eq. 5.227) at platform positions ``(..., 3)``; a platform mass is shared."""
    g = design.geometry
    q = inverse_kinematics(g, position)
    require_regular(g, q)
    return sum(
        cartesian_inertia(_joint_inertia(device, parameters, q[..., i, :]), chain_jacobian(g, i, q[..., i, :]))
        for i, (device, parameters) in enumerate(_chain_parameters(design))
    )


def nonlinear_terms(design: RCubeDesign, position, velocity) -> np.ndarray:
    """``B* = sum_i B_i`` (eq. 5.224, 5.228) at a platform position and velocity ``(3,)``.

    With ``r_dot = J_i q_i_dot``, eq. 5.224 reads
    ``B_i = J_i^-T (C_i q_i_dot - M_i J_i^-1 J_i_dot q_i_dot)``, where
    ``C_i q_i_dot = M_i_dot q_i_dot - 1/2 d(q_i_dot^T M_i q_i_dot)/dq_i`` with the engine's exact
    Coriolis matrix ``C_i`` (:func:`~hapticdesign.analysis.dynamics.device.coriolis_matrix`, from the
    Christoffel symbols of ``M_i``).
    """
    g = design.geometry
    r_dot = np.asarray(velocity, dtype=float)
    q = inverse_kinematics(g, position)
    require_regular(g, q)
    qd = passive_rates(g, q, r_dot)
    total = np.zeros(3)
    for i, device in enumerate(chain_devices(design)):
        qi, qdi = q[i], qd[i]
        J = chain_jacobian(g, i, qi)
        convective = mass_matrix(device, qi) @ np.linalg.solve(J, jacobian_rate(g, i, qi, qdi) @ qdi)
        total += np.linalg.solve(J.T, coriolis_matrix(device, qi, qdi) @ qdi - convective)
    return total
