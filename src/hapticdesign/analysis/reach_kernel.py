"""The one inverse kinematics, compiled: the continuation of :meth:`~.configuration.Configuration.reach` for one
device or many designs of it (issue 36: one IK behind one door, as Robotics Toolbox puts every IK behind one solver).

A tree is a closed-loop device without loops (no closures, no passive coordinates: Pinocchio's view), so trees and
closed loops take the same kernel. The device's frame tree comes with one node per elementary transform
(:class:`Shape`, the design's node offsets beside it), the closures on that node numbering
(:data:`~hapticdesign.model.mechanism.UNFOLDED`, :meth:`~hapticdesign.model.mechanism.CompiledMechanism.nodes` says
which walk takes which numbering; :class:`Closures`) and
the loop solver's :func:`~.loops.solver.settings_of`; the statuses are those every loop kernel returns
(:mod:`.loops.records`).

:func:`reach_designs` reaches the points of every design in one compiled call: from the start pose (the loops closed
by the loop solver's Newton, :func:`~.loops.closure_kernel.newton`) to the first point and from point to point along
straight Cartesian segments in steps of at most ``IK_STEP`` (a point whose way from the point before it fails is
tried once more straight from the start: a point is reached when either way gets there on the start's branch), with
Newton on all coordinates at once: the closures
``phi(q) = 0`` and the handle's position on the directions it moves, ``U^T (p(q) - goal) = 0``. With ``k = n_a <= 3``
actuated coordinates the system ``[Phi; U^T J_v]`` is square; a redundant device (``n_a > 3``, ``U = I``) takes the
least-norm step ``A^T (A A^T)^-1 r`` (for a tree, the least-squares step on ``J_v``). Each iteration changes no
coordinate by more than ``IK_JOINT_STEP``; on the way between two points one corrector from a pose near the segment
is taken (the next step's walk measures what it left), at the points Newton closes to the tolerance. There is no
position tolerance on the way: the NumPy walk this kernel replaced had one (``IK_WAY``, 1e-3 of the step), and with
it 1000 times looser, 1200 random reaches of the five-bar, delta, Phantom and Falcon gave the same answers and
refusals (issue 36's mutation audit), because what keeps the branch is the determinant's sign, checked at every
pose walked, with steps of at most ``IK_STEP`` and ``IK_JOINT_STEP``; the last walk of a point is the next step's
first. A step is refused (the design fails at that point) when Newton
does not converge or the handle stays off the goal in 3-D (out of reach, or off a planar device's plane), when the
system's pivot ratio falls below ``IK_PIVOTS`` or the sign of its determinant (``det Phi_p det(U^T J_v T)``,
Schur's complement: the working mode with the assembly branch) changes from the start's, or when ``det Phi_p``
(the assembly branch) differs at a point from the start's (behind a singularity). At each point it leaves the full
pose and ``J_v T`` (3 x n_a). Its inner kernels allocate nothing and are compiled without numba's reference counting
(``_nrt=False``), so that passing the records costs no atomic counts per array; the walk, the system and its solve
are inlined into Newton's loop (a call copies the records' fields).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from hapticdesign.analysis.loops import closure_kernel as ck
from hapticdesign.analysis.loops.records import (
    BRANCH_CHANGE, NO_HOME, OK, OUT_OF_REACH, SINGULAR, Closures, closure_scratch,
)
from hapticdesign.model.dense import lu_in_place
from hapticdesign.model.mechanism import UNFOLDED, Mechanism
from hapticdesign.model.walk import KinematicTree, Tree, frame_jacobian, planned_poses, trig_workspace

MESSAGES = {
    NO_HOME: "the loops cannot close at the home pose from the assembly guess",
    OUT_OF_REACH: "it is out of reach",
    SINGULAR: "it is out of reach or behind a singularity",
    BRANCH_CHANGE: "the way leaves the loops' assembly branch",
}
"""Why a point is not reached, per status of :func:`reach_designs`."""


class Shape(NamedTuple):
    """The frame tree without its offsets (one node per elementary transform): the :class:`Tree` of a design is
    this with the design's offsets."""

    parent: np.ndarray
    axis: np.ndarray
    coef: np.ndarray
    const_rot: np.ndarray
    const_pos: np.ndarray


