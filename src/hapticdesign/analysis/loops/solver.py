"""The loop solver: passive joint values and velocities from the actuated ones, on one assembly branch.

This is the single place where closed loops are solved; dynamics (:mod:`hapticdesign.analysis.dynamics.closed_loop`),
the Linearity Number and the metrics consume it. For a mechanism with
:class:`~hapticdesign.model.loops.ClosedLoops`:

- **home**: Newton from the file's ``assembly`` guess at the ``home`` actuated values. Failure is a
  one-line :class:`~hapticdesign.errors.UserError` (the loops cannot close there, or close only at a
  singular constraint Jacobian). The sign of ``det Phi_p`` at home names the assembly branch.
- **any actuated poses** ``q_a`` (P, n_a) are a *motion*: the first is reached from home along the
  straight segment in actuated space, each next one from the previous (continuation with a tangent
  predictor, :func:`.closure_kernel.solve_path`). A single pose is therefore always solved along the
  segment from home, independently of earlier calls.
- **velocities**: ``qd_p = S qd_a`` with ``S = -Phi_p^-1 Phi_a``, i.e. ``qd = T qd_a``, ``T = [I; S]``
  (the closed-loop counterpart of the constant coupling coefficients of seed 000 eq. 2.38-2.43).

Poses where the loops cannot close, a singular constraint Jacobian and a change of branch are
reported as one-line UserErrors naming the pose (or, with ``strict=False``, as a status array).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hapticdesign.analysis.loops import closure_kernel as ck
from hapticdesign.errors import UserError
from hapticdesign.model.loops import POSE_LIMIT, ClosedLoops
from hapticdesign.model.mechanism import Mechanism
from hapticdesign.model.walk import CONSTANT, KinematicTree, node_poses

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


@dataclass(frozen=True)
class LoopArrays:
    """Flat arrays of the closures: frame nodes per loop, (loop, component) per constraint row (loop after loop)."""

    frame_a: np.ndarray
    frame_b: np.ndarray
    row_loop: np.ndarray
    row_comp: np.ndarray
    actuated: np.ndarray
    passive: np.ndarray

    @classmethod
    def from_mechanism(cls, mech: Mechanism) -> "LoopArrays":
        loops: ClosedLoops = mech.loops
        nodes = mech.compiled.tree.frame_node
        rows = [(i, c) for i, closure in enumerate(loops.closures) for c in closure.components]
        return cls(
            frame_a=np.array([nodes[c.frames[0]] for c in loops.closures], dtype=np.int64),
            frame_b=np.array([nodes[c.frames[1]] for c in loops.closures], dtype=np.int64),
            row_loop=np.array([r[0] for r in rows], dtype=np.int64),
            row_comp=np.array([r[1] for r in rows], dtype=np.int64),
            actuated=np.array(loops.actuated(mech.n_dof), dtype=np.int64),
            passive=np.array(loops.passive, dtype=np.int64),
        )


@dataclass(frozen=True)
class MotionPlan:
    """The nodes whose motions (:func:`.closure_kernel.node_motion`) a set of nodes needs, in tree order.

    Those nodes and, among their ancestors, the variable ones: the others (constants, fixed
    translations) only carry a motion along a rigid offset, which the next kept node takes from its
    kept ancestor ``parent[i]`` (``-1``: the base) over the origin difference. ``moves[i]`` is False when
    node ``order[i]`` has its kept ancestor's origin (only rotations between them), so that its origin
    acceleration is the ancestor's.
    """

    order: np.ndarray
    parent: np.ndarray
    moves: np.ndarray

    @classmethod
    def of(cls, tree: KinematicTree, needed: list[int]) -> MotionPlan:
        """The plan of the nodes ``needed`` (``-1``, the base, needs none) on the folded tree ``tree``."""
        variable = np.any(tree.coef != 0.0, axis=1)
        path: set[int] = set()
        for node in needed:
            while node >= 0 and node not in path:
                path.add(node)
                node = int(tree.parent[node])
        order = sorted(n for n in path if variable[n] or n in needed)
        kept = set(order)
        parents, moves = [], []
        for n in order:
            e, moved = n, False
            while e >= 0 and (e == n or e not in kept):
                shift = tree.axis[e] >= 3 if tree.axis[e] != CONSTANT else bool(np.any(tree.const_pos[e] != 0.0))
                moved = moved or bool(shift)
                e = int(tree.parent[e])
            parents.append(e)
            moves.append(moved)
        return cls(order=np.array(order, dtype=np.int64), parent=np.array(parents, dtype=np.int64),
                   moves=np.array(moves, dtype=np.bool_))

    @property
    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(order, parent, moves)``, the ``motion`` of the kernels."""
        return self.order, self.parent, self.moves


