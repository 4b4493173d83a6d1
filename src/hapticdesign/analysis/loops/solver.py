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
reported as one-line UserErrors naming the pose (or, with ``strict=False``, as a status array). A tree is a
mechanism whose loops are empty (no closures, no passive coordinates): its poses are closed as they are.
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.loops import closure_kernel as ck
from hapticdesign.analysis.loops.records import Closures, Settings
from hapticdesign.errors import UserError
from hapticdesign.model.loops import POSE_LIMIT
from hapticdesign.model.mechanism import FOLDED, Mechanism
from hapticdesign.model.walk import node_poses

MAX_STEP = 0.1
"""Largest continuation step in the actuated coordinates (rad or m) before Newton."""
MAX_ITER = 30
SINGULAR_RATIO = 1e-9
"""Pivot ratio ``min |u_ii| / max |u_ii|`` of ``Phi_p`` below which the constraint Jacobian is singular."""
MIN_FRACTION = 1e-7
"""Smallest step, as a fraction of a segment, before continuation gives up."""
ACCURACY = 1e-7
"""Largest estimated relative error of ``T`` (so of H and G; C's is a few times larger) at a closed pose:
beyond it the pose is refused as too close to a singular configuration (results stay within about 1e-6)."""
ROUNDING = 2.2e-16
"""Machine epsilon: the closure residual cannot fall below about this times the device's size."""

MESSAGES = {
    ck.NO_CLOSURE: "the loops cannot close (outside the workspace the assembly branch reaches)",
    ck.SINGULAR: "the constraint Jacobian of the loops is singular there (a singular configuration)",
    ck.BRANCH_CHANGE: "the motion leaves the assembly branch (det of the constraint Jacobian changes sign)",
    ck.ILL_CONDITIONED: "too close to a singular configuration for results within 1e-6 (the constraint Jacobian "
                        "is nearly singular)",
}


def settings_of(mechanism: Mechanism) -> Settings:
    """The solver's :class:`~.records.Settings` for a mechanism: the closure tolerance is 1e-12 of its largest
    length (at least 1 mm)."""
    compiled = mechanism.compiled
    lengths = np.abs(compiled.node_offset[compiled.node_axis >= 3])
    tol = 1e-12 * max(float(lengths.max(initial=0.0)), 1e-3)
    return Settings(MAX_STEP, tol, MAX_ITER, SINGULAR_RATIO, MIN_FRACTION, ACCURACY, ROUNDING * tol / 1e-12)


