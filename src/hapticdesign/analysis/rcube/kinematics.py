"""Modified R-CUBE kinematics in closed form (seed 001 §5.1), vectorized over poses.

Positions are ``(..., 3)`` arrays in metres, chain angles ``(..., 3, 3)`` with row ``i`` =
``(q_i1, q_i2, q_i3)`` of chain ``i``. The closed forms are checked in the tests against the
numeric kinematics of :func:`hapticdesign.model.rcube.chain_mechanism`.
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.kinematics import forward_kinematics as frame_pose
from hapticdesign.analysis.kinematics import poses_and_jacobians
from hapticdesign.errors import UserError
from hapticdesign.model.rcube import RCubeGeometry, axis_permutation, chain_mechanism

SINGULAR_TOLERANCE = 1e-9


def _as_positions(position) -> np.ndarray:
    r = np.asarray(position, dtype=float)
    if r.shape[-1:] != (3,) or not np.all(np.isfinite(r)):
        raise UserError(f"a platform position is three finite numbers (metres), got {position!r}")
    return r


def active_angles(geometry: RCubeGeometry, position) -> np.ndarray:
    """``q_i1 = asin((r_i - S) / l1)`` (eq. 5.30); raises when ``|r_i - S| > l1``."""
    r = _as_positions(position)
    s = (r - geometry.S) / geometry.l1
    if np.any(np.abs(s) > 1.0):
        raise UserError(
            f"position {np.round(r, 6).tolist()} is unreachable: every coordinate must lie within "
            f"S +- l1 = {geometry.S:g} +- {geometry.l1:g} m (eq. 5.30)"
        )
    return np.arcsin(s)


def passive_reach(geometry: RCubeGeometry, position) -> np.ndarray:
    """``cos q_i3`` of eq. 5.39 for each chain ``(..., 3)``; the pose is reachable when it is in [-1, 1]."""
    r = _as_positions(position)
    q1 = np.arcsin(np.clip((r - geometry.S) / geometry.l1, -1.0, 1.0))
    g = geometry
    out = np.empty(r.shape)
    for chain in range(3):
        a, b, c = axis_permutation(chain)
        x = r[..., c] - g.l1 * np.cos(q1[..., a])
        out[..., chain] = (x**2 + r[..., b] ** 2 - g.l2**2 - g.l3**2) / (2 * g.l2 * g.l3)
    return out


def is_reachable(geometry: RCubeGeometry, position) -> np.ndarray:
    """Boolean mask of positions the mechanism reaches with non-singular chains (eq. 5.30, 5.39, 5.72)."""
    r = _as_positions(position)
    s = (r - geometry.S) / geometry.l1
    ok_active = np.all(np.abs(s) < 1.0, axis=-1)
    c3 = passive_reach(geometry, r)
    return ok_active & np.all(np.abs(c3) < 1.0, axis=-1)


def inverse_kinematics(geometry: RCubeGeometry, position) -> np.ndarray:
    """All joint angles ``(..., 3, 3)`` for platform positions (eq. 5.30-5.45).

    Raises :class:`UserError` when a position is out of reach of the active or passive links.
    """
    r = _as_positions(position)
    g = geometry
    active_angles(g, r)  # raises when out of the active links' reach
    c3_all = passive_reach(g, r)
    if np.any(np.abs(c3_all) > 1.0):
        raise UserError(
            f"position {np.round(r, 6).tolist()} is unreachable by the passive links l2 = {g.l2:g}, "
            f"l3 = {g.l3:g} m (|cos q_i3| > 1, eq. 5.39)"
        )
    return np.stack([chain_angles(g, chain, r) for chain in range(3)], axis=-2)


def chain_angles(geometry: RCubeGeometry, chain: int, position) -> np.ndarray:
    """Angles ``(q_i1, q_i2, q_i3)`` of one chain ``(..., 3)`` (eq. 5.30-5.45), unchecked: positions out
    of that chain's reach give clipped (meaningless) angles; see :func:`passive_reach`."""
    r = _as_positions(position)
    g = geometry
    a, b, c = axis_permutation(chain)
    q1 = np.arcsin(np.clip((r[..., a] - g.S) / g.l1, -1.0, 1.0))
    q2, q3 = arm_angles(r[..., b], r[..., c] - g.l1 * np.cos(q1), g.l2, g.l3, g.sigma)
    return np.stack([q1, q2, q3], axis=-1)