class LoopSolver:
    """Passive coordinates of a closed-loop mechanism (see the module docstring)."""

    def __init__(self, mechanism: Mechanism):
        if mechanism.loops is None:
            raise UserError("the mechanism has no closed loops to solve")
        self.mechanism = mechanism
        self.compiled = mechanism.compiled
        self.arrays = LoopArrays.from_mechanism(mechanism)
        self.plan = self.compiled.tree.plan([*self.arrays.frame_a, *self.arrays.frame_b], list(self.arrays.passive))
        """Walk of the tree, the closures' nodes first (:class:`~hapticdesign.model.walk.WalkPlan`)."""
        self.n_dof = mechanism.n_dof
        self.n_actuated = mechanism.n_actuated
        lengths = np.abs(self.compiled.node_offset[self.compiled.node_axis >= 3])
        self.tol = 1e-12 * max(float(lengths.max(initial=0.0)), 1e-3)
        self.settings = (MAX_STEP, self.tol, MAX_ITER, SINGULAR_RATIO, MIN_FRACTION)
        """``(max_step, tol, max_iter, singular_ratio, min_fraction)``: the continuation's settings (kernel order)."""
        loops = mechanism.loops
        q = np.zeros(self.n_dof)
        q[self.arrays.actuated] = loops.home
        q[self.arrays.passive] = loops.assembly
        status, sign, _ = self._newton(q)
        names = ", ".join(f"{mechanism.coordinates[k]} = {q[k]:.4g}" for k in self.arrays.passive)
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

    # -- kernels ------------------------------------------------------------------------------
    def _kinematic_args(self) -> tuple:
        t, a = self.compiled.tree, self.arrays
        return (t.parent, t.axis, t.offset, t.const_rot, t.const_pos, self.plan.arrays, a.frame_a, a.frame_b,
                a.row_loop, a.row_comp)

    def _newton(self, q: np.ndarray) -> tuple[int, float, float]:
        a = self.arrays
        return ck.newton(q, a.actuated, a.passive, *self._kinematic_args(), self.tol, MAX_ITER, SINGULAR_RATIO,
                         *self.compiled.tree.workspace(), self.plan.workspace())

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
        a = self.arrays
        out, status, first = ck.solve_path(
            path, np.asarray(self.home if start is None else start, dtype=float), self.branch, a.actuated, a.passive,
            *self._kinematic_args(), *self.settings,
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
        out = np.empty(len(self.arrays.row_loop))
        a = self.arrays
        ck.closure_residual(a.frame_a, a.frame_b, a.row_loop, a.row_comp, rot, pos, out)
        return out

    def _poses(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        tree = self.compiled.tree
        rot, pos = tree.workspace()
        node_poses(np.asarray(q, dtype=float), *tree.arrays, len(tree.parent) - 1, rot, pos)
        return rot, pos

    # -- velocities ---------------------------------------------------------------------------
    def constraint_jacobian(self, q: np.ndarray) -> np.ndarray:
        """``Phi`` (m x N) at full coordinates ``q``."""
        rot, pos = self._poses(q)
        c, a = self.compiled, self.arrays
        phi = np.empty((len(a.row_loop), self.n_dof))
        ck.closure_jacobian(a.frame_a, a.frame_b, a.row_loop, a.row_comp, c.tree.parent, c.tree.axis, self.plan.arrays,
                            rot, pos, phi)
        return phi

    def velocity_transform(self, q: np.ndarray) -> np.ndarray:
        """``T`` (N x n_a) with ``qd = T qd_a`` at closed full coordinates ``q`` (N,) or (P, N)."""
        q = np.asarray(q, dtype=float)
        flat = np.atleast_2d(q)
        out = np.zeros((len(flat), self.n_dof, self.n_actuated))
        a = self.arrays
        for p, qp in enumerate(flat):
            s, ratio, _ = ck.velocity_map(self.constraint_jacobian(qp), a.actuated, a.passive)
            if ratio <= SINGULAR_RATIO:
                raise UserError(f"at q = ({', '.join(f'{v:.6g}' for v in qp)}): {MESSAGES[ck.SINGULAR]}")
            out[p, a.actuated, np.arange(self.n_actuated)] = 1.0
            out[p, a.passive] = s
        return out[0] if q.ndim == 1 else out