class Reach(NamedTuple):
    """The continuation's settings: largest Cartesian step (m), position tolerance (m) at the points, Newton
    iterations, largest coordinate change per iteration, singular pivot ratio, the handle's node, the directions
    ``U`` (3 x k) the handle moves, and the start (full coordinates; from a guess, the loops are closed first)."""

    step: float
    tol: float
    max_iter: int
    joint_step: float
    singular: float
    handle: int
    basis: np.ndarray
    guess: np.ndarray


class Reached(NamedTuple):
    """Per design: full poses (D, P, N), ``J_v T`` (D, P, 3, n_a), status (D,), the failed point (D,; -1: the
    start) and the handle's position where the walk stopped (D, 3)."""

    full: np.ndarray
    jvt: np.ndarray
    status: np.ndarray
    point: np.ndarray
    near: np.ndarray


class Structure(NamedTuple):
    """The records of a device's geometry the kernel takes: the frame tree (:class:`Shape` and the offsets of the
    device itself), the unfolded tree, the closures on its nodes and the handle's node."""

    shape: Shape
    offset: np.ndarray
    raw: KinematicTree
    closures: Closures
    handle: int


def structure_of(mech: Mechanism, frame: str | None = None) -> Structure:
    """The :class:`Structure` of a mechanism, with ``frame`` (default: the end effector) as the handle."""
    c = mech.compiled
    n_node = len(c.node_parent)
    shape = Shape(c.node_parent.astype(np.int64), c.node_axis.astype(np.int64), c.node_coef.copy(),
                  np.broadcast_to(np.eye(3), (n_node, 3, 3)).copy(), np.zeros((n_node, 3)))
    raw = KinematicTree(c.node_parent, c.node_axis, c.node_coef, c.node_offset, shape.const_rot, shape.const_pos,
                        dict(c.frame_node), c.body_node)
    return Structure(shape, c.node_offset.copy(), raw, Closures.of(mech, UNFOLDED),
                     int(c.frame_node[frame or mech.end_effector]))


class Scratch(NamedTuple):
    """The continuation's scratch: node poses, cosines and sines, the handle's position Jacobian, the system and its
    right-hand side, the closure residual, ``Phi``, ``Phi_p``, ``S = -Phi_p^-1 Phi_a`` and, for a redundant device,
    ``A A^T`` and its right-hand side."""

    rot: np.ndarray
    pos: np.ndarray
    trig: np.ndarray
    jac: np.ndarray
    a: np.ndarray
    rhs: np.ndarray
    res: np.ndarray
    phi: np.ndarray
    pp: np.ndarray
    t: np.ndarray
    aat: np.ndarray
    y: np.ndarray


@njit(cache=True, _nrt=False, inline="always")
def _walk(q, tree, plan, loops, reach, ws, start):
    """Node poses from the plan's node ``start`` on (0, or the plan's ``n_fixed`` after a walk of the same design),
    the closure residual, ``Phi`` and the handle's position Jacobian at ``q`` into ``ws``."""
    planned_poses(q, tree, plan, start, plan.n_first, ws.rot, ws.pos, ws.trig)
    ck.closure_residual(loops, ws.rot, ws.pos, ws.res)
    ck.closure_jacobian(loops, tree, plan, ws.rot, ws.pos, ws.phi)
    frame_jacobian(reach.handle, tree.parent, tree.axis, tree.coef, ws.rot, ws.pos, np.bool_(False), ws.jac)


