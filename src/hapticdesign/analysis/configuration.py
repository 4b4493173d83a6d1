"""The configuration space of a device geometry: the one door to closed poses (issue 21).

Every analysis that needs "the device at actuated coordinates ``q_a``" asks :func:`configuration_of`
(cached per geometry, like :func:`~hapticdesign.analysis.dynamics.device.dynamics_of`):

- ``names``, ``home``: the actuated coordinates and the home pose (zeros for a tree, the file's ``home``
  for a closed-loop device, whose loops need not close at 0); ``is_tree``;
- :meth:`Configuration.full`: every tree coordinate at actuated ones (the identity for a tree; for loops
  the passive joints continued from home on the assembly branch, :class:`~.loops.solver.LoopSolver`);
- :meth:`Configuration.velocity_transform`: ``T`` with ``qd = T qd_a`` (``T = [I; S]``,
  ``S = -Phi_p^-1 Phi_a``; the identity for a tree; seed 000 eq. 2.38-2.43 generalized);
- :meth:`Configuration.pose`, :meth:`Configuration.jacobian`: a frame's pose and its Jacobian over the
  actuated coordinates, ``J T`` (seed 000 eq. 2.20-2.26);
- :meth:`Configuration.reach` (and :meth:`Configuration.inverse_kinematics` for one point, :func:`handle_pose`
  with the device's joint limits): the one inverse kinematics of the project, the actuated coordinates that put
  a frame's origin (default: the handle) at positions, continued from home (or a given pose) on its branch in
  small Cartesian steps, point after point.

A closed-loop device's configuration (:class:`LoopConfiguration`) owns the loop solver; its dynamics model
(:class:`~.dynamics.closed_loop.ClosedLoopModel`) takes it, so one solver serves every caller.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from hapticdesign.analysis import kinematics
from hapticdesign.analysis.loops.solver import LoopSolver
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device, MechanismBuilder, build_mechanism
from hapticdesign.model.mechanism import Mechanism

IK_STEP = 0.01
"""m: largest Cartesian step of :meth:`Configuration.reach` along a straight segment."""
IK_WAY = 1e-3
"""Position tolerance on the way between two points, as a fraction of :data:`IK_STEP` (at the points themselves it
is 1e-12 of the device's size). A safeguard rather than a working part: with it 1000 times looser (every step on
the way accepted as it starts), 1200 random reaches from home of the five-bar, delta, Phantom and Falcon gave the same
answers and the same refusals, because Newton's steps clamped to :data:`IK_JOINT_STEP` follow the branch by
themselves (issue 36's mutation audit; no test distinguishes it yet)."""
IK_ITER = 30
"""Newton iterations per Cartesian step."""
IK_JOINT_STEP = 0.2
"""rad or m: largest change of an actuated coordinate in one Newton iteration."""
IK_SINGULAR = 1e-7
"""Smallest over largest singular value of the position Jacobian below which a pose is singular."""


class Configuration:
    """The configuration space of a tree (every coordinate actuated); see the module docstring."""

    is_tree = True

    def __init__(self, mechanism: Mechanism):
        self.mechanism = mechanism
        self.names: tuple[str, ...] = mechanism.coordinates if mechanism.loops is None else mechanism.actuated_coordinates
        self.n_actuated = len(self.names)
        self.home = self._home()
        """Actuated coordinates of the home pose."""

    def _home(self) -> np.ndarray:
        return np.zeros(self.mechanism.n_dof)

    def _actuated(self, q_a) -> np.ndarray:
        q_a = np.asarray(q_a, dtype=float)
        if q_a.ndim == 0 or q_a.shape[-1] != self.n_actuated:
            raise UserError(f"expected {self.n_actuated} actuated joint coordinates, got shape {q_a.shape}")
        if not np.all(np.isfinite(q_a)):
            raise UserError("joint coordinates must be finite numbers (got NaN or infinity)")
        return q_a

    def full(self, q_a, start: np.ndarray | None = None) -> np.ndarray:
        """Every tree coordinate at actuated poses (n_a,) or a motion (P, n_a) (continued from ``start``, a
        closed full pose, default home)."""
        return self._actuated(q_a)

    def velocity_transform(self, q: np.ndarray) -> np.ndarray:
        """``T`` (N x n_a) with ``qd = T qd_a`` at full coordinates ``q`` (N,) or (P, N)."""
        q = np.asarray(q, dtype=float)
        return np.broadcast_to(np.eye(self.n_actuated), q.shape[:-1] + (self.n_actuated, self.n_actuated)).copy()

    def pose(self, q_a, frame: str | None = None) -> np.ndarray:
        """World pose (4 x 4) of ``frame`` (default: the end effector) at actuated coordinates ``q_a`` (n_a,)."""
        return kinematics.forward_kinematics(self.mechanism, self.full(q_a), frame)

    def jacobian(self, q_a, frame: str | None = None) -> np.ndarray:
        """Geometric Jacobian (6 x n_a) of ``frame``'s origin over the actuated coordinates: ``J(q) T``."""
        q = self.full(q_a)
        return kinematics.jacobian(self.mechanism, q, frame) @ self.velocity_transform(q)

    def position_and_jacobian(self, q: np.ndarray, frame: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The origin of ``frame`` (default: the handle) and its translational Jacobian over the actuated
        coordinates, ``J_v T`` (3 x n_a), at the closed full pose ``q`` (N,)."""
        pose, jac = kinematics.poses_and_jacobians(self.mechanism, q, frame)
        return pose[:3, 3], jac[:3] @ self.velocity_transform(q)

    def inverse_kinematics(self, position, frame: str | None = None, start: np.ndarray | None = None) -> np.ndarray:
        """Actuated coordinates that put the origin of ``frame`` (default: the handle) at ``position`` (3,)
        (:meth:`reach` of one point)."""
        return self.reach(np.reshape(np.asarray(position, dtype=float), (1, -1)), frame, start)[0][0]

    def reach(self, positions, frame: str | None = None,
              start: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Actuated (P, n_a) and full (P, N) coordinates that put the origin of ``frame`` (default: the handle)
        at each of ``positions`` (P, 3) in turn: the one inverse kinematics of the project.

        Continuation from ``start`` (a closed full pose; default: home, on the loops' assembly branch) to the
        first point, then from each point to the next, along straight Cartesian segments in steps of at most
        :data:`IK_STEP` (met within :data:`IK_WAY` of the step on the way, within 1e-12 of the device's size at the
        points), each closed by Newton on the actuated coordinates (least squares on ``J_v T``, at most
        :data:`IK_JOINT_STEP` per iteration, the loops closed from the last pose), so every answer stays on the
        branch of the start. The working mode is the sign of ``det(B^T J_v T)`` (``B`` the directions the handle
        moves at the start, when there are as many as actuated coordinates); a change of that sign between two
        steps, like a change of the loops' assembly branch, means the way crossed a singularity. A point the
        handle cannot reach, or one behind a singularity, raises a one-line UserError naming the point.
        """
        targets = np.asarray(positions, dtype=float)
        if targets.ndim != 2 or targets.shape[1] != 3 or not np.all(np.isfinite(targets)):
            raise UserError(f"a handle position is 3 finite numbers, got {np.ravel(positions).tolist()[:6]}")
        q = self.full(self.home) if start is None else np.array(start, dtype=float)
        q_a = q[self.actuated_index()]
        p, jac = self.position_and_jacobian(q, frame)
        walk = _Walk(self, frame, _moving_directions(jac), q_a, q, p)
        out_a = np.empty((len(targets), self.n_actuated))
        out = np.empty((len(targets), len(q)))
        for i, target in enumerate(targets):
            walk.go_to(target)
            out_a[i], out[i] = walk.q_a, walk.q
        return out_a, out

    def actuated_index(self) -> np.ndarray:
        """The places of the actuated coordinates among the full ones."""
        return np.arange(self.n_actuated)


def _moving_directions(jac: np.ndarray) -> np.ndarray | None:
    """Orthonormal directions (3 x n_a) the handle moves in at a pose, when ``J_v T`` has full column rank
    n_a <= 3 (the working mode's frame); None for a redundant device."""
    if jac.shape[1] > 3:
        return None
    u, s, _ = np.linalg.svd(jac)
    if s[-1] <= IK_SINGULAR * s[0]:
        return None
    return u[:, :jac.shape[1]]


def _text(v) -> str:
    return ", ".join(f"{x:.6g}" for x in v)


class _Walk:
    """The continuation state of :meth:`Configuration.reach`: the pose, the handle position and the working mode."""

    def __init__(self, space: Configuration, frame: str | None, basis: np.ndarray | None, q_a: np.ndarray,
                 q: np.ndarray, p: np.ndarray):
        self.space, self.frame, self.basis = space, frame, basis
        self.q_a, self.q, self.p = q_a, q, p
        self.mode = self._mode(space.position_and_jacobian(q, frame)[1])
        scale = max(float(np.abs(space.mechanism.compiled.node_offset).max(initial=0.0)), 1e-3)
        self.tol = 1e-12 * max(scale, float(np.linalg.norm(p)))

    def _mode(self, jac: np.ndarray) -> float:
        if self.basis is None:
            return 0.0
        return float(np.sign(np.linalg.det(self.basis.T @ jac)))

    def go_to(self, target: np.ndarray) -> None:
        begin = self.p.copy()
        n_steps = max(1, int(np.ceil(np.linalg.norm(target - begin) / IK_STEP)))
        for k in range(1, n_steps + 1):
            self._newton(begin + (target - begin) * (k / n_steps), target,
                         self.tol if k == n_steps else IK_WAY * IK_STEP)

    def _newton(self, goal: np.ndarray, target: np.ndarray, tol: float) -> None:
        space, q_a, q = self.space, self.q_a, self.q
        for _ in range(IK_ITER):
            p, jac = space.position_and_jacobian(q, self.frame)
            error = goal - p
            s = np.linalg.svd(jac, compute_uv=False)
            if s[-1] <= IK_SINGULAR * s[0] or (self.mode and self._mode(jac) != self.mode):
                raise UserError(f"the handle cannot reach ({_text(target)}) m: it is out of reach or behind a singularity (the "
                                f"handle's Jacobian loses rank near ({_text(p)}) m on the way)")
            if np.linalg.norm(error) <= tol:
                self.q_a, self.q, self.p = q_a, q, p
                return
            dq = np.linalg.lstsq(jac, error, rcond=None)[0]
            dq *= min(1.0, IK_JOINT_STEP / max(float(np.abs(dq).max()), 1e-300))
            try:
                q = space.full(q_a + dq, start=q)
            except UserError:
                raise UserError(f"the handle cannot reach ({_text(target)}) m: it is out of reach (the loops cannot "
                                f"close on the way, near ({_text(p)}) m)") from None
            q_a = q_a + dq
        raise UserError(f"the handle cannot reach ({_text(target)}) m: it is out of reach (the last point reached "
                        f"on the way is ({_text(p)}) m)")


@dataclass(frozen=True)
class HandlePose:
    """The inverse kinematics of one handle position: actuated, full and passive coordinates and the position
    reached (m)."""

    q: np.ndarray
    full: np.ndarray
    passive: np.ndarray
    position: np.ndarray


def handle_pose(device: Device, position, frame: str | None = None, start=None) -> HandlePose:
    """The actuated coordinates that put ``frame``'s origin (default: the handle) at ``position`` (m), continued
    from ``start`` (actuated coordinates on the branch of home; default: home) by :meth:`Configuration.reach`;
    a one-line :class:`UserError` when the point is out of reach, behind a singularity or outside the joint
    limits."""
    space = configuration_of(device)
    begin = None if start is None else space.full(np.asarray(start, dtype=float))
    q_a, q = space.reach(np.reshape(np.asarray(position, dtype=float), (1, -1)), frame, begin)
    check_limits(device, q_a, np.reshape(position, (1, 3)))
    passive = q[0][list(device.mechanism.loops.passive)] if not space.is_tree else np.zeros(0)
    return HandlePose(q_a[0], q[0], passive, space.position_and_jacobian(q[0], frame)[0])


def check_limits(device: Device, q_a: np.ndarray, positions: np.ndarray) -> None:
    """A one-line UserError when a pose ``q_a[i]`` (reached for ``positions[i]``) leaves a joint's limits."""
    names = device.mechanism.actuated_coordinates
    for k, (name, span) in enumerate(zip(names, device.joint_limits())):
        if span is None:
            continue
        outside = np.flatnonzero((q_a[:, k] < span[0]) | (q_a[:, k] > span[1]))
        if outside.size:
            i = int(outside[0])
            raise UserError(f"the position ({_text(positions[i])}) m needs {name} = {q_a[i, k]:.6g}, outside its "
                            f"limits [{span[0]:.6g}, {span[1]:.6g}]")


class LoopConfiguration(Configuration):
    """The configuration space of a closed-loop device: its :class:`~.loops.solver.LoopSolver` closes the poses."""

    is_tree = False

    def __init__(self, mechanism: Mechanism):
        self.solver = LoopSolver(mechanism)
        super().__init__(mechanism)

    def _home(self) -> np.ndarray:
        return np.array(self.mechanism.loops.home, dtype=float)

    def actuated_index(self) -> np.ndarray:
        return self.solver.closures.actuated

    def full(self, q_a, start: np.ndarray | None = None) -> np.ndarray:
        return self.solver.solve(self._actuated(q_a), start)

    def velocity_transform(self, q: np.ndarray) -> np.ndarray:
        return self.solver.velocity_transform(q)


def configuration(mechanism: Mechanism) -> Configuration:
    """The configuration space of a mechanism (not cached: prefer :func:`configuration_of` for a device)."""
    return Configuration(mechanism) if mechanism.loops is None else LoopConfiguration(mechanism)


def configuration_of(device: Device) -> Configuration:
    """The configuration space of the device's geometry (cached per builder and kinematic parameters)."""
    return configuration_for(device.builder, device.kinematic_values())


@lru_cache(maxsize=16)
def configuration_for(builder: MechanismBuilder, kinematic: tuple[tuple[str, float], ...]) -> Configuration:
    return configuration(build_mechanism(builder, kinematic))