class LoopSolver:
    """Passive coordinates of a mechanism (see the module docstring; a tree's: none).

    ``tree``, ``plan``, ``closures`` and ``settings`` are the records the compiled kernels take
    (:mod:`.records`), on the folded node numbering (:data:`~hapticdesign.model.mechanism.FOLDED`).
    """

    def __init__(self, mechanism: Mechanism):
        self.mechanism = mechanism
        self.compiled = mechanism.compiled
        self.tree = self.compiled.tree.arrays
        """The folded tree's record (:class:`~hapticdesign.model.walk.Tree`)."""
        self.closures = Closures.of(mechanism, FOLDED)
        self.plan = self.compiled.tree.plan([*self.closures.frame_a, *self.closures.frame_b],
                                            list(self.closures.passive))
        """Walk of the tree, the closures' nodes first (:class:`~hapticdesign.model.walk.WalkPlan`)."""
        self.n_dof = mechanism.n_dof
        self.n_actuated = mechanism.n_actuated
        self.settings = settings_of(mechanism)
        self.tol = self.settings.tol
        self.empty = mechanism.loops.empty
        """No closures (a tree): nothing to solve."""
        loops = mechanism.loops
        q = loops.guess(self.n_dof)
        status, sign, _ = (ck.OK, 1.0, 1.0) if self.empty else ck.newton(q, self.tree, self.plan, self.closures,
                                                                          self.settings)
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
        """Sign of ``det Phi_p`` on the assembly branch (1 without closures)."""

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
        if self.empty:
            q = np.asarray(q_a, dtype=float)
            return q if strict else (q, np.zeros(q.shape[:-1], dtype=np.int64))
        q_a = self._actuated(q_a)
        path = np.ascontiguousarray(np.atleast_2d(q_a))
        begin = np.asarray(self.home if start is None else start, dtype=float)
        out, status, first = ck.solve_path(path, begin, self.branch, self.tree, self.plan, self.closures, self.settings)
        if not strict:
            return (out[0] if q_a.ndim == 1 else out), (status[0] if q_a.ndim == 1 else status)
        while first >= 0:
            reached = self.detour(path[first], out[first - 1] if first > 0 else begin)
            if reached is None:
                raise UserError(self.explain(path[first], int(status[first])))
            out[first] = reached
            if first + 1 == len(path):
                break
            rest, status_rest, again = ck.solve_path(path[first + 1:], reached, self.branch, self.tree, self.plan,
                                                     self.closures, self.settings)
            out[first + 1:] = rest
            status[first + 1:] = status_rest
            first = -1 if again < 0 else first + 1 + again
        return out[0] if q_a.ndim == 1 else out

    def detour(self, target: np.ndarray, start: np.ndarray) -> np.ndarray | None:
        """The closed pose at actuated ``target`` reached from the closed ``start`` another way than the straight
        segment, or None: joint by joint (each actuated coordinate in turn, in both orders), continued as any
        motion (on the assembly branch, within the accuracy). Newton straight from ``start`` is not a way: it
        may land on another assembly mode with the same sign of ``det Phi_p``."""
        start = np.asarray(start, dtype=float)
        begin = start[self.closures.actuated]
        for order in (range(self.n_actuated), reversed(range(self.n_actuated))):
            waypoints, point = [], begin.copy()
            for j in order:
                point = point.copy()
                point[j] = target[j]
                waypoints.append(point)
            out, _, first = ck.solve_path(np.array(waypoints), start, self.branch, self.tree, self.plan, self.closures,
                                          self.settings)
            if first < 0:
                return out[-1]
        return None

    def explain(self, target: np.ndarray, status: int) -> str:
        """One line on why ``target`` (actuated) cannot be returned: the pose itself (no closure on the branch, a
        singular or nearly singular constraint Jacobian, with its distance from the singularity), or only the
        paths to it."""
        pose = ", ".join(f"{v:.6g}" for v in target)
        q = self.home.copy()
        q[self.closures.actuated] = target
        loose = self.settings._replace(accuracy=np.inf, tol=10 * self.settings.floor, max_iter=60)
        code, sign, _ = ck.newton(q, self.tree, self.plan, self.closures, loose)
        if code != ck.OK:
            return f"at q = ({pose}): {MESSAGES[status if status != ck.ILL_CONDITIONED else code]}"
        if sign != self.branch:
            return (f"at q = ({pose}): the loops close there only on another assembly branch (det of the constraint "
                    "Jacobian of the other sign than at home)")
        sigma = self._singular_values(q)
        bound = self.settings.floor * sigma[0] / sigma[-1] ** 2
        if bound > self.settings.accuracy:
            return (f"at q = ({pose}): too close to a singular configuration for results within 1e-6: the constraint "
                    f"Jacobian's singular values are {sigma[-1]:.3g} and {sigma[0]:.3g} (estimated relative error "
                    f"{bound:.1g}), about {self._distance(q, loose, sigma[-1]):.2g} (rad or m, actuated coordinates) from a singular pose")
        return (f"at q = ({pose}): the pose closes on the assembly branch, but the paths tried from home (straight, "
                "joint by joint) cross a singular configuration or leave the workspace; move there in steps that "
                "avoid them")

    def _singular_values(self, q: np.ndarray) -> np.ndarray:
        """Singular values of ``Phi_p`` at the full pose ``q``, largest first."""
        return np.linalg.svd(self.constraint_jacobian(q)[:, self.closures.passive], compute_uv=False)

    def _distance(self, q: np.ndarray, settings, sigma: float) -> float:
        """Distance (actuated infinity norm, rad or m) to where ``Phi_p`` is singular, from its smallest singular
        value over that value's gradient (finite differences of 1e-7 between poses closed to rounding): the singular
        value falls linearly there."""
        grad = np.zeros(self.n_actuated)
        for j in range(self.n_actuated):
            shifted = q.copy()
            shifted[self.closures.actuated[j]] += 1e-7
            code, _, _ = ck.newton(shifted, self.tree, self.plan, self.closures, settings)
            if code != ck.OK:
                return 0.0
            grad[j] = (self._singular_values(shifted)[-1] - sigma) / 1e-7
        return sigma / max(float(np.abs(grad).sum()), 1e-300)

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
        if self.empty:
            return np.broadcast_to(np.eye(self.n_dof), q.shape[:-1] + (self.n_dof, self.n_dof)).copy()
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