@njit(cache=True, _nrt=False, inline="always")
def _system(reach, goal, ws):
    """The system ``[Phi; U^T J_v]`` into ``ws.a`` and ``[-phi; U^T (goal - p)]`` into ``ws.rhs`` from the walk in
    ``ws``; returns the largest closure residual and the 3-D distance of the handle from ``goal``."""
    pos, jac, a, rhs, res, phi = ws.pos, ws.jac, ws.a, ws.rhs, ws.res, ws.phi
    m, n = phi.shape
    big = 0.0
    for i in range(m):
        rhs[i, 0] = -res[i]
        big = max(big, abs(res[i]))
        for j in range(n):
            a[i, j] = phi[i, j]
    e0, e1, e2 = goal[0] - pos[reach.handle, 0], goal[1] - pos[reach.handle, 1], goal[2] - pos[reach.handle, 2]
    k = reach.basis.shape[1]
    for r in range(k):
        rhs[m + r, 0] = reach.basis[0, r] * e0 + reach.basis[1, r] * e1 + reach.basis[2, r] * e2
        for j in range(n):
            acc = 0.0
            for c in range(3):
                acc += reach.basis[c, r] * jac[c, j]
            a[m + r, j] = acc
    return big, np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)


@njit(cache=True, _nrt=False, inline="always")
def _solve(ws, singular):
    """The Newton step into ``ws.rhs`` (its first N rows): the system's solution when it is square, else the
    least-norm ``A^T (A A^T)^-1 r``; returns (pivot ratio, sign of the determinant of ``A`` or ``A A^T``)."""
    a, rhs = ws.a, ws.rhs
    rows, n = ws.aat.shape[0], a.shape[1]
    if rows == n:
        return lu_in_place(a, rhs)
    aat, y = ws.aat, ws.y
    for i in range(rows):
        y[i, 0] = rhs[i, 0]
        for j in range(rows):
            acc = 0.0
            for c in range(n):
                acc += a[i, c] * a[j, c]
            aat[i, j] = acc
    ratio, sign = lu_in_place(aat, y)
    for c in range(n):
        acc = 0.0
        for i in range(rows):
            acc += a[i, c] * y[i, 0]
        rhs[c, 0] = acc
    return ratio / singular, sign  # A A^T squares A's conditioning: its pivot ratio is measured against singular^2


@njit(cache=True, _nrt=False)
def _newton(q, tree, plan, loops, settings, reach, goal, mode, final, walked, ws):
    """Newton on all coordinates to put the handle at ``goal`` with the loops closed (to the tolerance when
    ``final``, else one corrector near the segment); returns (status, sign of the system's determinant). ``mode``
    0: no sign to keep (the start). ``walked``: ``ws`` holds the walk at ``q`` already (a point just reached, whose
    last walk is the next step's first)."""
    rhs = ws.rhs
    for it in range(reach.max_iter):
        if it > 0 or not walked:
            _walk(q, tree, plan, loops, reach, ws, plan.n_fixed)
        big, dist = _system(reach, goal, ws)
        ratio, sign = _solve(ws, reach.singular)
        if not ratio > reach.singular:
            return SINGULAR, sign
        if mode != 0.0 and sign != mode:
            return SINGULAR, sign
        if final and big <= settings.tol and dist <= reach.tol:
            return OK, sign
        largest = 0.0
        for j in range(q.shape[0]):
            largest = max(largest, abs(rhs[j, 0]))
        scale = 1.0 if largest <= reach.joint_step else reach.joint_step / largest
        for j in range(q.shape[0]):
            q[j] += scale * rhs[j, 0]
        if not final and scale == 1.0 and dist <= 1.5 * reach.step and big <= 1.5 * reach.step:
            return OK, sign  # on the way: one corrector from a pose near the segment, checked by the next step's walk
    return OUT_OF_REACH, 0.0