def elbow_cosine(r_x, r_y, l2, l3) -> np.ndarray:
    """``cos q_i3`` of the passive 2R arm (links ``l2``, ``l3``) reaching ``(r_x, r_y)`` (eq. 5.39, 6.32)."""
    return (np.square(r_x) + np.square(r_y) - np.square(l2) - np.square(l3)) / (2.0 * l2 * l3)


def arm_angles(r_x, r_y, l2, l3, sigma: int) -> tuple[np.ndarray, np.ndarray]:
    """Angles ``(q_i2, q_i3)`` of the passive 2R arm reaching ``(r_x, r_y)`` with the elbow configuration
    ``sigma`` (eq. 5.39-5.45): ``r_y`` is the reach along the link-1 direction (``r_c - l1 cos q_i1``) and
    ``r_x`` the across coordinate ``r_b``. Unreachable points are evaluated at the nearest reachable elbow
    angle (:func:`passive_reach` tells them apart)."""
    c3 = np.clip(elbow_cosine(r_x, r_y, l2, l3), -1.0, 1.0)
    s3 = sigma * np.sqrt(1.0 - c3**2)
    den = l2**2 + l3**2 + 2.0 * l2 * l3 * c3
    c2 = (l2 * r_y + l3 * r_y * c3 - l3 * r_x * s3) / den
    s2 = (-l2 * r_x - l3 * r_x * c3 - l3 * r_y * s3) / den
    return np.arctan2(s2, c2), np.arctan2(s3, c3)


def forward_kinematics(geometry: RCubeGeometry, q_active) -> np.ndarray:
    """Platform position from the active angles ``(..., 3)``: ``r_i = S + l1 sin q_i1`` (eq. 5.28)."""
    q = np.asarray(q_active, dtype=float)
    if q.shape[-1:] != (3,) or not np.all(np.isfinite(q)):
        raise UserError(f"expected three finite active angles (rad), got {q_active!r}")
    return geometry.S + geometry.l1 * np.sin(q)


def chain_position(geometry: RCubeGeometry, chain: int, q_chain) -> np.ndarray:
    """Platform position computed along chain ``chain`` (eq. 5.21-5.23)."""
    q = np.asarray(q_chain, dtype=float)
    g = geometry
    q1, q2, q3 = q[..., 0], q[..., 1], q[..., 2]
    a, b, c = axis_permutation(chain)
    out = np.empty(q.shape)
    out[..., a] = g.S + g.l1 * np.sin(q1)
    out[..., b] = -g.l2 * np.sin(q2) - g.l3 * np.sin(q2 + q3)
    out[..., c] = g.l1 * np.cos(q1) + g.l2 * np.cos(q2) + g.l3 * np.cos(q2 + q3)
    return out


def active_jacobian(geometry: RCubeGeometry, q_active) -> np.ndarray:
    """``J_m = diag(l1 cos q_i1)`` (eq. 5.49), shape ``(..., 3, 3)``."""
    q = np.asarray(q_active, dtype=float)
    J = np.zeros(q.shape + (3,))
    idx = np.arange(3)
    J[..., idx, idx] = geometry.l1 * np.cos(q)
    return J


def chain_jacobian(geometry: RCubeGeometry, chain: int, q_chain) -> np.ndarray:
    """``J_i`` (eq. 5.53-5.55): platform velocity per chain angle rate, ``(..., 3, 3)``."""
    q = np.asarray(q_chain, dtype=float)
    g = geometry
    q1, q2, q23 = q[..., 0], q[..., 1], q[..., 1] + q[..., 2]
    a, b, c = axis_permutation(chain)
    J = np.zeros(q.shape[:-1] + (3, 3))
    J[..., a, 0] = g.l1 * np.cos(q1)
    J[..., b, 1] = -g.l2 * np.cos(q2) - g.l3 * np.cos(q23)
    J[..., b, 2] = -g.l3 * np.cos(q23)
    J[..., c, 0] = -g.l1 * np.sin(q1)
    J[..., c, 1] = -g.l2 * np.sin(q2) - g.l3 * np.sin(q23)
    J[..., c, 2] = -g.l3 * np.sin(q23)
    return J


