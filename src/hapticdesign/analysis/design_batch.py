"""Many designs of one closed-loop device through compiled kernels: workspace poses, ``J_v T`` and ``H`` per design.

An optimization evaluates thousands of designs that differ only in numbers: lengths, masses, motors. Building each
design's mechanism, loop solver and models in Python costs milliseconds, so :class:`DesignBatch` builds the
*structure* once (the frame tree with one node per elementary transform, its walk plan, the closures, the bodies)
and takes per design only what changes:

- the node offsets, affine in the kinematic parameters (a device file's values are affine expressions, so
  ``offset = offset_0 + S (p - p_0)`` exactly; ``S`` is found once by building the mechanism at ``p_0 + e_k``);
- the standard inertial parameters and the motors' reflected inertia.

:func:`reach_designs` then reaches the workspace points of every design in one compiled call, by the same
continuation as :meth:`~hapticdesign.analysis.configuration.Configuration.reach` (straight Cartesian segments in
steps of at most ``IK_STEP`` from home to the first point and from point to point), with Newton on all coordinates
at once: the closures ``phi(q) = 0`` and the handle's position on the directions it moves, ``U^T (p(q) - goal) =
0`` (a square system when the loops leave ``k = n_a <= 3`` actuated coordinates). A step is refused (the design
fails at that point) when Newton does not converge or the handle is off the goal in 3-D (out of reach, or off a
planar device's plane), when the system's pivot ratio falls below ``IK_SINGULAR`` or the sign of its determinant
(``det Phi_p det(U^T J_v T)``, Schur's complement) or of ``det Phi_p`` (the assembly branch) changes from home's
(behind a singularity). At each point it leaves ``J_v T`` (3 x n_a). :func:`mass_designs` gives ``H`` at those
poses with the closed-loop dynamics' own pose kernels (:mod:`hapticdesign.analysis.dynamics.actuated_kernel`). The
continuation's inner kernels allocate nothing and are compiled without numba's reference counting (``_nrt=False``),
so that passing the records costs no atomic counts per array.
``tests/design/test_design_batch.py`` checks both against the one-design path (:mod:`.metrics.indices`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from hapticdesign.analysis.configuration import IK_JOINT_STEP, IK_STEP, IK_WAY, configuration_of
from hapticdesign.analysis.dynamics.actuated_kernel import (
    Bodies, factor_pose, mass_and_gravity, passive_paths, reduce_pose, world_parameters,
)
from hapticdesign.analysis.loops import closure_kernel as ck
from hapticdesign.analysis.loops.records import Closures, workspace
from hapticdesign.errors import UserError
from hapticdesign.model.dense import lu_in_place
from hapticdesign.model.device import Device, build_mechanism
from hapticdesign.model.walk import KinematicTree, MotionPlan, Tree, frame_jacobian, planned_poses, trig_workspace

OK, NO_HOME, OUT_OF_REACH, SINGULAR, BRANCH = 0, 1, 2, 3, 4
SINGULAR_PIVOTS = 1e-9
"""Pivot ratio of the system ``[Phi; U^T J_v]`` below which a pose counts as singular."""
MESSAGES = {
    NO_HOME: "the loops cannot close at the home pose from the assembly guess",
    OUT_OF_REACH: "it is out of reach",
    SINGULAR: "it is out of reach or behind a singularity",
    BRANCH: "the way leaves the loops' assembly branch",
}


class Shape(NamedTuple):
    """The frame tree without its offsets (one node per elementary transform): the :class:`Tree` of a design is
    this with the design's offsets."""

    parent: np.ndarray
    axis: np.ndarray
    coef: np.ndarray
    const_rot: np.ndarray
    const_pos: np.ndarray


class Reach(NamedTuple):
    """The continuation's settings: largest Cartesian step (m), position tolerance (m) at the points and on the way
    between them (``IK_WAY`` of the step; there one Newton corrector from a pose within 1.5 steps of the goal is taken without a
    second walk, the next step's walk measuring what it left), Newton iterations, largest
    coordinate change per iteration, singular pivot ratio, the handle's node and the directions ``U`` (3 x k) the
    handle moves, and the home guess (full coordinates: home's actuated values, the assembly's passive ones)."""

    step: float
    tol: float
    loose: float
    max_iter: int
    joint_step: float
    singular: float
    handle: int
    basis: np.ndarray
    guess: np.ndarray


class Reached(NamedTuple):
    """Per design: full poses (D, P, N), ``J_v T`` (D, P, 3, n_a), status (D,) and the failed point (D,)."""

    full: np.ndarray
    jvt: np.ndarray
    status: np.ndarray
    point: np.ndarray


