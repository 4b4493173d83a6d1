"""The configuration space of a device geometry: the one door to closed poses (issue 21).

Every analysis that needs "the device at actuated coordinates ``q_a``" asks :func:`configuration_of`
(cached per geometry, like :func:`~hapticdesign.analysis.dynamics.device.dynamics_of`):

- ``names``, ``home``: the actuated coordinates and the home pose (zeros for a tree, the file's ``home``
  for a closed-loop device, whose loops need not close at 0); ``full_home``, every coordinate there;
- :meth:`Configuration.full`: every tree coordinate at actuated ones, the passive joints continued from home on
  the assembly branch by the device's :class:`~.loops.solver.LoopSolver`; :meth:`Configuration.passive`: the
  passive ones of a full pose;
- :meth:`Configuration.velocity_transform`: ``T`` with ``qd = T qd_a`` (``T = [I; S]``,
  ``S = -Phi_p^-1 Phi_a``; the identity for a tree; seed 000 eq. 2.38-2.43 generalized);
- :meth:`Configuration.pose`, :meth:`Configuration.jacobian`: a frame's pose and its Jacobian over the
  actuated coordinates, ``J T`` (seed 000 eq. 2.20-2.26);
- :meth:`Configuration.reach` (and :meth:`Configuration.inverse_kinematics` for one point, :func:`handle_pose`
  with the device's joint limits): the one inverse kinematics of the project, the actuated coordinates that put
  a frame's origin (default: the handle) at positions, continued from home (or a given pose) on its branch in
  small Cartesian steps, point after point, by the compiled kernel the design batch runs over many designs
  (:func:`~.reach_kernel.reach_designs`, here a batch of one).

Every device takes the same calls (Pinocchio's view: a tree's list of constraints is empty, so its solver closes
nothing). The configuration owns the loop solver; a closed-loop device's dynamics model
(:class:`~.dynamics.closed_loop.ClosedLoopModel`) takes it, so one solver serves every caller.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from hapticdesign.analysis import kinematics
from hapticdesign.analysis.loops.records import BRANCH_CHANGE, OK, OUT_OF_REACH, SINGULAR, Settings
from hapticdesign.analysis.loops.solver import LoopSolver
from hapticdesign.analysis.reach_kernel import MESSAGES, Reach, Reached, Structure, reach_designs, structure_of
from hapticdesign.errors import RenamedWarning, UserError
from hapticdesign.model.device import Device, MechanismBuilder, build_mechanism
from hapticdesign.model.mechanism import Mechanism
from hapticdesign.model.walk import WalkPlan

IK_STEP = 0.01
"""m: largest Cartesian step of :meth:`Configuration.reach` along a straight segment."""
IK_ITER = 60
"""Newton iterations per Cartesian step."""
IK_JOINT_STEP = 0.2
"""rad or m: largest change of a coordinate in one Newton iteration."""
IK_SINGULAR = 1e-7
"""Smallest over largest singular value of the position Jacobian below which a start pose is singular."""
IK_PIVOTS = 1e-9
"""Pivot ratio of the inverse kinematics' system ``[Phi; U^T J_v]`` below which a pose counts as singular."""


