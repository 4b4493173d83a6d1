"""The stiffest stable virtual wall at a handle: the sampled loop's exact limit along a direction, or the worst one.

Along a unit direction ``u`` of the directions the handle moves (basis ``U``), the handle is the 1-DOF mass-damper
of mass ``1 / (u^T M u)`` (``M = U^T J_v H^-1 J_v^T U``, the mobility: the inverse of the Cartesian mass) and
damping ``u^T D u`` (``D = U^T J_v^+T B J_v^+ U``, ``B`` the joints' and motors' viscous damping). A virtual spring
``K`` (and damper) sampled every ``T`` with a delay of ``d`` samples is stable below the exact limit of that loop
(:func:`hapticdesign.analysis.sampled_loop.exact_boundary`: the plant discretized exactly, the closed loop's spectral
radius reaching 1). The worst direction is searched over the axes, the principal directions of ``M`` and of ``D``
and :data:`DIRECTIONS` evenly spread directions (a Fibonacci sphere; a half circle for a planar device).
:func:`wall_limits` takes many points at once: the loops of all their directions are searched together
(:func:`~hapticdesign.analysis.sampled_loop.exact_boundaries`, one batched eigenvalue call per step), and a
direction whose stable bracket lies above another's unstable one leaves the search early.
"""

from __future__ import annotations

import math

import numpy as np

from hapticdesign.analysis.sampled_loop import MassDampers, exact_boundaries
from hapticdesign.errors import UserError

DIRECTIONS = 60
"""Directions spread over the sphere (circle for a planar device) for the worst wall direction."""


MAX_PERIOD = 1.0
"""Longest sample period (s) of ``kmax``'s loop: a haptic loop samples far faster than 1 Hz, and the exact
discretization of a handle's mass over much longer periods overflows."""


def directions(dim: int, count: int = DIRECTIONS) -> np.ndarray:
    """Evenly spread unit vectors (Fibonacci sphere; a half circle in 2-D, a line in 1-D), symmetric use."""
    if dim == 1:
        return np.ones((1, 1))
    if dim == 2:
        t = np.pi * np.arange(count) / count
        return np.stack([np.cos(t), np.sin(t)], axis=1)
    k = np.arange(count) + 0.5
    z = 1.0 - k / count
    r = np.sqrt(1.0 - z**2)
    phi = np.pi * (3.0 - math.sqrt(5.0)) * k
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def wall_directions(mobility: np.ndarray, damping: np.ndarray) -> np.ndarray:
    """The axes, the principal directions of the mobility and of the damping, and evenly spread ones (rows; (..., C,
    k) for a stack of matrices (..., k, k))."""
    dim = mobility.shape[-1]
    stack = mobility.shape[:-2]
    principal = [np.swapaxes(np.linalg.eigh(m)[1], -1, -2) for m in (mobility, damping)]
    fixed = [np.broadcast_to(rows, (*stack, *rows.shape)) for rows in (np.eye(dim), directions(dim))]
    return np.concatenate([fixed[0], *principal, fixed[1]], axis=-2)


CHUNK_BYTES = 1 << 24
"""The closed-loop matrices :func:`wall_limits` searches at once (``8 (3 + 3 d)^2`` bytes a loop), at least one
point's."""


def wall_limit(mobility: np.ndarray, damping: np.ndarray, period: float, delay: int, virtual_damping: float = 0.0,
               direction: np.ndarray | None = None) -> float:
    """The exact stable wall stiffness (N/m) along ``direction`` (unit, in the basis of ``mobility``), or the smallest
    over :func:`wall_directions` when it is None (see the module docstring)."""
    along = None if direction is None else np.atleast_2d(direction)[None]
    return float(wall_limits(mobility[None], damping[None], period, delay, virtual_damping, along)[0])


def wall_limits(mobility: np.ndarray, damping: np.ndarray, period: float, delay: int, virtual_damping: float = 0.0,
                along: np.ndarray | None = None) -> np.ndarray:
    """:func:`wall_limit` at P points at once: ``mobility`` and ``damping`` (P, k, k), ``along`` None (the worst
    of :func:`wall_directions`) or (P, C, k) unit rows (the smallest over them); (P,) in N/m. The loops of all
    points and directions go through :func:`~hapticdesign.analysis.sampled_loop.exact_boundaries` together, in
    chunks of about :data:`CHUNK_BYTES` of matrices."""
    rows = wall_directions(mobility, damping) if along is None else np.asarray(along, dtype=float)
    mass = 1.0 / np.einsum("pck,pkl,pcl->pc", rows, mobility, rows)
    damped = np.einsum("pck,pkl,pcl->pc", rows, damping, rows)
    per = max(1, CHUNK_BYTES // (8 * (3 + 3 * delay) ** 2 * rows.shape[1]))
    out = np.empty(len(mass))
    for start in range(0, len(mass), per):
        part = slice(start, start + per)
        systems = MassDampers(mass[part].ravel(), damped[part].ravel(), period, delay, virtual_damping)
        out[part] = exact_boundaries(systems, np.repeat(np.arange(len(mass[part])), rows.shape[1]))
    return out


def handle_wall_limits(mobility: np.ndarray, damping: np.ndarray, basis: np.ndarray, period: float, delay: int,
                       virtual_damping: float = 0.0, direction=None) -> np.ndarray:
    """:func:`wall_limits` at P handle poses (the ``kmax`` design index): ``mobility`` and ``damping`` (P, k, k) on
    the directions ``basis`` (P, 3, k) the handle moves, along ``direction`` (a base-frame vector, one the handle
    moves in) or the worst direction when it is None; the settings are checked here (one-line UserError)."""
    if isinstance(period, bool) or not isinstance(period, (int, float)) or not 0 < period <= MAX_PERIOD:
        raise UserError(f"index kmax: the sample period is a positive number of seconds, at most {MAX_PERIOD:g} s, "
                        f"got {period!r}")
    if isinstance(delay, bool) or not isinstance(delay, int) or not 0 <= delay <= 100:
        raise UserError(f"index kmax: the delay is a whole number of samples from 0 to 100, got {delay!r}")
    if isinstance(virtual_damping, bool) or not isinstance(virtual_damping, (int, float)) or not (
            math.isfinite(virtual_damping) and virtual_damping >= 0):
        raise UserError(f"index kmax: the wall's damping is a number >= 0 (N s/m), got {virtual_damping!r}")
    along = None
    if direction is not None:
        unit = np.asarray(direction, dtype=float)
        if unit.shape != (3,) or not np.all(np.isfinite(unit)) or not np.linalg.norm(unit) > 0:
            raise UserError(f"index kmax: the direction is 3 finite numbers, not all 0, got {direction!r}")
        unit = unit / np.linalg.norm(unit)
        along = np.swapaxes(basis, 1, 2) @ unit
        if not np.all(np.abs(np.linalg.norm(along, axis=1) - 1.0) <= 1e-9):
            raise UserError(f"index kmax: the direction {np.round(unit, 6).tolist()} is not one the handle moves in")
        along = along[:, None, :]
    return wall_limits(mobility, damping, float(period), delay, float(virtual_damping), along)