class Scratch(NamedTuple):
    """The continuation's scratch: node poses, cosines and sines, the handle's Jacobian, the system and its right-hand
    side, the closure residual, ``Phi``, ``Phi_p`` and ``S = -Phi_p^-1 Phi_a``."""

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


@njit(cache=True, _nrt=False)
def _walk_and_system(q, tree, plan, loops, reach, goal, ws):
    """Node poses, the system ``[Phi; U^T J_v]`` (N x N) into ``ws.a`` and ``[-phi; U^T (goal - p)]`` into ``ws.rhs``;
    returns the largest closure residual and the 3-D distance of the handle from ``goal``."""
    rot, pos, trig, jac, a, rhs, res = ws.rot, ws.pos, ws.trig, ws.jac, ws.a, ws.rhs, ws.res
    m = loops.row_loop.shape[0]
    n = q.shape[0]
    planned_poses(q, tree, plan, np.int64(0), plan.n_first, rot, pos, trig)  # a literal would compile its own copy
    ck.closure_residual(loops, rot, pos, res)
    ck.closure_jacobian(loops, tree, plan, rot, pos, a[:m])
    frame_jacobian(reach.handle, tree.parent, tree.axis, tree.coef, rot, pos, np.bool_(False), jac)
    big = 0.0
    for i in range(m):
        rhs[i, 0] = -res[i]
        big = max(big, abs(res[i]))
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


@njit(cache=True, _nrt=False)
def _newton(q, tree, plan, loops, settings, reach, goal, mode, tol, ws):
    """Newton on all coordinates to put the handle at ``goal`` within ``tol`` (m) with the loops closed; returns
    (status, sign of the system's determinant). ``mode`` 0: no sign to keep (home)."""
    a, rhs = ws.a, ws.rhs
    for _ in range(reach.max_iter):
        big, dist = _walk_and_system(q, tree, plan, loops, reach, goal, ws)
        ratio, sign = lu_in_place(a, rhs)
        if not ratio > reach.singular:
            return SINGULAR, sign
        if mode != 0.0 and sign != mode:
            return SINGULAR, sign
        if big <= settings.tol * tol / reach.tol and dist <= tol:
            return OK, sign
        largest = 0.0
        for j in range(q.shape[0]):
            largest = max(largest, abs(rhs[j, 0]))
        scale = 1.0 if largest <= reach.joint_step else reach.joint_step / largest
        for j in range(q.shape[0]):
            q[j] += scale * rhs[j, 0]
        if tol > reach.tol and scale == 1.0 and dist <= 1.5 * reach.step and big <= 1.5 * reach.step:
            return OK, sign  # on the way: one corrector from a pose near the segment, checked by the next step's walk
    return OUT_OF_REACH, 0.0


@njit(cache=True, _nrt=False)
def _branch(q, tree, plan, loops, ws):
    """Sign of ``det Phi_p`` at the closed pose ``q`` (its poses in ``ws``) and ``S`` into ``ws.t``."""
    ck.closure_jacobian(loops, tree, plan, ws.rot, ws.pos, ws.phi)
    ratio, sign = ck.velocity_map_into(ws.phi, loops.actuated, loops.passive, ws.pp, ws.t)
    return sign if ratio > 0.0 else 0.0


@njit(cache=True)
def reach_designs(offsets, targets, shape, plan, loops, settings, reach, out):
    """Reach ``targets`` (P, 3) for every design's node offsets (D, nodes) into ``out`` (:class:`Reached`); see the
    module docstring."""
    n = reach.guess.shape[0]
    m = loops.row_loop.shape[0]
    na = loops.actuated.shape[0]
    n_node = shape.parent.shape[0]
    ws = Scratch(np.zeros((n_node, 3, 3)), np.zeros((n_node, 3)), trig_workspace(n_node), np.zeros((6, n)),
                 np.zeros((n, n)), np.zeros((n, 1)), np.zeros(m), np.zeros((m, n)), np.zeros((m, m)), np.zeros((m, na)))
    here = np.zeros(3)
    goal = np.zeros(3)
    for d in range(offsets.shape[0]):
        tree = Tree(shape.parent, shape.axis, shape.coef, offsets[d], shape.const_rot, shape.const_pos)
        q = reach.guess.copy()
        out.status[d] = OK
        out.point[d] = -1
        code, _, _ = ck.newton(q, tree, plan, loops, settings)
        if code != ck.OK:
            out.status[d] = NO_HOME
            continue
        planned_poses(q, tree, plan, np.int64(0), plan.n_first, ws.rot, ws.pos, ws.trig)
        branch = _branch(q, tree, plan, loops, ws)
        for c in range(3):
            here[c] = ws.pos[reach.handle, c]
        code, mode = _newton(q, tree, plan, loops, settings, reach, here, 0.0, reach.tol, ws)
        for p in range(targets.shape[0]):
            if code != OK:
                break
            dist = np.sqrt((targets[p, 0] - here[0]) ** 2 + (targets[p, 1] - here[1]) ** 2
                           + (targets[p, 2] - here[2]) ** 2)
            steps = max(1, int(np.ceil(dist / reach.step)))
            for s in range(1, steps + 1):
                for c in range(3):
                    goal[c] = here[c] + (targets[p, c] - here[c]) * (s / steps)
                code, _ = _newton(q, tree, plan, loops, settings, reach, goal, mode,
                                  reach.tol if s == steps else reach.loose, ws)
                if code != OK:
                    break
            if code == OK and _branch(q, tree, plan, loops, ws) != branch:
                code = BRANCH
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
        out.status[d] = code


