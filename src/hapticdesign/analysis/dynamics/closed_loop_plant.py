"""A compiled closed-loop plant: H, C(q, qd) qd and G in actuated coordinates, pose after pose (seed 000 eq. 2.44-2.50).

A closed-loop device has no exact basis tables (:mod:`hapticdesign.simulation.tables`): its equations of
motion in the actuated coordinates ``tau_a = H_a qdd_a + c_a(q_a, qd_a) + G_a`` come from the loop-opened
tree reduced by ``T = [I; S]`` (:mod:`.actuated_kernel`), at the passive values that close the loops.
:func:`closed_loop_terms` gives them inside numba for one parameter set, at one actuated pose and rate:

- the passive values follow by Newton (:func:`hapticdesign.analysis.loops.closure_kernel.newton_into`)
  from a tangent predictor ``q_p + S dq_a`` at the last pose solved, which the workspace carries (a
  fixed-step integrator moves little between calls, so one or two iterations close the loops);
- ``H_a`` (n_a x n_a, with the constant reflected rotor inertia), ``c_a = C(q, qd) qd^2`` (the velocity
  terms for the given rates, one tree pass instead of the ``n_a (n_a + 1) / 2`` of eq. 2.50's columns)
  and ``G_a``;
- a status: ``OK``, ``NO_CLOSURE`` (Newton fails, or its correction exceeds half the actuated step: it
  jumped), ``SINGULAR`` (``Phi_p`` singular) or ``BRANCH_CHANGE`` (``det Phi_p`` changed sign). On any
  failure the outputs are left as they were and the workspace keeps the last closed pose.

:class:`ClosedLoopPlant` builds the arrays (``structure``) and the workspace from a
:class:`~.closed_loop.ClosedLoopModel` and starts on the assembly branch at a given actuated pose.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hapticdesign.analysis.dynamics.actuated_kernel import (
    active_bodies,
    body_wrench,
    mass_and_gravity,
    reduce_pose,
    velocity_state,
    workspace,
    world_parameters,
)
from hapticdesign.analysis.dynamics.closed_loop import ClosedLoopModel
from hapticdesign.analysis.loops import closure_kernel as ck
from hapticdesign.analysis.loops.solver import MAX_ITER, MESSAGES, SINGULAR_RATIO
from hapticdesign.errors import UserError
from hapticdesign.model.walk import CONSTANT, planned_poses, unit_twist

OK, NO_CLOSURE, SINGULAR, BRANCH_CHANGE = ck.OK, ck.NO_CLOSURE, ck.SINGULAR, ck.BRANCH_CHANGE


@njit(cache=True)
def plant_workspace(n_node, n_dof, na, passive, n_body):
    """Scratch of :func:`closed_loop_terms`: ``(kernel workspace, q, q_last, res, rhs, pp, pw, predicted)``.

    ``q`` is the warm start (full coordinates of the last closed pose), ``q_last`` a copy to fall back to.
    """
    npas = passive.shape[0]
    return (
        workspace(n_node, n_dof, na, passive, n_body), np.zeros(n_dof), np.zeros(n_dof), np.zeros(npas),
        np.zeros((npas, 1)), np.zeros((npas, npas)), np.zeros((1, n_body, 10)), np.zeros(npas),
    )


@njit(cache=True)
def closed_loop_terms(qa, qda, structure, ws, h, cqd, g):
    """``H_a`` (n_a x n_a), ``c_a = C(q, qd) qd^2`` (n_a) and ``G_a`` (n_a) at actuated ``qa``, rates ``qda``.

    ``structure``: ``(parent, axis, offset, const_rot, const_pos, plan, motion, body_node, gravity, frame_a, frame_b,
    row_loop, row_comp, actuated, passive, params (1, 10 B), active (B,), constant (n_a x n_a), tol, max_iter,
    singular_ratio, branch)`` with ``plan`` the arrays of the loop solver's
    :class:`~hapticdesign.model.walk.WalkPlan` and ``motion`` the model's
    :class:`~hapticdesign.analysis.loops.solver.MotionPlan`; ``ws``: :func:`plant_workspace`. Returns the status (module
    docstring).
    """
    (parent, axis, offset, const_rot, const_pos, plan, motion, body_node, gravity, frame_a, frame_b, row_loop, row_comp,
     actuated, passive, params, active, constant, tol, max_iter, singular_ratio, branch) = structure
    dyn, q, q_last, res, rhs, pp, pw, predicted = ws
    rot, pos, w, al, ac, phi, pinv, t, ja, trig = dyn[0], dyn[1], dyn[2], dyn[3], dyn[4], dyn[5], dyn[7], dyn[8], dyn[11], dyn[14]
    na = actuated.shape[0]
    npas = passive.shape[0]
    dist = 0.0
    for k in range(q.shape[0]):
        q_last[k] = q[k]
    # tangent predictor from T at the last closed pose
    for j in range(na):
        delta = qa[j] - q[actuated[j]]
        dist = max(dist, abs(delta))
        for r in range(npas):
            q[passive[r]] += t[passive[r], j] * delta
        q[actuated[j]] = qa[j]
    for r in range(npas):
        predicted[r] = q[passive[r]]
    status, sign, _ = ck.newton_into(q, actuated, passive, parent, axis, offset, const_rot, const_pos, plan, frame_a,
                                     frame_b, row_loop, row_comp, tol, max_iter, singular_ratio, rot, pos, trig, res,
                                     phi, rhs, pp, pinv)
    if status == OK and sign != branch:
        status = BRANCH_CHANGE
    if status == OK:
        for r in range(npas):
            if abs(q[passive[r]] - predicted[r]) > 0.5 * dist + 1e-9:
                status = NO_CLOSURE
    if status != OK:
        for k in range(q.shape[0]):
            q[k] = q_last[k]
        return status
    # Newton left Phi, Phi_p^-1 and the closures' node poses at q: the other nodes complete factor_pose
    planned_poses(q, parent, axis, offset, const_rot, const_pos, plan, plan[1], parent.shape[0], rot, pos, trig)
    reduce_pose(parent, axis, plan, body_node, actuated, passive, dyn)
    world_parameters(rot, body_node, params, 0, pw)
    for i in range(na):
        g[i] = 0.0
        cqd[i] = 0.0
        for j in range(na):
            h[i, j] = constant[i, j]
    for b in range(body_node.shape[0]):
        if active[b] and body_node[b] >= 0:
            mass_and_gravity(ja, b, gravity, pw, 0, h, g, h, False)
    velocity_state(qda, -1, -1, axis, plan, motion, frame_a, frame_b, row_loop, row_comp, passive, dyn)
    for b in range(body_node.shape[0]):
        nb = body_node[b]
        if not active[b] or nb < 0:
            continue
        f0, f1, f2, n0, n1, n2 = body_wrench(w, al, ac, nb, pw, 0, b)
        for i in range(na):
            cqd[i] += (ja[b, 0, i] * f0 + ja[b, 1, i] * f1 + ja[b, 2, i] * f2
                       + ja[b, 3, i] * n0 + ja[b, 4, i] * n1 + ja[b, 5, i] * n2)
    return OK


class ClosedLoopPlant:
    """:func:`closed_loop_terms` for one device geometry and parameter set, started at an actuated pose.

    ``structure`` and ``workspace`` are what a numba caller passes; :meth:`terms` is the Python entry.
    """

    def __init__(self, model: ClosedLoopModel, pi: np.ndarray, q_a0: np.ndarray):
        solver, c, a, tree = model.solver, model.compiled, model.solver.arrays, model.compiled.tree
        params = np.ascontiguousarray(np.atleast_2d(model._params(pi)), dtype=float)
        if params.shape[0] != 1:
            raise UserError("a plant takes one set of standard inertial parameters")
        n = model.n_dof
        constant = np.zeros((n, n))
        if model.constant is not None:
            iu, ju = np.triu_indices(n)
            constant[iu, ju] = constant[ju, iu] = model.constant[model.slice_h]
        self.n_dof = n
        self.structure = (
            tree.parent, tree.axis, tree.offset, tree.const_rot, tree.const_pos, solver.plan.arrays,
            model.motion.arrays, tree.body_node, c.gravity,
            a.frame_a, a.frame_b, a.row_loop, a.row_comp, a.actuated, a.passive, params, active_bodies(params),
            constant, float(solver.tol), int(MAX_ITER), float(SINGULAR_RATIO), float(solver.branch),
        )
        self.workspace = plant_workspace(len(tree.parent), solver.n_dof, n, a.passive, len(tree.body_node))
        self.workspace[1][:] = solver.solve(q_a0)
        self.terms(q_a0, np.zeros(n))  # T at the start pose, for the first tangent predictor

    def terms(self, q_a: np.ndarray, qd_a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(H_a, C(q, qd) qd^2, G_a)`` at the next actuated pose and rates (continued from the last one)."""
        n = self.n_dof
        h, cqd, g = np.zeros((n, n)), np.zeros(n), np.zeros(n)
        q_a = np.asarray(q_a, dtype=float)
        status = closed_loop_terms(q_a, np.asarray(qd_a, dtype=float), self.structure, self.workspace, h, cqd, g)
        if status != OK:
            raise UserError(f"at q = ({', '.join(f'{v:.6g}' for v in q_a)}): {MESSAGES[status]}")
        return h, cqd, g

    @property
    def q_full(self) -> np.ndarray:
        """Full coordinates of the last closed pose (the warm start)."""
        return self.workspace[1].copy()


