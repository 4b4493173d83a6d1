"""The stiffest stable virtual wall at a handle: the sampled loop's exact limit along a direction, or the worst one.

Along a unit direction ``u`` of the directions the handle moves (basis ``U``), the handle is the 1-DOF mass-damper
of mass ``1 / (u^T M u)`` (``M = U^T J_v H^-1 J_v^T U``, the mobility: the inverse of the Cartesian mass) and
damping ``u^T D u`` (``D = U^T J_v^+T B J_v^+ U``, ``B`` the joints' and motors' viscous damping). A virtual spring
``K`` (and damper) sampled every ``T`` with a delay of ``d`` samples is stable below the exact limit of that loop
(:func:`hapticdesign.simulation.boundary.exact_boundary`: the plant discretized exactly, the closed loop's spectral
radius reaching 1). The worst direction is searched over the axes, the principal directions of ``M`` and of ``D``
and :data:`DIRECTIONS` evenly spread directions (a Fibonacci sphere; a half circle for a planar device).
"""

from __future__ import annotations

import math

import numpy as np

from hapticdesign.simulation.boundary import MassDamper, exact_boundary

DIRECTIONS = 60
"""Directions spread over the sphere (circle for a planar device) for the worst wall direction."""


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
    """The axes, the principal directions of the mobility and of the damping, and evenly spread ones (rows)."""
    dim = mobility.shape[0]
    return np.vstack([np.eye(dim), np.linalg.eigh(mobility)[1].T, np.linalg.eigh(damping)[1].T, directions(dim)])


def wall_limit(mobility: np.ndarray, damping: np.ndarray, period: float, delay: int, virtual_damping: float = 0.0,
               direction: np.ndarray | None = None) -> float:
    """The exact stable wall stiffness (N/m) along ``direction`` (unit, in the basis of ``mobility``), or the smallest
    over :func:`wall_directions` when it is None (see the module docstring)."""
    candidates = wall_directions(mobility, damping) if direction is None else np.atleast_2d(direction)
    return float(min(exact_boundary(MassDamper(1.0 / float(u @ mobility @ u), float(u @ damping @ u), period, delay,
                                               virtual_damping))
                     for u in candidates))