def chain_jacobian_determinant(geometry: RCubeGeometry, q_chain) -> np.ndarray:
    """``det J_i = l1 l2 l3 cos q_i1 sin q_i3`` (eq. 5.71), up to the chain's axis permutation sign."""
    q = np.asarray(q_chain, dtype=float)
    return geometry.l1 * geometry.l2 * geometry.l3 * np.cos(q[..., 0]) * np.sin(q[..., 2])


def is_singular(geometry: RCubeGeometry, q, tolerance: float = SINGULAR_TOLERANCE) -> np.ndarray:
    """True where any chain meets ``cos q_i1 = 0`` or ``sin q_i3 = 0`` (eq. 5.72-5.73); ``q (..., 3, 3)``."""
    q = np.asarray(q, dtype=float)
    return np.any((np.abs(np.cos(q[..., 0])) < tolerance) | (np.abs(np.sin(q[..., 2])) < tolerance), axis=-1)


def require_regular(geometry: RCubeGeometry, q) -> None:
    """Raise :class:`UserError` at a singular pose (eq. 5.70-5.73)."""
    if np.any(is_singular(geometry, q)):
        raise UserError("singular pose: an active angle is +-pi/2 or a passive elbow q_i3 is 0 or pi (eq. 5.73)")


def passive_rates(geometry: RCubeGeometry, q, r_dot) -> np.ndarray:
    """Chain angle rates ``q_i_dot = J_i^-1 r_dot`` (eq. 5.57 with ``r_dot = J_m q_m_dot``), ``(..., 3, 3)``."""
    q = np.asarray(q, dtype=float)
    r_dot = np.asarray(r_dot, dtype=float)
    return np.stack([np.linalg.solve(chain_jacobian(geometry, i, q[..., i, :]), r_dot[..., None])[..., 0] for i in range(3)], axis=-2)


def jacobian_rate(geometry: RCubeGeometry, chain: int, q_chain, q_dot) -> np.ndarray:
    """``dJ_i/dt`` for chain rates ``q_dot``: the exact derivative of eq. 5.53-5.55."""
    q = np.asarray(q_chain, dtype=float)
    qd = np.asarray(q_dot, dtype=float)
    g = geometry
    q1, q2, q23 = q[..., 0], q[..., 1], q[..., 1] + q[..., 2]
    w1, w2, w23 = qd[..., 0], qd[..., 1], qd[..., 1] + qd[..., 2]
    a, b, c = axis_permutation(chain)
    Jd = np.zeros(q.shape[:-1] + (3, 3))
    Jd[..., a, 0] = -g.l1 * np.sin(q1) * w1
    Jd[..., b, 1] = g.l2 * np.sin(q2) * w2 + g.l3 * np.sin(q23) * w23
    Jd[..., b, 2] = g.l3 * np.sin(q23) * w23
    Jd[..., c, 0] = -g.l1 * np.cos(q1) * w1
    Jd[..., c, 1] = -g.l2 * np.cos(q2) * w2 - g.l3 * np.cos(q23) * w23
    Jd[..., c, 2] = -g.l3 * np.cos(q23) * w23
    return Jd


def passive_accelerations(geometry: RCubeGeometry, q, r_dot, r_ddot) -> np.ndarray:
    """Chain angle accelerations from platform motion (eq. 5.58-5.60): ``J_i q_dd = r_dd - J_i_dot q_d``."""
    q = np.asarray(q, dtype=float)
    qd = passive_rates(geometry, q, r_dot)
    out = []
    for i in range(3):
        rhs = np.asarray(r_ddot, dtype=float) - (jacobian_rate(geometry, i, q[..., i, :], qd[..., i, :]) @ qd[..., i, :, None])[..., 0]
        out.append(np.linalg.solve(chain_jacobian(geometry, i, q[..., i, :]), rhs[..., None])[..., 0])
    return np.stack(out, axis=-2)


def extended_jacobian(geometry: RCubeGeometry, chain: int, q_chain) -> np.ndarray:
    """``J_Hi`` (eq. 5.61-5.67): 6 x 3 linear and angular velocity coefficients of the platform frame.

    Its angular rows vanish: the platform never rotates (eq. 5.68-5.69).
    """
    return poses_and_jacobians(chain_mechanism(geometry, chain), q_chain)[1]