@njit(cache=True)
def mass_designs(offsets, full, status, shape, plan, bodies, loops, params, out):
    """``H`` (actuated coordinates, without the reflected rotor inertia) at the poses ``full`` (D, P, N) of the
    designs whose status is OK, for their standard parameters ``params`` (D, 10 B), into ``out`` (D, P, n_a, n_a):
    ``sum_b (J_b T)^T M_b (J_b T)`` (eq. 2.44) with the closed-loop dynamics' own pose kernels."""
    n_design, n_pose, n = full.shape
    na = loops.actuated.shape[0]
    body_node = bodies.body_node
    n_body = body_node.shape[0]
    ws = workspace(shape.parent.shape[0], n, na, loops.passive, n_body)
    pw = np.zeros((1, n_body, 10))
    h = np.zeros((na, na))
    g = np.zeros(na)
    mj = np.zeros((6, na))
    for d in range(n_design):
        if status[d] != OK:
            continue
        tree = Tree(shape.parent, shape.axis, shape.coef, offsets[d], shape.const_rot, shape.const_pos)
        sets = params[d:d + 1]
        for p in range(n_pose):
            factor_pose(full[d, p], tree, plan, loops, ws)
            reduce_pose(tree, plan, body_node, loops, ws)
            world_parameters(ws.rot, body_node, sets, np.int64(0), pw)
            h[:] = 0.0
            for b in range(n_body):
                if body_node[b] >= 0:
                    mass_and_gravity(ws.ja, b, bodies.gravity, pw, 0, h, g, mj, False)
            out[d, p] = h


