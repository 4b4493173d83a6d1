"""Design indices of any device (trees and closed loops) at workspace poses: one registry, each with its formula,
unit and source (issue 23; docs/indices.md).

At a pose, ``J_v`` is the handle's translational Jacobian over the actuated coordinates (3 x n_a, base frame;
``J T`` with loops, ``qd = T qd_a``) and ``H`` the mass matrix over the actuated coordinates with the reflected
rotor inertia. With ``k = min(3, n_a)`` the directions the handle moves are the ``k`` left singular vectors
``U`` of ``J_v`` (a planar device's plane), ``sigma_1 >= ... >= sigma_k`` its singular values, and the handle's
Cartesian mass on them ``Lambda = (U^T J_v H^-1 J_v^T U)^-1`` (k x k; ``(J_v H^-1 J_v^T)^+`` in that basis).

========================  =============================================  ===========  ==========================
index                     formula                                        unit         source
========================  =============================================  ===========  ==========================
``isotropy``              ``sigma_k / sigma_1``                          1            seed 001 eq. 4.40 (inverse)
``condition``             ``sigma_1 / sigma_k``                          1            seed 001 eq. 4.39-4.40
``manipulability``        ``sigma_1 ... sigma_k = sqrt(det(U^T J_v J_v^T U))``  m^k/rad^k  seed 001 eq. 4.36
``apparent_mass``         largest eigenvalue of ``Lambda``               kg           Khatib (1987); seed 001 §4.2
``inertia_uniformity``    smallest / largest eigenvalue of ``Lambda``    1            seed 001 eq. 4.47 (I_e)
========================  =============================================  ===========  ==========================

``m^k/rad^k``: metres per radian for revolute coordinates (m/m for prismatic ones). Reductions over the
workspace points: ``min``, ``max``, ``mean`` (:data:`REDUCTIONS`; ``isotropy`` with ``mean`` over a uniform
Cartesian grid is the global conditioning index of Gosselin & Angeles (1991), with the grid's points as the
measure).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from hapticdesign.analysis import kinematics
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics.device import mass_matrix_at
from hapticdesign.analysis.workspace import reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device


@dataclass
class HandleStates:
    """The handle's kinematics and dynamics at closed full poses ``full`` (P, N) of ``device``; each quantity is
    computed once, when an index first asks for it."""

    device: Device
    full: np.ndarray
    frame: str | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    @cached_property
    def jacobian(self) -> np.ndarray:
        """``J_v`` (P, 3, n_a)."""
        return handle_jacobians(self.device, self.full, self.frame)

    @cached_property
    def svd(self) -> tuple[np.ndarray, np.ndarray]:
        """``U`` (P, 3, k) and the singular values (P, k) of ``J_v``, largest first."""
        u, s, _ = np.linalg.svd(self.jacobian)
        k = s.shape[-1]
        return u[:, :, :k], s

    @cached_property
    def mass(self) -> np.ndarray:
        """``H`` (P, n_a, n_a) with the reflected rotor inertia."""
        return mass_matrix_at(self.device, self.full)

    @cached_property
    def cartesian_mass(self) -> np.ndarray:
        """Eigenvalues (P, k) of ``Lambda`` (kg), ascending."""
        u, _ = self.svd
        jv = self.jacobian
        mobility = np.swapaxes(u, 1, 2) @ jv @ np.linalg.solve(self.mass, np.swapaxes(jv, 1, 2)) @ u
        return 1.0 / np.linalg.eigvalsh(mobility)[:, ::-1]


def handle_jacobians(device: Device, full: np.ndarray, frame: str | None = None) -> np.ndarray:
    """``J_v T`` (P, 3, n_a): the handle's (or ``frame``'s) translational Jacobian over the actuated coordinates at
    closed full poses (P, N)."""
    space = configuration_of(device)
    full = np.atleast_2d(np.asarray(full, dtype=float))
    _, jac = kinematics.poses_and_jacobians(space.mechanism, full, frame)
    return jac[:, :3] @ space.velocity_transform(full)


@dataclass(frozen=True)
class Index:
    """A design index: its name, unit, formula, source and its values at the poses of :class:`HandleStates`."""

    name: str
    unit: str
    formula: str
    source: str
    values: Callable[[HandleStates], np.ndarray]


def _isotropy(h: HandleStates) -> np.ndarray:
    s = h.svd[1]
    return s[:, -1] / s[:, 0]


def _condition(h: HandleStates) -> np.ndarray:
    s = h.svd[1]
    return s[:, 0] / s[:, -1]


def _manipulability(h: HandleStates) -> np.ndarray:
    return np.prod(h.svd[1], axis=1)


def _apparent_mass(h: HandleStates) -> np.ndarray:
    return h.cartesian_mass.max(axis=1)


def _inertia_uniformity(h: HandleStates) -> np.ndarray:
    m = h.cartesian_mass
    return m.min(axis=1) / m.max(axis=1)


INDICES: dict[str, Index] = {index.name: index for index in (
    Index("isotropy", "1", "sigma_min(J_v) / sigma_max(J_v)", "seed 001 eq. 4.40 (inverse of the condition number)",
          _isotropy),
    Index("condition", "1", "sigma_max(J_v) / sigma_min(J_v)", "seed 001 eq. 4.39-4.40", _condition),
    Index("manipulability", "m^k/rad^k", "sqrt(det(U^T J_v J_v^T U))", "seed 001 eq. 4.36 (Yoshikawa 1985)",
          _manipulability),
    Index("apparent_mass", "kg", "largest eigenvalue of (J_v H^-1 J_v^T)^+", "Khatib (1987); seed 001 §4.2",
          _apparent_mass),
    Index("inertia_uniformity", "1", "smallest / largest eigenvalue of (J_v H^-1 J_v^T)^+", "seed 001 eq. 4.47 (I_e)",
          _inertia_uniformity),
)}
"""The registry: index name -> :class:`Index`."""

REDUCTIONS: dict[str, Callable[[np.ndarray], float]] = {
    "min": lambda v: float(np.min(v)),
    "max": lambda v: float(np.max(v)),
    "mean": lambda v: float(np.mean(v)),
}
"""Reductions of an index over the workspace points (the mean weighs each grid point alike)."""


class Evaluation(NamedTuple):
    """Values per index per point (P,), or ``reason`` (one line) when the design fails (then ``values`` is empty)."""

    values: dict[str, np.ndarray]
    reason: str | None = None


def require_indices(names: Iterable[str]) -> list[str]:
    """The names, each a registered index; an unknown one raises a one-line UserError."""
    names = list(names)
    for name in names:
        if name not in INDICES:
            raise UserError(f"unknown index {name!r} (indices: {', '.join(INDICES)})")
    return names


def evaluate(device: Device, points: np.ndarray, requests: Iterable[str], frame: str | None = None) -> Evaluation:
    """The indices ``requests`` at the workspace ``points`` (P, 3), reached in order from home
    (:func:`~hapticdesign.analysis.workspace.reach_workspace`). A point the handle does not reach (out of reach,
    behind a singularity, outside the joint limits) makes the design fail: the reason names the point."""
    names = require_indices(requests)
    try:
        poses = reach_workspace(device, points, frame)
        states = HandleStates(device, poses.full, frame)
        return Evaluation({name: INDICES[name].values(states) for name in names})
    except UserError as exc:
        return Evaluation({}, str(exc))


def reduce(values: np.ndarray, how: str) -> float:
    """An index over the workspace points reduced by ``min``, ``max`` or ``mean``."""
    if how not in REDUCTIONS:
        raise UserError(f"unknown reduction {how!r} (use {', '.join(REDUCTIONS)})")
    return REDUCTIONS[how](values)