def extended_active_jacobian(geometry: RCubeGeometry, q_active) -> np.ndarray:
    """``J_Hm = [J_m; 0]`` (eq. 5.68), shape ``(..., 6, 3)``."""
    J = active_jacobian(geometry, q_active)
    return np.concatenate([J, np.zeros_like(J)], axis=-2)


def critical_poses(geometry: RCubeGeometry, q_max: float) -> dict[str, np.ndarray]:
    """Home, fully folded and fully extended platform positions (§5.1.5): ``q_i1 = 0, -q_max, q_max``."""
    if not np.isfinite(q_max) or not 0.0 < q_max < np.pi / 2:
        raise UserError(f"q_max must lie in (0, pi/2), got {q_max!r}")
    return {
        "home": forward_kinematics(geometry, np.zeros(3)),
        "folded": forward_kinematics(geometry, np.full(3, -q_max)),
        "extended": forward_kinematics(geometry, np.full(3, q_max)),
    }


def q_max_for_cube(geometry: RCubeGeometry, side: float = 0.12) -> float:
    """Active range of a centred cube of edge ``side``: ``l1 sin q_max = side / 2`` (eq. 6.23-6.24)."""
    ratio = side / (2 * geometry.l1)
    if not 0.0 < ratio < 1.0:
        raise UserError(f"a {side:g} m cube needs l1 > {side / 2:g} m (eq. 6.24), got l1 = {geometry.l1:g}")
    return float(np.arcsin(ratio))


def cube_grid(geometry: RCubeGeometry, side: float = 0.12, n: int = 5) -> np.ndarray:
    """``n^3`` positions spanning the cube of edge ``side`` centred at home, shape ``(n, n, n, 3)``."""
    axis = np.linspace(-side / 2, side / 2, n)
    X, Y, Z = np.meshgrid(axis, axis, axis, indexing="ij")
    return geometry.home + np.stack([X, Y, Z], axis=-1)


def dexterous_cube(geometry: RCubeGeometry, side: float = 0.12, n: int = 9) -> bool:
    """Whether the cube of edge ``side`` around home is reachable and singularity free (§4.1.1, §6.1.3)."""
    return bool(np.all(is_reachable(geometry, cube_grid(geometry, side, n))))


def workspace_reach_index(positions) -> float:
    """``W_r = max |r| - min |r|`` over sampled positions (eq. 4.2)."""
    norms = np.linalg.norm(_as_positions(positions).reshape(-1, 3), axis=1)
    return float(norms.max() - norms.min())


def critical_manipulability(geometry: RCubeGeometry, q_max: float) -> float:
    """Worst-pose manipulability ``mu_v = l1 cos q_max`` (eq. 6.7-6.8, cube root of ``det J_m``)."""
    return float(geometry.l1 * np.cos(q_max))


def critical_condition_number(q_max: float) -> float:
    """Worst-pose condition number ``c_v = 1 / cos^2 q_max`` (eq. 6.14-6.18).

    The seed's norm here is the largest eigenvalue of ``J_m J_m^T``, so this is the square of the
    singular-value ratio that :func:`hapticdesign.analysis.metrics.kinematic.condition_number` gives.
    """
    return float(1.0 / np.cos(q_max) ** 2)


CHAIN_POINTS = ("chain_base", "tip1", "tip2", "tip3")
"""The frames of a chain drawn as its links: the base, then the ends of l1, l2 and l3 (the platform)."""


def chain_paths(geometry: RCubeGeometry, position=None) -> list[np.ndarray]:
    """Each chain's points :data:`CHAIN_POINTS` (4, 3) with the platform at ``position`` (home by default): the chain's
    own forward kinematics (eq. 5.2-5.18) at the angles of eq. 5.30-5.45."""
    position = geometry.home if position is None else _as_positions(position)
    angles = inverse_kinematics(geometry, position)
    return [np.array([frame_pose(chain_mechanism(geometry, chain), np.asarray(angles[chain], dtype=float), frame)[:3, 3]
                      for frame in CHAIN_POINTS]) for chain in range(3)]
