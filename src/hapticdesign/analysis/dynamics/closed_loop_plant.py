"""A compiled closed-loop plant: H, C(q, qd) qd and G in actuated coordinates, pose after pose (seed 000 eq. 2.44-2.50).

A closed-loop device has no exact basis tables (:mod:`hapticdesign.simulation.tables`): its equations of
motion in the actuated coordinates ``tau_a = H_a qdd_a + c_a(q_a, qd_a) + G_a`` come from the loop-opened
tree reduced by ``T = [I; S]`` (:mod:`.actuated_kernel`), at the passive values that close the loops.
:func:`closed_loop_terms` gives them inside numba for one parameter set, at one actuated pose and rate:

- the passive values follow by the continuation step (:func:`hapticdesign.analysis.loops.closure_kernel.correct`)
  from a tangent predictor ``q_p + S dq_a`` at the last pose solved, which the workspace carries (a
  fixed-step integrator moves little between calls, so one or two Newton iterations close the loops);
- ``H_a`` (n_a x n_a, with the constant reflected rotor inertia), ``c_a = C(q, qd) qd^2`` (the velocity
  terms for the given rates, one tree pass instead of the ``n_a (n_a + 1) / 2`` of eq. 2.50's columns)
  and ``G_a``;
- a status: ``OK``, ``NO_CLOSURE`` (Newton fails, or its correction exceeds half the actuated step: it
  jumped), ``SINGULAR`` (``Phi_p`` singular) or ``BRANCH_CHANGE`` (``det Phi_p`` changed sign). On any
  failure the outputs are left as they were and the workspace keeps the last closed pose.

:class:`ClosedLoopPlant` builds the records (:class:`PlantStructure`, :class:`PlantWorkspace`) from a
:class:`~.closed_loop.ClosedLoopModel` and starts on the assembly branch at a given actuated pose.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from hapticdesign.analysis.dynamics.actuated_kernel import (
    Bodies,
    active_bodies,
    body_wrench,
    mass_and_gravity,
    reduce_pose,
    velocity_state,
    world_parameters,
)
from hapticdesign.analysis.dynamics.closed_loop import ClosedLoopModel
from hapticdesign.analysis.loops import closure_kernel as ck
from hapticdesign.analysis.loops.records import ClosureScratch, Closures, Settings, closure_scratch
from hapticdesign.analysis.loops.solver import MESSAGES
from hapticdesign.errors import UserError
from hapticdesign.model.walk import CONSTANT, Tree, WalkPlan, planned_poses, unit_twist

OK, NO_CLOSURE, SINGULAR, BRANCH_CHANGE = ck.OK, ck.NO_CLOSURE, ck.SINGULAR, ck.BRANCH_CHANGE


class PlantStructure(NamedTuple):
    """What :func:`closed_loop_terms` reads: the loop records of the model's solver, its bodies, the branch
    (sign of ``det Phi_p``), one parameter set ``params`` (1, 10 B), the bodies it moves ``active`` (B,) and
    the constant inertia added to ``H_a`` (n_a x n_a, the reflected rotor inertia)."""

    tree: Tree
    plan: WalkPlan
    bodies: Bodies
    loops: Closures
    settings: Settings
    branch: float
    params: np.ndarray
    active: np.ndarray
    constant: np.ndarray


class PlantWorkspace(NamedTuple):
    """Scratch of :func:`closed_loop_terms`: the kernels' :class:`~hapticdesign.analysis.loops.records.ClosureScratch`,
    the warm start ``q`` (full coordinates of the last closed pose), ``q_last`` a copy to fall back to and the
    world parameters ``pw`` (1, B, 10)."""

    kernel: ClosureScratch
    q: np.ndarray
    q_last: np.ndarray
    pw: np.ndarray


def plant_workspace(n_node: int, n_dof: int, na: int, passive: np.ndarray, n_body: int) -> PlantWorkspace:
    """A zeroed :class:`PlantWorkspace`."""
    return PlantWorkspace(closure_scratch(n_node, n_dof, na, passive, n_body), np.zeros(n_dof), np.zeros(n_dof),
                          np.zeros((1, n_body, 10)))


@njit(cache=True, _nrt=False)
def closed_loop_terms(qa, qda, structure, ws, h, cqd, g):
    """``H_a`` (n_a x n_a), ``c_a = C(q, qd) qd^2`` (n_a) and ``G_a`` (n_a) at actuated ``qa``, rates ``qda``.

    ``structure``: :class:`PlantStructure`; ``ws``: :class:`PlantWorkspace`. Returns the status (module
    docstring).
    """
    tree, plan, bodies, loops = structure.tree, structure.plan, structure.bodies, structure.loops
    params, active, constant = structure.params, structure.active, structure.constant
    dyn, q, q_last, pw = ws.kernel, ws.q, ws.q_last, ws.pw
    w, al, ac, t, ja = dyn.w, dyn.al, dyn.ac, dyn.t, dyn.ja
    actuated, passive = loops.actuated, loops.passive
    body_node = bodies.body_node
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
    status = ck.correct(q, tree, plan, loops, structure.settings, dyn, structure.branch, 0.5 * dist)
    if status != OK:
        for k in range(q.shape[0]):
            q[k] = q_last[k]
        return status
    # Newton left Phi, Phi_p^-1 and the closures' node poses at q: the other nodes complete factor_pose
    planned_poses(q, tree, plan, plan.n_first, tree.parent.shape[0], dyn.rot, dyn.pos, dyn.trig)
    reduce_pose(tree, plan, body_node, loops, dyn)
    world_parameters(dyn.rot, body_node, params, np.int64(0), pw)  # a literal would compile its own copy
    for i in range(na):
        g[i] = 0.0
        cqd[i] = 0.0
        for j in range(na):
            h[i, j] = constant[i, j]
    for b in range(body_node.shape[0]):
        if active[b] and body_node[b] >= 0:
            mass_and_gravity(ja, b, bodies.gravity, pw, np.int64(0), h, g, h, np.bool_(False))
    velocity_state(qda, np.int64(-1), np.int64(-1), tree.axis, plan, bodies.motion, loops, dyn)
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
        solver, tree = model.solver, model.compiled.tree
        params = np.ascontiguousarray(np.atleast_2d(model._params(pi)), dtype=float)
        if params.shape[0] != 1:
            raise UserError("a plant takes one set of standard inertial parameters")
        n = model.n_dof
        constant = np.zeros((n, n))
        if model.constant is not None:
            iu, ju = np.triu_indices(n)
            constant[iu, ju] = constant[ju, iu] = model.constant[model.slice_h]
        self.n_dof = n
        self.structure = PlantStructure(
            tree=solver.tree, plan=solver.plan, bodies=model.bodies, loops=solver.closures, settings=solver.settings,
            branch=float(solver.branch), params=params, active=active_bodies(params), constant=constant,
        )
        self.workspace = plant_workspace(len(tree.parent), solver.n_dof, n, solver.closures.passive,
                                         len(tree.body_node))
        self.workspace.q[:] = solver.solve(q_a0)
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
        return self.workspace.q.copy()


@njit(cache=True)
def handle_along(ws, parent, axis, node, direction, jn, want_jn):
    """At the last closed pose of a :func:`plant_workspace`: the position of node ``node`` (the handle) along
    the unit ``direction`` n, ``n . p``, and, when ``want_jn``, into ``jn`` (n_a) its velocity along n per
    actuated rate, ``J_n = n^T J_v T`` (seed 000 eq. 2.24-2.26 on the loop-opened tree, reduced by ``T``).

    ``J_v T`` is summed over the variable nodes from the handle to the base with each node's joint-value rate
    per actuated rate (``coef T``, which :func:`closed_loop_terms` leaves in the workspace)."""
    rot, pos, node_t = ws.kernel.rot, ws.kernel.pos, ws.kernel.node_t
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
