"""A Cartesian workspace the handle must reach: a box sampled on a grid, reached by inverse kinematics (issue 23).

``Workspace(center, size, grid)`` is the box ``center +- size / 2`` (m, base frame) sampled with ``grid``
points per axis whose size is not 0, edges included; an axis of size 0 keeps the centre's coordinate (a
planar device's plane, a line). :meth:`Workspace.points` lists the points in snake (boustrophedon) order, so
that each point is next to the one before it. :func:`reach_workspace` reaches them: from the device's home
pose (on the loops' ``assembly`` branch) to the first point, then from each point to the next, by the one
inverse kinematics of the project (:meth:`~hapticdesign.analysis.configuration.Configuration.reach`, small
Cartesian steps on the home branch). A point out of reach, behind a singularity or needing a joint outside its
limits raises a one-line :class:`UserError` naming the point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hapticdesign.analysis.configuration import check_limits, configuration_of
from hapticdesign.errors import InputError, UserError
from hapticdesign.model.device import Device
from hapticdesign.model.loops import handle_position

POINT_LIMIT = 10_000
"""Most workspace points (``grid`` to the power of the axes whose size is not 0)."""


@dataclass(frozen=True)
class Workspace:
    """A box ``center +- size / 2`` (m) with ``grid`` points per axis whose size is not 0."""

    center: tuple[float, float, float]
    size: tuple[float, float, float]
    grid: int

    def __post_init__(self) -> None:
        center = tuple(float(v) for v in np.ravel(self.center))
        size = tuple(float(v) for v in np.ravel(self.size))
        if len(center) != 3 or not all(math.isfinite(v) for v in center):
            raise InputError(f"workspace: the centre is 3 finite numbers (m), got {list(np.ravel(self.center))}",
                             "center")
        if len(size) != 3 or not all(math.isfinite(v) and v >= 0.0 for v in size):
            raise InputError(f"workspace: the size is 3 finite numbers >= 0 (m), got {list(np.ravel(self.size))}",
                             "size")
        if isinstance(self.grid, bool) or not isinstance(self.grid, (int, np.integer)):
            raise InputError(f"workspace: grid is a whole number of points per axis, got {self.grid!r}", "grid")
        axes = sum(v > 0.0 for v in size)
        if axes and self.grid < 2:
            raise InputError(f"workspace: grid must be at least 2 (points per axis, edges included), got {self.grid}",
                             "grid")
        if axes and float(self.grid) ** axes > POINT_LIMIT:
            raise InputError(f"workspace: {self.grid}^{axes} points is above the limit of {POINT_LIMIT}", "grid")
        for corner in (np.array(center) - np.array(size) / 2, np.array(center) + np.array(size) / 2):
            try:
                handle_position(corner, "workspace")
            except UserError as exc:
                raise InputError(f"{exc} (a corner of the box, centre +- size / 2)", "center", "size") from None
        object.__setattr__(self, "center", center)
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "grid", int(self.grid))

    def points(self) -> np.ndarray:
        """The grid points (P, 3) in snake order (each next to the one before it); the centre alone when every
        size is 0."""
        axes = [k for k in range(3) if self.size[k] > 0.0]
        offsets = np.linspace(-0.5, 0.5, self.grid)
        out = []
        for index in _snake([self.grid] * len(axes)):
            point = list(self.center)
            for k, i in zip(axes, index):
                point[k] += self.size[k] * offsets[i]
            out.append(point)
        return np.array(out, dtype=float)


    @property
    def center_index(self) -> int | None:
        """The place of the box's centre among :meth:`points`: the middle of every axis of nonzero size, which an
        odd grid holds; None for an even grid (no point at the centre)."""
        axes = sum(v > 0.0 for v in self.size)
        if axes and self.grid % 2 == 0:
            return None
        return _snake([self.grid] * axes).index(((self.grid - 1) // 2,) * axes)

    def describe(self) -> str:
        """How coarse the grid is: ``27 points, grid 3``."""
        count = len(self.points())
        return f"{count} point{'s' if count > 1 else ''}, grid {self.grid}"


def _snake(counts: list[int]) -> list[tuple[int, ...]]:
    """Grid indices in boustrophedon order: every other sweep of the inner axes runs backwards."""
    if not counts:
        return [()]
    inner = _snake(counts[1:])
    return [(i, *rest) for i in range(counts[0]) for rest in (inner if i % 2 == 0 else inner[::-1])]


@dataclass(frozen=True)
class WorkspacePoses:
    """The workspace points (P, 3) and the poses that reach them: actuated (P, n_a) and full (P, N) coordinates."""

    points: np.ndarray
    q: np.ndarray
    full: np.ndarray


def reach_workspace(device: Device, points: np.ndarray, frame: str | None = None,
                    start: np.ndarray | None = None) -> WorkspacePoses:
    """The poses that put the handle (or ``frame``'s origin) at ``points`` (P, 3), reached in order from home (or
    from the actuated coordinates ``start``, on home's branch). A point is reached when the way from the point
    before it, or else the straight way from the start, gets there on the start's branch (no singularity crossed,
    the loops' assembly branch kept) and its pose is within the joint limits: the one meaning of "reached" of a
    study's workspace and of the spec sheet's cube (:func:`cube_points`)."""
    points = np.asarray(points, dtype=float)
    space = configuration_of(device)
    q, full = space.reach(points, frame, None if start is None else space.full(np.asarray(start, dtype=float)))
    check_limits(device, q, points)
    return WorkspacePoses(points, q, full)


def cube_points(center, basis: np.ndarray, edge: float, grid: int) -> np.ndarray:
    """The grid points (snake order) of the cube of ``edge`` (m) centred at ``center`` on the directions ``basis``
    (3, k) spans (a square for a planar device, a segment for one axis): the study box ``Workspace(center, size,
    grid)`` with ``edge`` on the base axes the directions are (every axis when k = 3), else the same grid on the
    basis itself (a plane no study box lies in)."""
    basis = np.asarray(basis, dtype=float)
    k = basis.shape[1]
    axes = [0, 1, 2] if k == 3 else [int(np.argmax(np.abs(column))) for column in basis.T]
    if k == 3 or (len(set(axes)) == k and all(abs(basis[a, j]) > 1.0 - 1e-9 for j, a in enumerate(axes))):
        return Workspace(tuple(center), tuple(edge if a in axes else 0.0 for a in range(3)), grid).points()
    offsets = Workspace((0.0, 0.0, 0.0), (edge,) * k + (0.0,) * (3 - k), grid).points()[:, :k]
    return np.asarray(center, dtype=float) + offsets @ basis.T