class DesignBatch:
    """The compiled structure of a closed-loop device's geometry family (see the module docstring): designs that
    share the file's frames, loops and bodies and differ in kinematic parameters, inertial parameters and motors."""

    def __init__(self, device: Device, frame: str | None = None):
        mech = device.mechanism
        if mech.loops is None:
            raise UserError("the batched design kernels take closed-loop devices (a tree takes the one-design path)")
        space = configuration_of(device)
        c = mech.compiled
        n_a = mech.n_actuated
        if n_a > 3 or len(mech.loops.passive) + n_a != mech.n_dof:
            raise UserError("the batched design kernels take devices whose handle moves in as many directions as they "
                            "have actuated coordinates (at most 3)")
        self.device, self.names = device, tuple(device.kinematic)
        self.p0 = np.array([device.params[k] for k in self.names], dtype=float)
        self.offset0 = c.node_offset.copy()
        self.sensitivity = self._sensitivity(device)
        n_node = len(c.node_parent)
        self.shape = Shape(c.node_parent.astype(np.int64), c.node_axis.astype(np.int64), c.node_coef.copy(),
                           np.broadcast_to(np.eye(3), (n_node, 3, 3)).copy(), np.zeros((n_node, 3)))
        raw = KinematicTree(c.node_parent, c.node_axis, c.node_coef, c.node_offset, self.shape.const_rot,
                            self.shape.const_pos, dict(c.frame_node), c.body_node)
        loops = mech.loops
        rows = [(i, comp) for i, closure in enumerate(loops.closures) for comp in closure.components]
        self.closures = Closures(
            frame_a=np.array([c.frame_node[cl.frames[0]] for cl in loops.closures], dtype=np.int64),
            frame_b=np.array([c.frame_node[cl.frames[1]] for cl in loops.closures], dtype=np.int64),
            row_loop=np.array([r[0] for r in rows], dtype=np.int64),
            row_comp=np.array([r[1] for r in rows], dtype=np.int64),
            actuated=np.array(loops.actuated(mech.n_dof), dtype=np.int64),
            passive=np.array(loops.passive, dtype=np.int64),
        )
        handle = c.frame_node[frame or mech.end_effector]
        plan = raw.plan([*self.closures.frame_a, *self.closures.frame_b, handle], list(self.closures.passive))
        self.plan = self._unshared(plan)
        body_node = c.body_node.astype(np.int64)
        ptr, nodes = passive_paths(c.node_parent, self.plan, body_node, self.closures.passive)
        self.bodies = Bodies(body_node=body_node, gravity=c.gravity,
                             motion=MotionPlan.of(raw, [*body_node, *self.closures.frame_a, *self.closures.frame_b]),
                             path_ptr=ptr, path_nodes=nodes)
        self.settings = space.solver.settings
        guess = np.zeros(mech.n_dof)
        guess[self.closures.actuated] = loops.home
        guess[self.closures.passive] = loops.assembly
        jac = space.position_and_jacobian(space.full(space.home), frame)[1]
        u, s, _ = np.linalg.svd(jac)
        self.reach = Reach(IK_STEP, self.settings.tol, IK_WAY * IK_STEP, 60, IK_JOINT_STEP, SINGULAR_PIVOTS, int(handle),
                           np.ascontiguousarray(u[:, :n_a]), guess)

    def _sensitivity(self, device: Device) -> np.ndarray:
        """``d offset / d p`` (nodes x parameters), exact for the affine values of a device file."""
        out = np.zeros((len(self.offset0), len(self.names)))
        for k, name in enumerate(self.names):
            shifted = tuple((n, float(v) + (1.0 if n == name else 0.0)) for n, v in device.kinematic_values())
            out[:, k] = build_mechanism(device.builder, shifted).compiled.node_offset - self.offset0
        return out

    def _unshared(self, plan):
        """The plan without shared cosines and sines between nodes whose angles parameters move differently."""
        source, sign = plan.trig_source.copy(), plan.trig_sign.copy()
        for n, s in enumerate(source):
            if s != n and not np.allclose(self.sensitivity[n], sign[n] * self.sensitivity[s], rtol=0, atol=1e-12):
                source[n], sign[n] = n, 1.0
        return plan._replace(trig_source=source, trig_sign=sign)

    def offsets(self, kinematic: np.ndarray) -> np.ndarray:
        """Node offsets (D, nodes) of designs with kinematic parameters ``kinematic`` (D, parameters) in the order of
        ``names``."""
        return self.offset0 + (np.atleast_2d(kinematic) - self.p0) @ self.sensitivity.T

    def reach_points(self, offsets: np.ndarray, points: np.ndarray) -> Reached:
        """:func:`reach_designs` of the designs' offsets (D, nodes) to ``points`` (P, 3)."""
        offsets = np.ascontiguousarray(offsets, dtype=float)
        d, p, n, na = len(offsets), len(points), len(self.reach.guess), len(self.closures.actuated)
        out = Reached(np.zeros((d, p, n)), np.zeros((d, p, 3, na)), np.zeros(d, dtype=np.int64),
                      np.zeros(d, dtype=np.int64))
        reach_designs(offsets, np.ascontiguousarray(points, dtype=float), self.shape, self.plan, self.closures,
                      self.settings, self.reach, out)
        return out

    def mass_matrices(self, offsets: np.ndarray, reached: Reached, params: np.ndarray,
                      reflected: np.ndarray) -> np.ndarray:
        """``H`` (D, P, n_a, n_a) at the reached poses, standard parameters ``params`` (D, 10 B) or one set for every
        design (10 B,), and reflected rotor inertia ``reflected`` (D, n_a, n_a) or (n_a, n_a)."""
        d, p = reached.status.shape[0], reached.full.shape[1]
        na = len(self.closures.actuated)
        h = np.zeros((d, p, na, na))
        params = np.ascontiguousarray(np.broadcast_to(np.atleast_2d(params), (d, np.shape(params)[-1])), dtype=float)
        mass_designs(np.ascontiguousarray(offsets, dtype=float), reached.full, reached.status, self.shape, self.plan,
                     self.bodies, self.closures, params, h)
        return h + (reflected[:, None] if np.ndim(reflected) == 3 else reflected)

    def reason(self, reached: Reached, design: int, points: np.ndarray) -> str | None:
        """One line on why ``design`` failed (naming the point), or None."""
        code = int(reached.status[design])
        if code == OK:
            return None
        if code == NO_HOME:
            return MESSAGES[NO_HOME]
        index = int(reached.point[design])
        where = "home" if index < 0 else "(" + ", ".join(f"{v:.6g}" for v in points[index]) + ") m"
        return f"the handle cannot reach {where}: {MESSAGES[code]}"
