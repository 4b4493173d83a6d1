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
- :meth:`Configuration.inverse_kinematics`: the actuated coordinates that put a frame's origin (default:
  the handle) at a position, continued from home on the home branch in small Cartesian steps.

A closed-loop device's configuration (:class:`LoopConfiguration`) owns the loop solver; its dynamics model
(:class:`~.dynamics.closed_loop.ClosedLoopModel`) takes it, so one solver serves every caller.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from hapticdesign.analysis import kinematics
from hapticdesign.analysis.loops.solver import LoopSolver
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device, MechanismBuilder, build_mechanism
from hapticdesign.model.mechanism import Mechanism

IK_STEP = 0.005
"""m: largest Cartesian step of :meth:`Configuration.inverse_kinematics` along the straight line from home."""
IK_ITER = 30
"""Newton iterations per Cartesian step."""
IK_SINGULAR = 1e-9
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

    def inverse_kinematics(self, position, frame: str | None = None) -> np.ndarray:
        """Actuated coordinates that put the origin of ``frame`` (default: the handle) at ``position`` (3,).

        From home along the straight line to ``position`` in Cartesian steps of at most :data:`IK_STEP`,
        each closed by Newton on the actuated coordinates (least squares on ``J_v T``) from the last, so
        the answer stays on the home branch. A target the device cannot reach (Newton leaves a residual) or
        one behind a singular pose on the way raises a one-line UserError.
        """
        target = np.asarray(position, dtype=float)
        if target.shape != (3,) or not np.all(np.isfinite(target)):
            raise UserError(f"a handle position is 3 finite numbers, got {np.ravel(position).tolist()[:6]}")
        q_a = self.home.copy()
        q = self.full(q_a)
        start = kinematics.forward_kinematics(self.mechanism, q, frame)[:3, 3]
        scale = max(float(np.linalg.norm(start)), float(np.linalg.norm(target)), 1e-3)
        tol = 1e-12 * scale
        n_steps = max(1, int(np.ceil(np.linalg.norm(target - start) / IK_STEP)))
        for k in range(1, n_steps + 1):
            goal = start + (target - start) * (k / n_steps)
            reached = self._newton(q_a, q, goal, frame, tol)
            if reached is None:
                where = ", ".join(f"{v:.6g}" for v in goal)
                raise UserError(f"the handle cannot reach ({where}) m from home on the home branch "
                                "(out of reach, or behind a singular pose)")
            q_a, q = reached
        return q_a

    def _newton(self, q_a: np.ndarray, q: np.ndarray, goal: np.ndarray, frame: str | None,
                tol: float) -> tuple[np.ndarray, np.ndarray] | None:
        """Newton on the actuated coordinates ``q_a`` (full ``q``) to put the frame origin at ``goal``: the new
        ``(q_a, q)``, each pose continued from the last; None when it does not converge or meets a singular pose."""
        for _ in range(IK_ITER):
            error = goal - kinematics.forward_kinematics(self.mechanism, q, frame)[:3, 3]
            if np.linalg.norm(error) <= tol:
                return q_a, q
            try:
                jac = kinematics.jacobian(self.mechanism, q, frame)[:3] @ self.velocity_transform(q)
                sv = np.linalg.svd(jac, compute_uv=False)
                if sv[-1] <= IK_SINGULAR * sv[0]:
                    return None
                q_a = q_a + np.linalg.lstsq(jac, error, rcond=None)[0]
                q = self.full(q_a, start=q)
            except UserError:
                return None
        return None


class LoopConfiguration(Configuration):
    """The configuration space of a closed-loop device: its :class:`~.loops.solver.LoopSolver` closes the poses."""

    is_tree = False

    def __init__(self, mechanism: Mechanism):
        self.solver = LoopSolver(mechanism)
        super().__init__(mechanism)

    def _home(self) -> np.ndarray:
        return np.array(self.mechanism.loops.home, dtype=float)

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
