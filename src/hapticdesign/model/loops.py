"""Closed kinematic loops: passive joints and the closure constraints that determine them.

A device with closed loops is described by its *loop-opened tree* (every joint, actuated or
passive, is a coordinate of the tree, :class:`~hapticdesign.model.mechanism.Mechanism`) plus
closure constraints: two frames of the tree that must coincide in chosen components of their
difference in the base frame,

    phi(q_a, q_p) = select(x_A - x_B) = 0,

where the translational components ``x, y, z`` compare the frames' origins and the rotational
ones ``rx, ry, rz`` the axis-angle vector of ``R_A R_B^T``. The passive coordinates ``q_p``
follow from the actuated ones ``q_a`` (the generalization of the affine dependent joints of
seed 000 eq. 2.38-2.43 to closures that are not affine in the coordinates). This module holds
only *what the device is*; the solver lives in :mod:`hapticdesign.analysis.loops`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hapticdesign.errors import UserError

COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")
"""Closure components in the base frame: origin difference, then rotation-vector difference."""
COMPONENT_SETS = {"position": ("x", "y", "z"), "pose": COMPONENTS}
POSE_LIMIT = 1000.0
"""Largest magnitude of a home or assembly value (rad or m) and of a handle position's coordinates (m): the solver
follows the loops from the assembly at home to every pose asked for in steps of 0.1 rad, and the inverse kinematics
walks to a position in steps of millimetres, so a far-off home or target is work without end (or an overflow)."""


def handle_position(value, what: str) -> list[float]:
    """``value`` as a handle position [x, y, z] of finite numbers within +-:data:`POSE_LIMIT` m, or a one-line
    :class:`UserError` naming ``what`` (a target, a home position, a workspace point)."""
    try:
        numbers = [float(v) for v in value]
    except (TypeError, ValueError):
        raise UserError(f"{what}: a handle position is 3 numbers [x, y, z] (m), got {str(value)[:60]}") from None
    if len(numbers) != 3 or not all(math.isfinite(v) and abs(v) <= POSE_LIMIT for v in numbers):
        raise UserError(f"{what}: a handle position is 3 finite numbers within +-{POSE_LIMIT:g} m, got "
                        f"{', '.join(f'{v:g}' for v in numbers[:6])}")
    return numbers


def component_indices(close: str | list[str] | tuple[str, ...]) -> tuple[int, ...]:
    """``[x, z]`` -> (0, 2); ``position`` -> (0, 1, 2); ``pose`` -> (0, ..., 5). Raises ValueError."""
    names = COMPONENT_SETS.get(close, None) if isinstance(close, str) else tuple(close)
    if names is None:
        raise ValueError(f"close: {close!r} is not position, pose or a list of x, y, z, rx, ry, rz")
    if not names:
        raise ValueError("close: give at least one component (x, y, z, rx, ry, rz, position or pose)")
    unknown = [n for n in names if n not in COMPONENTS]
    if unknown:
        raise ValueError(f"close: unknown component {unknown[0]!r} (use x, y, z, rx, ry, rz, position or pose)")
    if len(set(names)) != len(names):
        raise ValueError("close: a component is listed twice")
    return tuple(sorted(COMPONENTS.index(n) for n in names))


@dataclass(frozen=True)
class LoopClosure:
    """Frames ``frames[0]`` and ``frames[1]`` coincide in the base-frame ``components`` (indices into COMPONENTS)."""

    frames: tuple[str, str]
    components: tuple[int, ...]

    def describe(self) -> str:
        names = ", ".join(COMPONENTS[c] for c in self.components)
        return f"{self.frames[0]} = {self.frames[1]} in {names}"


@dataclass(frozen=True)
class ClosedLoops:
    """Which tree coordinates are passive, the closures that fix them, and the assembly at home.

    ``passive`` are indices into the mechanism's coordinates (the others are actuated, in order);
    ``home`` holds the actuated values of the home pose (none given: 0) and ``assembly`` the passive values near
    the intended assembly branch at home (the Newton start of :mod:`hapticdesign.analysis.loops`). A tree's loops
    are the empty ones, ``ClosedLoops()``: no closures, no passive coordinates (Pinocchio's view: a tree is a
    device whose list of constraints is empty), so every device is solved by the same calls.
    """

    passive: tuple[int, ...] = ()
    closures: tuple[LoopClosure, ...] = ()
    assembly: tuple[float, ...] = ()
    home: tuple[float, ...] = ()

    @property
    def empty(self) -> bool:
        """No closures (a tree): nothing to close, no passive coordinates, the device's equations of motion keep
        their exact trigonometric basis."""
        return not self.closures

    @property
    def n_constraints(self) -> int:
        return sum(len(c.components) for c in self.closures)

    def actuated(self, n_coordinates: int) -> tuple[int, ...]:
        return tuple(k for k in range(n_coordinates) if k not in self.passive)

    def guess(self, n_coordinates: int) -> np.ndarray:
        """The Newton start at home (every coordinate): ``home``'s actuated values, ``assembly``'s passive ones."""
        q = np.zeros(n_coordinates)
        q[list(self.actuated(n_coordinates))] = self.home or 0.0
        q[list(self.passive)] = self.assembly
        return q

    def validate(self, coordinates: tuple[str, ...], frames: set[str]) -> None:
        """Square closure system (none for a tree) and known frames; raises a one-line UserError."""
        n = len(coordinates)
        if len(set(self.passive)) != len(self.passive) or not all(0 <= k < n for k in self.passive):
            raise UserError("passive joints must be distinct coordinates of the mechanism")
        if self.passive and len(self.passive) == n:
            raise UserError("every joint is passive: mark at least one joint as actuated")
        if self.passive and not self.closures:
            raise UserError(f"passive joints {', '.join(coordinates[k] for k in self.passive)} need loops to close")
        if self.closures and not self.passive:
            raise UserError("loops need at least one passive joint (actuated: false)")
        for closure in self.closures:
            for frame in closure.frames:
                if frame not in frames:
                    raise UserError(f"loop {closure.describe()}: unknown frame {frame!r}")
            if closure.frames[0] == closure.frames[1]:
                raise UserError(f"loop {closure.describe()}: a frame cannot close on itself")
        m, k = self.n_constraints, len(self.passive)
        if m != k:
            kind = "redundant" if m > k else "insufficient"
            raise UserError(
                f"{kind} loop closures: {m} constraint component{'s' if m != 1 else ''} for {k} passive joint"
                f"{'s' if k != 1 else ''} (each passive joint needs exactly one closure component)"
            )
        if len(self.assembly) != k:
            raise UserError(f"assembly: expected {k} passive values, got {len(self.assembly)}")
        if len(self.home) not in (0, n - k):
            raise UserError(f"home: expected {n - k} actuated values, got {len(self.home)}")
        for label, values in (("home", self.home), ("assembly", self.assembly)):
            if not all(math.isfinite(v) and abs(v) <= POSE_LIMIT for v in values):
                raise UserError(f"{label}: joint values must lie within +-{POSE_LIMIT:g} (rad or m), got "
                                f"{', '.join(f'{v:g}' for v in values)}")