@njit(cache=True, _nrt=False)
def _branch(loops, ws):
    """Sign of ``det Phi_p`` at the closed pose walked in ``ws`` and ``S`` into ``ws.t`` (1 for a tree)."""
    if loops.passive.shape[0] == 0:
        return 1.0
    ratio, sign = ck.velocity_map_into(ws.phi, loops.actuated, loops.passive, ws.pp, ws.t)
    return sign if ratio > 0.0 else 0.0


@njit(cache=True)
def reach_designs(offsets, targets, shape, plan, loops, settings, reach, out):
    """Reach ``targets`` (P, 3) for every design's node offsets (D, nodes) into ``out`` (:class:`Reached`); see the
    module docstring."""
    n = reach.guess.shape[0]
    m = loops.row_loop.shape[0]
    na = loops.actuated.shape[0]
    rows = m + reach.basis.shape[1]
    n_node = shape.parent.shape[0]
    ws = Scratch(np.zeros((n_node, 3, 3)), np.zeros((n_node, 3)), trig_workspace(n_node), np.zeros((3, n)),
                 np.zeros((rows, n)), np.zeros((max(rows, n), 1)), np.zeros(m), np.zeros((m, n)), np.zeros((m, m)),
                 np.zeros((m, na)), np.zeros((rows, rows)), np.zeros((rows, 1)))
    closing = closure_scratch(n_node, n, na, loops.passive, np.int64(0))
    here = np.zeros(3)
    goal = np.zeros(3)
    origin = np.zeros(3)
    q0 = np.zeros(n)
    for d in range(offsets.shape[0]):
        tree = Tree(shape.parent, shape.axis, shape.coef, offsets[d], shape.const_rot, shape.const_pos)
        q = reach.guess.copy()
        out.status[d] = OK
        out.point[d] = -1
        if m > 0:
            code, _, _ = ck.newton_into(q, tree, plan, loops, settings, closing)
            if code != OK:
                out.status[d] = NO_HOME
                continue
        _walk(q, tree, plan, loops, reach, ws, np.int64(0))  # the design's fixed nodes too
        branch = _branch(loops, ws)
        for c in range(3):
            here[c] = ws.pos[reach.handle, c]
        code, mode = _newton(q, tree, plan, loops, settings, reach, here, 0.0, np.bool_(True), np.bool_(True),
                             ws)  # literal True would compile a second _newton (Literal[bool] beside bool)
        q0[:] = q
        origin[:] = here
        for p in range(targets.shape[0]):
            if code != OK:
                break
            for attempt in range(2):  # from the point before, then (when that way fails) straight from the start
                if attempt == 1:
                    if p == 0:
                        break
                    q[:] = q0
                    here[:] = origin
                    _walk(q, tree, plan, loops, reach, ws, plan.n_fixed)
                dist = np.sqrt((targets[p, 0] - here[0]) ** 2 + (targets[p, 1] - here[1]) ** 2
                               + (targets[p, 2] - here[2]) ** 2)
                steps = max(1, int(np.ceil(dist / reach.step)))
                for s in range(1, steps + 1):
                    for c in range(3):
                        goal[c] = here[c] + (targets[p, c] - here[c]) * (s / steps)
                    code, _ = _newton(q, tree, plan, loops, settings, reach, goal, mode, s == steps, s == 1, ws)
                    if code != OK:
                        break
                if code == OK and _branch(loops, ws) != branch:
                    code = BRANCH_CHANGE
                if code == OK:
                    break
            if code != OK:
                out.point[d] = p
                break
            for c in range(3):
                here[c] = targets[p, c]
            out.full[d, p] = q
            for r in range(3):
                for j in range(na):
                    acc = ws.jac[r, loops.actuated[j]]
                    for i in range(m):
                        acc += ws.jac[r, loops.passive[i]] * ws.t[i, j]
                    out.jvt[d, p, r, j] = acc
        for c in range(3):
            out.near[d, c] = ws.pos[reach.handle, c]
        out.status[d] = code