class Configuration:
    """The configuration space of a device's geometry; see the module docstring."""

    def __init__(self, mechanism: Mechanism):
        self.mechanism = mechanism
        self.solver = LoopSolver(mechanism)
        """The loop solver (:class:`~.loops.solver.LoopSolver`), which closes the poses."""
        self.names: tuple[str, ...] = mechanism.actuated_coordinates
        self.n_actuated = len(self.names)
        self.full_home = self.solver.home
        """Every coordinate of the home pose (the loops closed on their assembly branch)."""
        self.home = self.full_home[self.actuated_index()]
        """Actuated coordinates of the home pose."""
        self.settings = self.solver.settings
        """The loop solver's settings (:func:`~.loops.solver.settings_of`), whose tolerance the reach closes to."""
        self._walks: dict[str | None, tuple[Structure, WalkPlan]] = {}

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
        return self.solver.solve(self._actuated(q_a), start)

    def passive(self, q: np.ndarray) -> np.ndarray:
        """The passive coordinates (..., n_p) of full poses ``q`` (..., N) (none for a tree)."""
        return np.asarray(q)[..., self.solver.closures.passive]

    def velocity_transform(self, q: np.ndarray) -> np.ndarray:
        """``T`` (N x n_a) with ``qd = T qd_a`` at closed full coordinates ``q`` (N,) or (P, N)."""
        return self.solver.velocity_transform(q)

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

    def walk(self, frame: str | None = None) -> tuple[Structure, WalkPlan]:
        """The records :func:`~.reach_kernel.reach_designs` takes for ``frame`` as the handle (built once per frame):
        the device's :class:`~.reach_kernel.Structure` and the walk of its tree, the closures' and the handle's
        nodes first."""
        if frame not in self._walks:
            structure = structure_of(self.mechanism, frame)
            closures = structure.closures
            plan = structure.raw.plan([*closures.frame_a, *closures.frame_b, structure.handle], list(closures.passive))
            self._walks[frame] = (structure, plan)
        return self._walks[frame]

    def reach(self, positions, frame: str | None = None,
              start: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Actuated (P, n_a) and full (P, N) coordinates that put the origin of ``frame`` (default: the handle)
        at each of ``positions`` (P, 3) in turn: the one inverse kinematics of the project.

        Continuation from ``start`` (a closed full pose; default: home, on the loops' assembly branch) to the
        first point, then from each point to the next, along straight Cartesian segments in steps of at most
        :data:`IK_STEP`, each closed by Newton on all coordinates (the closures and the handle's position on the
        directions ``U`` it moves at the start, at most :data:`IK_JOINT_STEP` per iteration), so every answer
        stays on the branch of the start: the compiled :func:`~.reach_kernel.reach_designs`, the design batch's
        own, for this one device. The working mode is the sign of ``det(U^T J_v T)`` (with the loops' assembly
        branch, the sign of the system's determinant); a change of that sign, or of the assembly branch, means
        the way crossed a singularity. A point the handle cannot reach, or one behind a singularity, raises a
        one-line UserError naming the point.
        """
        targets = np.asarray(positions, dtype=float)
        if targets.ndim != 2 or targets.shape[1] != 3 or not np.all(np.isfinite(targets)):
            raise UserError(f"a handle position is 3 finite numbers, got {np.ravel(positions).tolist()[:6]}")
        q = self.full(self.home) if start is None else np.array(start, dtype=float)
        jac = self.position_and_jacobian(q, frame)[1]
        structure, plan = self.walk(frame)
        n = len(q)
        out = Reached(np.zeros((1, len(targets), n)), np.zeros((1, len(targets), 3, self.n_actuated)),
                      np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64), np.zeros((1, 3)))
        reach_designs(structure.offset[None], np.ascontiguousarray(targets), structure.shape, plan,
                      structure.closures, self.settings, reach_settings(structure.handle, jac, q, self.settings), out)
        code = int(out.status[0])
        if code != OK:
            raise UserError(reach_failure(code, targets[max(int(out.point[0]), 0)], out.near[0]))
        full = out.full[0]
        return full[:, self.actuated_index()], full

    def actuated_index(self) -> np.ndarray:
        """The places of the actuated coordinates among the full ones."""
        return self.solver.closures.actuated


def reach_settings(handle: int, jac: np.ndarray, start: np.ndarray, settings: Settings) -> Reach:
    """The :class:`~.reach_kernel.Reach` record of a walk from ``start`` (full coordinates) whose handle is node
    ``handle`` with ``J_v T`` = ``jac`` (3 x n_a) there: the directions ``U`` the handle moves (the left singular
    vectors of ``jac``; all three for a redundant device), closed to the loop solver's tolerance."""
    n_a = jac.shape[1]
    basis = np.linalg.svd(jac)[0][:, :n_a] if n_a <= 3 else np.eye(3)
    return Reach(IK_STEP, settings.tol, IK_ITER, IK_JOINT_STEP, IK_PIVOTS, int(handle), np.ascontiguousarray(basis),
                 np.ascontiguousarray(start, dtype=float))


def reach_failure(code: int, target: np.ndarray, near: np.ndarray) -> str:
    """One line on why the handle does not reach ``target``, from the reach kernel's status and the handle's
    position ``near`` where the walk stopped."""
    head = f"the handle cannot reach ({_text(target)}) m: {MESSAGES[code]}"
    if code == SINGULAR:
        return f"{head} (the handle's Jacobian loses rank near ({_text(near)}) m on the way)"
    if code == OUT_OF_REACH:
        return f"{head} (the last point reached on the way is ({_text(near)}) m)"
    return f"{head} (near ({_text(near)}) m)" if code == BRANCH_CHANGE else head


def _text(v) -> str:
    return ", ".join(f"{x:.6g}" for x in v)


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
    return HandlePose(q_a[0], q[0], space.passive(q[0]), space.position_and_jacobian(q[0], frame)[0])


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


def configuration(mechanism: Mechanism) -> Configuration:
    """The configuration space of a mechanism (not cached: prefer :func:`configuration_of` for a device)."""
    return Configuration(mechanism)


def __getattr__(name: str):
    """``LoopConfiguration``, the former name of a closed-loop device's :class:`Configuration`, for one release."""
    if name == "LoopConfiguration":
        warnings.warn("LoopConfiguration is now Configuration (one configuration for every device)", RenamedWarning,
                      stacklevel=2)
        return Configuration
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def configuration_of(device: Device) -> Configuration:
    """The configuration space of the device's geometry (cached per builder and kinematic parameters)."""
    return configuration_for(device.builder, device.kinematic_values())


@lru_cache(maxsize=16)
def configuration_for(builder: MechanismBuilder, kinematic: tuple[tuple[str, float], ...]) -> Configuration:
    return configuration(build_mechanism(builder, kinematic))