@njit(cache=True)
def handle_along(ws, parent, axis, node, direction, jn, want_jn):
    """At the last closed pose of a :func:`plant_workspace`: the position of node ``node`` (the handle) along
    the unit ``direction`` n, ``n . p``, and, when ``want_jn``, into ``jn`` (n_a) its velocity along n per
    actuated rate, ``J_n = n^T J_v T`` (seed 000 eq. 2.24-2.26 on the loop-opened tree, reduced by ``T``).

    ``J_v T`` is summed over the variable nodes from the handle to the base with each node's joint-value rate
    per actuated rate (``coef T``, which :func:`closed_loop_terms` leaves in the workspace)."""
    dyn = ws[0]
    rot, pos, node_t = dyn[0], dyn[1], dyn[9]
    x = direction[0] * pos[node, 0] + direction[1] * pos[node, 1] + direction[2] * pos[node, 2]
    if not want_jn:
        return x
    for j in range(jn.shape[0]):
        jn[j] = 0.0
    e = node
    while e >= 0:
        if axis[e] != CONSTANT:
            u0, u1, u2, _, _, _ = unit_twist(rot, pos, axis, e, node)
            along = direction[0] * u0 + direction[1] * u1 + direction[2] * u2
            for j in range(jn.shape[0]):
                jn[j] += node_t[e, j] * along
        e = parent[e]
    return x
