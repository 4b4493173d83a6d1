"""The loop solver: passive joint values and velocities from the actuated ones, on one assembly branch.

This is the single place where closed loops are solved; dynamics (:mod:`hapticdesign.analysis.dynamics.closed_loop`),
the Linearity Number and the metrics consume it. For a mechanism with
:class:`~hapticdesign.model.loops.ClosedLoops`:

- **home**: Newton from the file's ``assembly`` guess at the ``home`` actuated values. Failure is a
  one-line :class:`~hapticdesign.errors.UserError` (the loops cannot close there, or close only at a
  singular constraint Jacobian). The sign of ``det Phi_p`` at home names the assembly branch.
- **any actuated poses** ``q_a`` (P, n_a) are a *motion*: the first is reached from home along the
  straight segment in actuated space, each next one from the previous (continuation with a tangent
  predictor, :func:`.closure_kernel.solve_path`, whose steps are :func:`.closure_kernel.correct`). A single pose is therefore always solved along the
  segment from home, independently of earlier calls.
- **velocities**: ``qd_p = S qd_a`` with ``S = -Phi_p^-1 Phi_a``, i.e. ``qd = T qd_a``, ``T = [I; S]``
  (the closed-loop counterpart of the constant coupling coefficients of seed 000 eq. 2.38-2.43).

Poses where the loops cannot close, a singular constraint Jacobian and a change of branch are
reported as one-line UserErrors naming the pose (or, with ``strict=False``, as a status array).
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.loops import closure_kernel as ck
from hapticdesign.analysis.loops.records import Closures, Settings
from hapticdesign.errors import UserError
from hapticdesign.model.loops import POSE_LIMIT
from hapticdesign.model.mechanism import Mechanism
from hapticdesign.model.walk import node_poses

MAX_STEP = 0.1
"""Largest continuation step in the actuated coordinates (rad or m) before Newton."""
MAX_ITER = 30
SINGULAR_RATIO = 1e-9
"""Pivot ratio ``min |u_ii| / max |u_ii|`` of ``Phi_p`` below which the constraint Jacobian is singular."""
MIN_FRACTION = 1e-7
"""Smallest step, as a fraction of a segment, before continuation gives up."""

MESSAGES = {
    ck.NO_CLOSURE: "the loops cannot close (outside the workspace the assembly branch reaches)",
    ck.SINGULAR: "the constraint Jacobian of the loops is singular there (a singular configuration)",
    ck.BRANCH_CHANGE: "the motion leaves the assembly branch (det of the constraint Jacobian changes sign)",
}


class LoopSolver:
    """Passive coordinates of a closed-loop mechanism (see the module docstring).

    ``tree``, ``plan``, ``closures`` and ``settings`` are the records the compiled kernels take
    (:mod:`.records`).
    """

    def __init__(self, mechanism: Mechanism):
        if mechanism.loops is None:
            raise UserError("the mechanism has no closed loops to solve")
        self.mechanism = mechanism
        self.compiled = mechanism.compiled
        self.tree = self.compiled.tree.arrays
        """The folded tree's record (:class:`~hapticdesign.model.walk.Tree`)."""
        self.closures = Closures.of(mechanism)
        self.plan = self.compiled.tree.plan([*self.closures.frame_a, *self.closures.frame_b],
                                            list(self.closures.passive))
        """Walk of the tree, the closures' nodes first (:class:`~hapticdesign.model.walk.WalkPlan`)."""
        self.n_dof = mechanism.n_dof
        self.n_actuated = mechanism.n_actuated
        lengths = np.abs(self.compiled.node_offset[self.compiled.node_axis >= 3])
        self.tol = 1e-12 * max(float(lengths.max(initial=0.0)), 1e-3)
        self.settings = Settings(MAX_STEP, self.tol, MAX_ITER, SINGULAR_RATIO, MIN_FRACTION)
        loops = mechanism.loops
        q = np.zeros(self.n_dof)
        q[self.closures.actuated] = loops.home
        q[self.closures.passive] = loops.assembly
        status, sign, _ = ck.newton(q, self.tree, self.plan, self.closures, self.settings)
        names = ", ".join(f"{mechanism.coordinates[k]} = {q[k]:.4g}" for k in self.closures.passive)
        if status == ck.NO_CLOSURE:
            raise UserError(
                "the loops cannot close at the home pose from the assembly guess "
                f"({', '.join(c.describe() for c in loops.closures)}); check the lengths, home and assembly"
            )
        if status == ck.SINGULAR:
            raise UserError(f"the loops close at the home pose only at a singular constraint Jacobian ({names})")
        self.home = q
        """Full coordinates (actuated and passive) of the home pose on the assembly branch."""
        self.branch = sign
        """Sign of ``det Phi_p`` on the assembly branch."""

    def _actuated(self, q_a: np.ndarray) -> np.ndarray:
        q_a = np.asarray(q_a, dtype=float)
        if q_a.shape[-1] != self.n_actuated:
            raise UserError(f"expected {self.n_actuated} actuated joint coordinates, got {q_a.shape[-1]}")
        if not np.all(np.isfinite(q_a)):
            raise UserError("joint coordinates must be finite numbers (got NaN or infinity)")
        if np.any(np.abs(q_a) > POSE_LIMIT):
            raise UserError(f"joint coordinates of a closed loop must lie within +-{POSE_LIMIT:g} (rad or m); the "
                            f"loops are followed from home in steps of {MAX_STEP} rad")
        return q_a

    # -- positions ----------------------------------------------------------------------------
    def solve(self, q_a: np.ndarray, start: np.ndarray | None = None, strict: bool = True):
        """Full coordinates for actuated poses (n_a,) or a motion (P, n_a), continued from ``start``.

        ``start`` is a closed full pose on the branch (default: home). With ``strict`` a failure raises a
        one-line UserError; otherwise returns ``(q, status)`` with status 0 up to the first failure.
        """
        q_a = self._actuated(q_a)
        path = np.ascontiguousarray(np.atleast_2d(q_a))
        out, status, first = ck.solve_path(
            path, np.asarray(self.home if start is None else start, dtype=float), self.branch, self.tree, self.plan,
            self.closures, self.settings,
        )
        if not strict:
            return (out[0] if q_a.ndim == 1 else out), (status[0] if q_a.ndim == 1 else status)
        if first >= 0:
            pose = ", ".join(f"{v:.6g}" for v in path[first])
            raise UserError(f"at q = ({pose}): {MESSAGES[int(status[first])]}")
        return out[0] if q_a.ndim == 1 else out

    def residual(self, q: np.ndarray) -> np.ndarray:
        """Closure residual ``phi`` (m,) at full coordinates ``q`` (N,)."""
        rot, pos = self._poses(q)
        out = np.empty(len(self.closures.row_loop))
        ck.closure_residual(self.closures, rot, pos, out)
        return out

    def _poses(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        tree = self.compiled.tree
        rot, pos = tree.workspace()
        node_poses(np.asarray(q, dtype=float), *self.tree, len(tree.parent) - 1, rot, pos)
        return rot, pos

    # -- velocities ---------------------------------------------------------------------------
    def constraint_jacobian(self, q: np.ndarray) -> np.ndarray:
        """``Phi`` (m x N) at full coordinates ``q``."""
        rot, pos = self._poses(q)
        phi = np.empty((len(self.closures.row_loop), self.n_dof))
        ck.closure_jacobian(self.closures, self.tree, self.plan, rot, pos, phi)
        return phi

    def velocity_transform(self, q: np.ndarray) -> np.ndarray:
        """``T`` (N x n_a) with ``qd = T qd_a`` at closed full coordinates ``q`` (N,) or (P, N)."""
        q = np.asarray(q, dtype=float)
        flat = np.atleast_2d(q)
        out = np.zeros((len(flat), self.n_dof, self.n_actuated))
        a = self.closures
        for p, qp in enumerate(flat):
            s, ratio, _ = ck.velocity_map(self.constraint_jacobian(qp), a.actuated, a.passive)
            if ratio <= SINGULAR_RATIO:
                raise UserError(f"at q = ({', '.join(f'{v:.6g}' for v in qp)}): {MESSAGES[ck.SINGULAR]}")
            out[p, a.actuated, np.arange(self.n_actuated)] = 1.0
            out[p, a.passive] = s
        return out[0] if q.ndim == 1 else out
