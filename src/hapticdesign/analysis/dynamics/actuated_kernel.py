"""Compiled (numba) kernel: H, C, G of a closed-loop mechanism in its actuated coordinates.

On the loop-opened tree (all joints are coordinates ``q``, seed 000 eq. 2.44-2.50) the passive rates
follow the actuated ones, ``qd = T qd_a`` with ``T = [I; S]``, ``S = -Phi_p^-1 Phi_a``
(:mod:`hapticdesign.analysis.loops`). The virtual power of the tree's generalized forces
(d'Alembert) on the admissible motions gives the reduced equations ``T^T (H qdd + c(q, qd) + G) = tau_a``
with ``qdd = T qdd_a + [0; gamma]`` and ``gamma = -Phi_p^-1 (Phidot qd)``:

- ``H_a = T^T H T = sum_b (J_b T)^T M_b (J_b T)`` with ``J_b T`` the reduced Jacobian of body ``b``'s
  origin and ``M_b [v; w] = [m v + w x h; h x v + J w]`` its spatial inertia about that origin (eq. 2.44);
- ``G_a = T^T G``: the weight ``-g (m, m c)`` projected likewise (eq. 2.46);
- the velocity terms ``T^T (H [0; gamma] + c(q, T qd_a))`` (``T^T (H Tdot + C-terms T)``): per body the
  Newton-Euler wrench ``f = m a + al x h + w x (w x h)``, ``n = J al + w x (J w) + h x a`` at the body
  velocities of ``qd = T qd_a`` and accelerations of ``qdd = [0; gamma]`` (the node motions at ``qdd = 0``
  plus those of the passive joints' accelerations ``gamma``), projected by ``(J_b T)^T``.
  It is a quadratic form in ``qd_a``; its coefficients (the columns of eq. 2.50's ``C``: ``Gamma_ijj``
  and ``2 Gamma_ijk``) follow by polarization from ``n_a (n_a + 1) / 2`` rate vectors ``e_j`` and
  ``e_j + e_k``. The part of ``gamma`` is linear in it: ``T^T H [0; gamma] = hap gamma`` with the inertia
  coupling ``hap = sum_b (J_b T)^T M_b J_b,p`` (``J_b,p`` the passive coordinates' columns of the body
  Jacobian), so that the entries take one tree pass per rate vector (the node motions at ``qdd = 0``, whose
  closure bias gives ``gamma``) and ``hap`` once per pose.

Everything is linear in the standard inertial parameters ``(m, h, J)``: :func:`actuated_regressor`
returns the regressor (ten columns per body, in body axes, via :func:`.kernel.body_regressor`), entry
by entry in :class:`.model.DynamicsModel`'s order, from the body motions of both passes
(:func:`velocity_state`); :func:`actuated_entries` evaluates the entries for given parameter sets
directly (:func:`pose_entries`), in world axes (each body's ``h`` and ``J`` rotated once per pose), and
skips bodies whose parameters are all zero; :func:`motion_entries` does the same along a motion, each
pose continued from the last inside the kernel. They share :func:`factor_pose` (poses and ``Phi_p^-1``)
and :func:`reduce_pose` (``T`` and the reduced Jacobians at one closed pose), which allocate nothing:
their scratch arrays come from a :class:`~hapticdesign.analysis.loops.records.ClosureScratch`. The closed-loop
plant of the simulation (:mod:`.closed_loop_plant`) calls them too.

Besides the loop records (``tree``, ``plan``, ``loops``, ``settings``, ``ws``:
:mod:`hapticdesign.analysis.loops.closure_kernel`), the kernels take the :class:`Bodies` record: the
bodies' nodes, gravity, the :class:`~hapticdesign.model.walk.MotionPlan` of the velocity sweeps and
per body the nodes the passive coordinates move (:func:`passive_paths`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from hapticdesign.analysis.dynamics.kernel import body_regressor
from hapticdesign.analysis.loops.closure_kernel import (
    OK,
    closure_bias,
    closure_jacobian,
    continue_to,
    correct,
    rotation_entry,
    tangent_into,
)
from hapticdesign.analysis.loops.records import ClosureScratch, closure_scratch
from hapticdesign.model.dense import lu_in_place
from hapticdesign.model.walk import MotionPlan, add_joint_accelerations, node_motion, planned_poses, unit_twist


class Bodies(NamedTuple):
    """The bodies of a closed-loop mechanism for the compiled entries: the node each is attached to, gravity,
    the :class:`~hapticdesign.model.walk.MotionPlan` of the nodes the bodies and closures need, and per body
    the nodes from its node to the base that a passive coordinate moves, body ``b``'s being
    ``path_nodes[path_ptr[b]:path_ptr[b + 1]]`` (:func:`passive_paths`)."""

    body_node: np.ndarray
    gravity: np.ndarray
    motion: MotionPlan
    path_ptr: np.ndarray
    path_nodes: np.ndarray


class MotionWork(NamedTuple):
    """Scratch of :func:`motion_entries_into`: the bodies the parameter sets move (:func:`active_bodies`), the
    entries' workspace and scratch, the last pose ``q_last``, the
    closures' bias and half the passive accelerations of a step, and for a pose handed to the continuation
    (:func:`~hapticdesign.analysis.loops.closure_kernel.continue_to`) its own workspace ``fallback``, tangent
    ``s``, ``start`` and ``trial``."""

    active: np.ndarray
    ws: ClosureScratch
    scratch: "EntriesScratch"
    q_last: np.ndarray
    bias: np.ndarray
    half_gamma: np.ndarray
    fallback: ClosureScratch
    s: np.ndarray
    start: np.ndarray
    trial: np.ndarray


class EntriesScratch(NamedTuple):
    """Scratch of :func:`pose_entries`: world parameters per set ``pw``, ``H_a`` per set ``h``, the passive
    inertia coupling ``hap`` and ``kmat = -hap Phi_p^-1`` per set, ``mj = M (J_b T)``, the closures' bias of
    each rate vector of the polarization ``biases`` and no rate vector ``empty`` (:func:`motion_state` takes
    the unit ones)."""

    pw: np.ndarray
    h: np.ndarray
    hap: np.ndarray
    kmat: np.ndarray
    mj: np.ndarray
    biases: np.ndarray
    empty: np.ndarray


@njit(cache=True)
def _wrench_regressor(w, al, acc, out):
    """Body-axis wrench ``[f; n]`` (6 x 10) about the body origin per standard parameter (m, h, J).

    ``f = m acc + al x h + w x (w x h)``, ``n = J al + w x (J w) + h x acc``; no allocation (inner loop).
    """
    w0, w1, w2 = w[0], w[1], w[2]
    l0, l1, l2 = al[0], al[1], al[2]
    a0, a1, a2 = acc[0], acc[1], acc[2]
    # m
    out[0, 0], out[1, 0], out[2, 0] = a0, a1, a2
    out[3, 0] = out[4, 0] = out[5, 0] = 0.0
    # h = e_x, e_y, e_z: f = al x e + w (w . e) - e |w|^2, n = e x acc
    ww = w0 * w0 + w1 * w1 + w2 * w2
    out[0, 1], out[1, 1], out[2, 1] = w0 * w0 - ww, l2 + w1 * w0, -l1 + w2 * w0
    out[3, 1], out[4, 1], out[5, 1] = 0.0, -a2, a1
    out[0, 2], out[1, 2], out[2, 2] = -l2 + w0 * w1, w1 * w1 - ww, l0 + w2 * w1
    out[3, 2], out[4, 2], out[5, 2] = a2, 0.0, -a0
    out[0, 3], out[1, 3], out[2, 3] = l1 + w0 * w2, -l0 + w1 * w2, w2 * w2 - ww
    out[3, 3], out[4, 3], out[5, 3] = -a1, a0, 0.0
    # J entries: n = J al + w x (J w), J = E_c (symmetric unit pattern)
    for c in range(6):
        for r in range(3):
            out[r, 4 + c] = 0.0
    # Jxx: J al = (l0, 0, 0), J w = (w0, 0, 0): w x = (0, w2 w0, -w1 w0)
    out[3, 4], out[4, 4], out[5, 4] = l0, w2 * w0, -w1 * w0
    # Jyy: (0, l1, 0); w x (0, w1, 0) = (-w2 w1, 0, w0 w1)
    out[3, 5], out[4, 5], out[5, 5] = -w2 * w1, l1, w0 * w1
    # Jzz: (0, 0, l2); w x (0, 0, w2) = (w1 w2, -w0 w2, 0)
    out[3, 6], out[4, 6], out[5, 6] = w1 * w2, -w0 * w2, l2
    # Jxy: J al = (l1, l0, 0), J w = (w1, w0, 0): w x = (-w2 w0, w2 w1, w0 w0 - w1 w1)
    out[3, 7], out[4, 7], out[5, 7] = l1 - w2 * w0, l0 + w2 * w1, w0 * w0 - w1 * w1
    # Jxz: J al = (l2, 0, l0), J w = (w2, 0, w0): w x = (w1 w0, w2 w2 - w0 w0, -w1 w2)
    out[3, 8], out[4, 8], out[5, 8] = l2 + w1 * w0, w2 * w2 - w0 * w0, l0 - w1 * w2
    # Jyz: J al = (0, l2, l1), J w = (0, w2, w1): w x = (w1 w1 - w2 w2, -w0 w1, w0 w2)
    out[3, 9], out[4, 9], out[5, 9] = w1 * w1 - w2 * w2, l2 - w0 * w1, l1 + w0 * w2


@njit(cache=True, _nrt=False, forceinline=True)
def factor_pose(q, tree, plan, loops, ws):
    """Every node's pose, ``Phi`` and ``Phi_p^-1`` at a closed full pose ``q`` into ``ws`` (for :func:`reduce_pose`).

    Returns the pivot ratio of ``Phi_p`` (0: singular) and the sign of its determinant. After Newton
    (:func:`hapticdesign.analysis.loops.closure_kernel.newton_into`), which leaves ``Phi``, ``Phi_p^-1``
    and the poses of the plan's first part, a walk of the other nodes does the same.
    """
    rot, pos, phi, lu, pinv = ws.rot, ws.pos, ws.phi, ws.lu, ws.pinv
    passive = loops.passive
    npas = passive.shape[0]
    planned_poses(q, tree, plan, np.int64(0), tree.parent.shape[0], rot, pos, ws.trig)  # a literal would compile its own copy
    closure_jacobian(loops, tree, plan, rot, pos, phi)
    for i in range(npas):
        for j in range(npas):
            lu[i, j] = phi[i, passive[j]]
            pinv[i, j] = 1.0 if i == j else 0.0
    return lu_in_place(lu, pinv)


@njit(cache=True, _nrt=False, forceinline=True)
def reduce_pose(tree, plan, body_node, loops, ws):
    """``T = [I; S]``, ``coef T`` and every body's Jacobian ``J_b T`` into ``ws``, from its node poses, ``Phi`` and
    ``Phi_p^-1`` at a closed pose (:func:`factor_pose`).

    A body Jacobian column is the unit twist of a variable node on the path from the body to the base
    (constant nodes carry none) at the body origin: ``(u x (p_b - p_e), u)`` for a rotation, ``(u, 0)`` for a
    translation (seed 000 eq. 2.20-2.26), weighted by the node's joint-value rates ``coef T`` (the plan's
    sparse coupling coefficients).
    """
    rot, pos, phi, pinv, t, node_t, ja = ws.rot, ws.pos, ws.phi, ws.pinv, ws.t, ws.node_t, ws.ja
    parent, axis = tree.parent, tree.axis
    ptr, index, value = plan.ptr, plan.index, plan.value
    actuated, passive = loops.actuated, loops.passive
    na = actuated.shape[0]
    npas = passive.shape[0]
    n_node = parent.shape[0]
    for j in range(na):
        for i in range(na):
            t[actuated[i], j] = 1.0 if i == j else 0.0
    for r in range(npas):
        for j in range(na):
            acc = 0.0
            for i in range(npas):
                acc -= pinv[r, i] * phi[i, actuated[j]]
            t[passive[r], j] = acc
    for n in range(n_node):
        for j in range(na):
            node_t[n, j] = 0.0
        for k in range(ptr[n], ptr[n + 1]):
            c = value[k]
            for j in range(na):
                node_t[n, j] += c * t[index[k], j]
    for b in range(body_node.shape[0]):
        nb = body_node[b]
        for r in range(6):
            for j in range(na):
                ja[b, r, j] = 0.0
        e = nb
        while e >= 0:
            if ptr[e] == ptr[e + 1]:  # no coordinate moves this node (constant): no column
                e = parent[e]
                continue
            v0, v1, v2, w0, w1, w2 = unit_twist(rot, pos, axis, e, nb)
            for j in range(na):
                c = node_t[e, j]
                ja[b, 0, j] += c * v0
                ja[b, 1, j] += c * v1
                ja[b, 2, j] += c * v2
                ja[b, 3, j] += c * w0
                ja[b, 4, j] += c * w1
                ja[b, 5, j] += c * w2
            e = parent[e]


@njit(cache=True, _nrt=False, forceinline=True)
def motion_state(qd_a, j, k, axis, motion, loops, ws):
    """Node motions at ``qd = T qd_a`` and ``qdd = 0`` and the closures' bias ``Phidot qd`` (:func:`closure_bias`)
    into ``ws``.

    ``j >= 0`` takes the rate vector ``e_j`` (plus ``e_k`` when ``k != j``) instead of ``qd_a``; ``motion``:
    a :class:`~hapticdesign.model.walk.MotionPlan` that keeps the bodies' and the closures' nodes.
    """
    node_t, rate = ws.node_t, ws.rate
    order = motion.order
    for i in range(order.shape[0]):
        n = order[i]
        if j >= 0:
            rate[n] = node_t[n, j] + (node_t[n, k] if k != j else 0.0)
        else:
            acc = 0.0
            for c in range(qd_a.shape[0]):
                acc += node_t[n, c] * qd_a[c]
            rate[n] = acc
    node_motion(rate, motion, axis, ws.rot, ws.pos, ws.w, ws.al, ws.ac)
    closure_bias(loops, ws.al, ws.ac, ws.bias)


@njit(cache=True, _nrt=False, forceinline=True)
def velocity_state(qd_a, j, k, axis, plan, motion, loops, ws):
    """Node motions at ``qd = T qd_a`` and ``qdd = [0; gamma]``, ``gamma = -Phi_p^-1 (Phidot qd)``, into ``ws``.

    The node motions at ``qdd = 0`` (:func:`motion_state`, same arguments) give ``Phidot qd``; the passive
    joints' accelerations ``gamma`` then add theirs (:func:`add_joint_accelerations`, joint values'
    accelerations ``coef [0; gamma]``).
    """
    pinv, rate, bias, gamma, slot = ws.pinv, ws.rate, ws.bias, ws.gamma, ws.slot
    ptr, index, value = plan.ptr, plan.index, plan.value
    order = motion.order
    npas = loops.passive.shape[0]
    motion_state(qd_a, j, k, axis, motion, loops, ws)
    for r in range(npas):
        acc = 0.0
        for i in range(npas):
            acc -= pinv[r, i] * bias[i]
        gamma[r] = acc
    for i in range(order.shape[0]):
        n = order[i]
        acc = 0.0
        for c in range(ptr[n], ptr[n + 1]):
            r = slot[index[c]]
            if r >= 0:
                acc += value[c] * gamma[r]
        rate[n] = acc
    add_joint_accelerations(rate, motion, axis, ws.rot, ws.pos, ws.al, ws.ac, ws.dal, ws.dac)


@njit(cache=True)
def world_parameters(rot, body_node, params, s, out):
    """Parameter set ``s`` (10 B) in world axes at the current poses: ``out[s, b] = (m, R h, R J R^T)``.

    The inertia ``J`` (about the body origin) is stored as ``Jxx, Jyy, Jzz, Jxy, Jxz, Jyz``; a body on the
    base keeps its parameters.
    """
    for b in range(body_node.shape[0]):
        nb = body_node[b]
        c = 10 * b
        if nb < 0:
            for i in range(10):
                out[s, b, i] = params[s, c + i]
            continue
        r = rot[nb]
        out[s, b, 0] = params[s, c]
        h0, h1, h2 = params[s, c + 1], params[s, c + 2], params[s, c + 3]
        for i in range(3):
            out[s, b, 1 + i] = r[i, 0] * h0 + r[i, 1] * h1 + r[i, 2] * h2
        jxx, jyy, jzz = params[s, c + 4], params[s, c + 5], params[s, c + 6]
        jxy, jxz, jyz = params[s, c + 7], params[s, c + 8], params[s, c + 9]
        # rows of R J
        a00 = r[0, 0] * jxx + r[0, 1] * jxy + r[0, 2] * jxz
        a01 = r[0, 0] * jxy + r[0, 1] * jyy + r[0, 2] * jyz
        a02 = r[0, 0] * jxz + r[0, 1] * jyz + r[0, 2] * jzz
        a10 = r[1, 0] * jxx + r[1, 1] * jxy + r[1, 2] * jxz
        a11 = r[1, 0] * jxy + r[1, 1] * jyy + r[1, 2] * jyz
        a12 = r[1, 0] * jxz + r[1, 1] * jyz + r[1, 2] * jzz
        a20 = r[2, 0] * jxx + r[2, 1] * jxy + r[2, 2] * jxz
        a21 = r[2, 0] * jxy + r[2, 1] * jyy + r[2, 2] * jyz
        a22 = r[2, 0] * jxz + r[2, 1] * jyz + r[2, 2] * jzz
        out[s, b, 4] = a00 * r[0, 0] + a01 * r[0, 1] + a02 * r[0, 2]
        out[s, b, 5] = a10 * r[1, 0] + a11 * r[1, 1] + a12 * r[1, 2]
        out[s, b, 6] = a20 * r[2, 0] + a21 * r[2, 1] + a22 * r[2, 2]
        out[s, b, 7] = a00 * r[1, 0] + a01 * r[1, 1] + a02 * r[1, 2]
        out[s, b, 8] = a00 * r[2, 0] + a01 * r[2, 1] + a02 * r[2, 2]
        out[s, b, 9] = a10 * r[2, 0] + a11 * r[2, 1] + a12 * r[2, 2]


@njit(cache=True, inline="always")
def body_wrench(w, al, ac, nb, pw, s, b):
    """World wrench ``[f; n]`` about body ``b``'s origin (node ``nb``) from the node's ``(w, al, acc)``, world
    parameters ``pw[s, b]``: ``f = m acc + al x h + w x (w x h)``, ``n = J al + w x (J w) + h x acc``."""
    w0, w1, w2 = w[nb, 0], w[nb, 1], w[nb, 2]
    l0, l1, l2 = al[nb, 0], al[nb, 1], al[nb, 2]
    a0, a1, a2 = ac[nb, 0], ac[nb, 1], ac[nb, 2]
    m, h0, h1, h2 = pw[s, b, 0], pw[s, b, 1], pw[s, b, 2], pw[s, b, 3]
    jxx, jyy, jzz, jxy, jxz, jyz = pw[s, b, 4], pw[s, b, 5], pw[s, b, 6], pw[s, b, 7], pw[s, b, 8], pw[s, b, 9]
    x0, x1, x2 = w1 * h2 - w2 * h1, w2 * h0 - w0 * h2, w0 * h1 - w1 * h0
    f0 = m * a0 + l1 * h2 - l2 * h1 + w1 * x2 - w2 * x1
    f1 = m * a1 + l2 * h0 - l0 * h2 + w2 * x0 - w0 * x2
    f2 = m * a2 + l0 * h1 - l1 * h0 + w0 * x1 - w1 * x0
    jw0 = jxx * w0 + jxy * w1 + jxz * w2
    jw1 = jxy * w0 + jyy * w1 + jyz * w2
    jw2 = jxz * w0 + jyz * w1 + jzz * w2
    n0 = jxx * l0 + jxy * l1 + jxz * l2 + w1 * jw2 - w2 * jw1 + h1 * a2 - h2 * a1
    n1 = jxy * l0 + jyy * l1 + jyz * l2 + w2 * jw0 - w0 * jw2 + h2 * a0 - h0 * a2
    n2 = jxz * l0 + jyz * l1 + jzz * l2 + w0 * jw1 - w1 * jw0 + h0 * a1 - h1 * a0
    return f0, f1, f2, n0, n1, n2


@njit(cache=True, _nrt=False, forceinline=True)
def mass_and_gravity(ja, b, gravity, pw, s, h, g, mj, keep):
    """Add body ``b``'s ``(J_b T)^T M (J_b T)`` to ``h`` (n x n) and ``-(J_b T)^T`` of its weight's wrench to
    ``g`` (eq. 2.44, 2.46), world parameters ``pw[s, b]``: ``M [v; w] = [m v + w x h; h x v + J w]``.
    With ``keep`` (a constant of the caller), ``mj`` (6 x n) receives ``M (J_b T)``; without, it is not touched."""
    m, h0, h1, h2 = pw[s, b, 0], pw[s, b, 1], pw[s, b, 2], pw[s, b, 3]
    jxx, jyy, jzz, jxy, jxz, jyz = pw[s, b, 4], pw[s, b, 5], pw[s, b, 6], pw[s, b, 7], pw[s, b, 8], pw[s, b, 9]
    for j in range(ja.shape[2]):
        v0, v1, v2 = ja[b, 0, j], ja[b, 1, j], ja[b, 2, j]
        w0, w1, w2 = ja[b, 3, j], ja[b, 4, j], ja[b, 5, j]
        mv0 = m * v0 + w1 * h2 - w2 * h1
        mv1 = m * v1 + w2 * h0 - w0 * h2
        mv2 = m * v2 + w0 * h1 - w1 * h0
        mw0 = h1 * v2 - h2 * v1 + jxx * w0 + jxy * w1 + jxz * w2
        mw1 = h2 * v0 - h0 * v2 + jxy * w0 + jyy * w1 + jyz * w2
        mw2 = h0 * v1 - h1 * v0 + jxz * w0 + jyz * w1 + jzz * w2
        if keep:
            mj[0, j], mj[1, j], mj[2, j], mj[3, j], mj[4, j], mj[5, j] = mv0, mv1, mv2, mw0, mw1, mw2
        g[j] -= gravity[0] * mv0 + gravity[1] * mv1 + gravity[2] * mv2
        for i in range(j + 1):
            e = (ja[b, 0, i] * mv0 + ja[b, 1, i] * mv1 + ja[b, 2, i] * mv2
                 + ja[b, 3, i] * mw0 + ja[b, 4, i] * mw1 + ja[b, 5, i] * mw2)
            h[i, j] += e
            if i != j:
                h[j, i] += e


class PoseDynamics(NamedTuple):
    """Scratch of one pose's ``H`` and ``G`` in the actuated coordinates (:func:`pose_terms`): the closed-loop
    kernels' ``closure`` scratch, the bodies' parameters in the world frame ``world`` (1, B, 10), ``h`` (n_a, n_a),
    ``g`` (n_a,) and one body's ``mj`` (6, n_a)."""

    closure: ClosureScratch
    world: np.ndarray
    h: np.ndarray
    g: np.ndarray
    mj: np.ndarray


@njit(cache=True)
def pose_dynamics(n_node: int, loops, bodies, n: int) -> PoseDynamics:
    """A zeroed :class:`PoseDynamics` for a tree of ``n_node`` nodes and ``n`` coordinates (its number of nodes, not
    the tree: one device's tree and a design batch's shape are records of different types)."""
    na = loops.actuated.shape[0]
    n_body = bodies.body_node.shape[0]
    return PoseDynamics(closure_scratch(n_node, n, na, loops.passive, n_body),
                        np.zeros((1, n_body, 10)), np.zeros((na, na)), np.zeros(na), np.zeros((6, na)))


@njit(cache=True, _nrt=False)
def pose_terms(q, tree, plan, bodies, loops, sets, s):
    """``H`` and ``G`` in the actuated coordinates at the full pose ``q`` into ``s.h`` and ``s.g`` (eq. 2.44: ``sum_b
    (J_b T)^T M_b (J_b T)``; eq. 2.46) for the parameter set ``sets[0]``, ``T`` of the pose left in ``s.closure.t``;
    returns the pivot ratio of ``Phi_p`` (0: singular; 1 for a tree). The same arithmetic as :func:`pose_entries`'
    H and G, without the velocity terms; allocates nothing."""
    ws, body_node = s.closure, bodies.body_node
    ratio = 1.0
    if loops.passive.shape[0] > 0:
        ratio, _ = factor_pose(q, tree, plan, loops, ws)
    else:
        planned_poses(q, tree, plan, np.int64(0), tree.parent.shape[0], ws.rot, ws.pos, ws.trig)
    reduce_pose(tree, plan, body_node, loops, ws)
    world_parameters(ws.rot, body_node, sets, np.int64(0), s.world)
    for i in range(s.h.shape[0]):
        s.g[i] = 0.0
        for j in range(s.h.shape[1]):
            s.h[i, j] = 0.0
    for b in range(body_node.shape[0]):
        if body_node[b] >= 0:
            mass_and_gravity(ws.ja, b, bodies.gravity, s.world, np.int64(0), s.h, s.g, s.mj, np.bool_(False))
    return ratio


@njit(cache=True, _nrt=False)
def terms_into(qs, tree, plan, bodies, loops, sets, s, h, g, ratios):
    """``H`` and ``G`` (:func:`pose_terms`) at the closed full poses ``qs`` (P, N) into ``h`` (P, n_a, n_a) and ``g``
    (P, n_a), the pivot ratio of ``Phi_p`` per pose into ``ratios`` (P,); ``s``: :func:`pose_dynamics`. It
    allocates nothing, so it is compiled without reference counting. One device's ``H`` and ``G`` at given poses
    (:meth:`~hapticdesign.analysis.dynamics.closed_loop.ClosedLoopModel.terms_at`) and a design batch's ``H``
    (:func:`~hapticdesign.analysis.design_batch.mass_designs`) share it."""
    for p in range(qs.shape[0]):
        ratios[p] = pose_terms(qs[p], tree, plan, bodies, loops, sets, s)
        for i in range(s.h.shape[0]):
            g[p, i] = s.g[i]
            for j in range(s.h.shape[1]):
                h[p, i, j] = s.h[i, j]


def passive_paths(parent: np.ndarray, plan, body_node: np.ndarray, passive: np.ndarray) -> tuple:
    """Per body, the nodes from its node to the base that a passive coordinate moves: ``(ptr, nodes)``, body
    ``b``'s being ``nodes[ptr[b]:ptr[b + 1]]`` (what :func:`passive_inertia` walks). ``plan``: the loop
    solver's :class:`~hapticdesign.model.walk.WalkPlan` (its sparse coupling coefficients)."""
    ptr, index = plan.ptr, plan.index
    moving = {int(k) for k in passive}
    counts, nodes = [0], []
    for nb in body_node:
        e = int(nb)
        while e >= 0:
            if moving.intersection(int(k) for k in index[ptr[e]:ptr[e + 1]]):
                nodes.append(e)
            e = int(parent[e])
        counts.append(len(nodes))
    return np.array(counts, dtype=np.int64), np.array(nodes, dtype=np.int64)


@njit(cache=True, inline="always")
def passive_inertia(b, bodies, axis, plan, slot, rot, pos, mj, hap):
    """Add body ``b``'s ``(J_b T)^T M J_b,p`` to ``hap`` (n_a x n_p), from ``mj = M (J_b T)`` (:func:`mass_and_gravity`;
    the passive columns of eq. 2.44's ``J^T M J``).

    ``J_b,p``: the passive coordinates' columns of the Jacobian of the body origin on the loop-opened tree,
    the unit twists of the nodes they move (``bodies``' paths: :func:`passive_paths`; as in :func:`reduce_pose`),
    weighted by their coupling coefficients. ``hap`` is the inertia coupling of the actuated motions to the
    passive joints' accelerations: ``T^T H [0; gamma] = hap gamma``.
    """
    ptr, index, value = plan.ptr, plan.index, plan.value
    first, nodes = bodies.path_ptr, bodies.path_nodes
    nb = bodies.body_node[b]
    for c in range(first[b], first[b + 1]):
        e = nodes[c]
        v0, v1, v2, w0, w1, w2 = unit_twist(rot, pos, axis, e, nb)
        for i in range(mj.shape[1]):
            d = mj[0, i] * v0 + mj[1, i] * v1 + mj[2, i] * v2 + mj[3, i] * w0 + mj[4, i] * w1 + mj[5, i] * w2
            for k in range(ptr[e], ptr[e + 1]):
                r = slot[index[k]]
                if r >= 0:
                    hap[i, r] += value[k] * d


@njit(cache=True)
def active_bodies(params):
    """Bodies with a non-zero parameter in some set (the others add nothing)."""
    n_body = params.shape[1] // 10
    out = np.zeros(n_body, dtype=np.bool_)
    for b in range(n_body):
        for s in range(params.shape[0]):
            for c in range(10):
                if params[s, 10 * b + c] != 0.0:
                    out[b] = True
    return out


@njit(cache=True)
def _state(j, na):
    """Index of the rate vector ``e_j`` among the states (j, k), j <= k, in order."""
    return j * na - j * (j - 1) // 2


@njit(cache=True)
def entries_scratch(n_sets, na, npas, n_body):
    """A zeroed :class:`EntriesScratch`."""
    return EntriesScratch(np.zeros((n_sets, n_body, 10)), np.zeros((n_sets, na, na)), np.zeros((n_sets, na, npas)),
                          np.zeros((n_sets, na, npas)), np.zeros((6, na)), np.zeros((na * (na + 1) // 2, npas)),
                          np.zeros(0))


@njit(cache=True, _nrt=False, forceinline=True)
def pose_entries(tree, plan, bodies, loops, params, active, ws, scratch, out):
    """Entries (unique H, C, G, eq. 2.44-2.50) at a closed pose whose node poses, ``Phi`` and ``Phi_p^-1`` are in
    ``ws``, for the parameter sets ``params`` (K, 10 B), added into ``out`` (K, E) (zero on entry).

    ``scratch``: :func:`entries_scratch`.
    The velocity terms of a rate vector ``e`` are ``T^T c(q, T e) + hap gamma`` with
    ``gamma = -Phi_p^-1 (Phidot T e)``: the body wrenches at the node motions of ``qdd = 0``
    (:func:`motion_state`) and the closures' bias through ``kmat = -hap Phi_p^-1`` (:func:`passive_inertia`),
    one tree pass per rate vector. ``scratch``'s ``biases`` keep each rate vector's ``Phidot T e``.
    """
    axis = tree.axis
    body_node, gravity, motion = bodies.body_node, bodies.gravity, bodies.motion
    actuated, passive = loops.actuated, loops.passive
    pw, h, hap, kmat, mj, biases, empty = (scratch.pw, scratch.h, scratch.hap, scratch.kmat, scratch.mj, scratch.biases,
                                           scratch.empty)
    rot, pos, w, al, ac, pinv, ja, bias, slot = ws.rot, ws.pos, ws.w, ws.al, ws.ac, ws.pinv, ws.ja, ws.bias, ws.slot
    na = actuated.shape[0]
    npas = passive.shape[0]
    n_body = body_node.shape[0]
    n_sets = params.shape[0]
    m = na * (na + 1) // 2
    reduce_pose(tree, plan, body_node, loops, ws)
    h[:] = 0.0
    hap[:] = 0.0
    for s in range(n_sets):
        world_parameters(rot, body_node, params, s, pw)
        g = out[s, m + na * m:]
        for b in range(n_body):
            if active[b] and body_node[b] >= 0:
                mass_and_gravity(ja, b, gravity, pw, s, h[s], g, mj, np.bool_(True))
                passive_inertia(b, bodies, axis, plan, slot, rot, pos, mj, hap[s])
        e = 0
        for i in range(na):
            for j in range(i, na):
                out[s, e] = h[s, i, j]
                e += 1
        for i in range(na):
            for r in range(npas):
                acc = 0.0
                for c in range(npas):
                    acc -= hap[s, i, c] * pinv[c, r]
                kmat[s, i, r] = acc
    st = 0
    for j in range(na):
        for k in range(j, na):
            motion_state(empty, j, k, axis, motion, loops, ws)
            for r in range(npas):
                biases[st, r] = bias[r]
            for s in range(n_sets):
                for i in range(na):
                    acc = 0.0
                    for r in range(npas):
                        acc += kmat[s, i, r] * bias[r]
                    out[s, m + i * m + st] += acc
                for b in range(n_body):
                    nb = body_node[b]
                    if not active[b] or nb < 0:
                        continue
                    f0, f1, f2, n0, n1, n2 = body_wrench(w, al, ac, nb, pw, s, b)
                    for i in range(na):
                        out[s, m + i * m + st] += (ja[b, 0, i] * f0 + ja[b, 1, i] * f1 + ja[b, 2, i] * f2
                                                   + ja[b, 3, i] * n0 + ja[b, 4, i] * n1 + ja[b, 5, i] * n2)
            st += 1
    # polarization: the state (j, k), j < k, held C(e_j + e_k); the cross term is what exceeds (j, j) + (k, k)
    for s in range(n_sets):
        for i in range(na):
            st = 0
            for j in range(na):
                for k in range(j, na):
                    if k != j:
                        out[s, m + i * m + st] -= out[s, m + i * m + _state(j, na)] + out[s, m + i * m + _state(k, na)]
                    st += 1


@njit(cache=True)
def actuated_entries(qs, tree, plan, bodies, loops, params):
    """Entries (unique H, C, G) in actuated coordinates at closed full poses ``qs`` (P, N) for parameter
    sets ``params`` (K, 10 B): (P, K, E), and the pivot ratio of ``Phi_p`` per pose (0: singular)."""
    n_pose, n_dof = qs.shape
    passive = loops.passive
    na = loops.actuated.shape[0]
    n_body = bodies.body_node.shape[0]
    n_sets = params.shape[0]
    m = na * (na + 1) // 2
    out = np.zeros((n_pose, n_sets, m + na * m + na))
    ratios = np.zeros(n_pose)
    ws = closure_scratch(tree.parent.shape[0], n_dof, na, passive, n_body)
    scratch = entries_scratch(n_sets, na, passive.shape[0], n_body)
    entries_into(qs, tree, plan, bodies, loops, params, active_bodies(params), ws, scratch, out, ratios)
    return out, ratios


@njit(cache=True, _nrt=False)
def entries_into(qs, tree, plan, bodies, loops, params, active, ws, scratch, out, ratios):
    """The pose loop of :func:`actuated_entries` into ``out`` and ``ratios``; it allocates nothing, so it is compiled
    without reference counting (the records' arrays cost no atomic counts per pose)."""
    for p in range(qs.shape[0]):
        ratio, _ = factor_pose(qs[p], tree, plan, loops, ws)
        ratios[p] = ratio
        if ratio != 0.0:
            pose_entries(tree, plan, bodies, loops, params, active, ws, scratch, out[p])


def motion_entries(path, q_start, branch, tree, plan, bodies, loops, settings, params):
    """Entries (unique H, C, G, eq. 2.44-2.50) in actuated coordinates along a motion: the actuated poses
    ``path`` (P, n_a) in order, the passive values continued from the closed full pose ``q_start`` on the
    branch ``branch`` (as :func:`~hapticdesign.analysis.loops.closure_kernel.solve_path`), for parameter sets
    ``params`` (K, 10 B).

    Returns the entries (P, K, E), the per-pose status (OK until the first failure) and
    the index of the first failed pose (-1 if none). From the second pose on, a step within ``max_step`` is
    predicted to second order from the last pose, ``dq_p = S dq_a + gamma / 2`` with
    ``gamma = -Phi_p^-1 (Phidot T dq_a)`` (the passive accelerations of the straight actuated segment, from
    the closures' biases that :func:`pose_entries` kept per rate vector, by polarization; the passive rates
    of eq. 2.38-2.43 and their derivative), and corrected by the continuation step
    (:func:`~hapticdesign.analysis.loops.closure_kernel.correct`, bound half the step), which leaves ``Phi``,
    ``Phi_p^-1`` and the closures' node poses for the entries. A second-order term above half the step or a
    step ``correct`` refuses hands the pose to ``continue_to`` (tangent predictor, step halving), as does the
    first pose.

    A Python function: it only allocates the scratch and calls the compiled pose loop
    (:func:`motion_entries_into`), whose pieces (:func:`active_bodies`, :func:`entries_scratch`,
    :func:`~hapticdesign.analysis.loops.records.closure_scratch`) the closed-loop plant compiles too; compiled, this
    wrapper alone took about 4 CPU-s of a fresh install's first closed-loop run (``benchmarks/bench_cold.py``).
    """
    passive = loops.passive
    n_pose = path.shape[0]
    n_dof = q_start.shape[0]
    na = loops.actuated.shape[0]
    npas = passive.shape[0]
    n_body = bodies.body_node.shape[0]
    n_sets = params.shape[0]
    m = na * (na + 1) // 2
    out = np.zeros((n_pose, n_sets, m + na * m + na))
    status = np.zeros(n_pose, dtype=np.int64)
    n_node = tree.parent.shape[0]
    work = MotionWork(active_bodies(params), closure_scratch(n_node, n_dof, na, passive, n_body),
                      entries_scratch(n_sets, na, npas, n_body), np.empty(n_dof), np.empty(npas), np.empty(npas),
                      closure_scratch(n_node, n_dof, na, passive, 0),
                      np.empty((npas, na)), np.empty(na), np.empty(n_dof))
    q = q_start.copy()
    first = motion_entries_into(path, q, branch, tree, plan, bodies, loops, settings, params, work, out, status)
    return out, status, int(first)


@njit(cache=True, _nrt=False)
def motion_entries_into(path, q, branch, tree, plan, bodies, loops, settings, params, work, out, status):
    """The pose loop of :func:`motion_entries` from the closed full pose ``q`` (in place) into ``out`` and
    ``status``; returns the index of the first failed pose (-1 if none). It allocates nothing, so it is compiled
    without reference counting."""
    actuated, passive = loops.actuated, loops.passive
    n_pose = path.shape[0]
    n_dof = q.shape[0]
    na = actuated.shape[0]
    npas = passive.shape[0]
    active, ws, scratch = work.active, work.ws, work.scratch
    q_last, bias, half_gamma = work.q_last, work.bias, work.half_gamma
    pinv, t, biases = ws.pinv, ws.t, scratch.biases
    for p in range(n_pose):
        dist = 0.0
        for j in range(na):
            dist = max(dist, abs(path[p, j] - q[actuated[j]]))
        fast = p > 0 and dist <= settings.max_step
        if fast:
            for r in range(npas):
                bias[r] = 0.0
            st = 0
            for j in range(na):
                dj = path[p, j] - q[actuated[j]]
                for k in range(j, na):
                    dk = path[p, k] - q[actuated[k]]
                    for r in range(npas):
                        if k == j:
                            bias[r] += dj * dj * biases[st, r]
                        else:
                            bias[r] += dj * dk * (biases[st, r] - biases[_state(j, na), r] - biases[_state(k, na), r])
                    st += 1
            for r in range(npas):
                acc = 0.0
                for i in range(npas):
                    acc -= pinv[r, i] * bias[i]
                half_gamma[r] = 0.5 * acc
                fast = fast and abs(half_gamma[r]) <= 0.5 * dist
        if fast:
            for k in range(n_dof):
                q_last[k] = q[k]
            for j in range(na):
                delta = path[p, j] - q[actuated[j]]
                for r in range(npas):
                    q[passive[r]] += t[passive[r], j] * delta
                q[actuated[j]] = path[p, j]
            for r in range(npas):
                q[passive[r]] += half_gamma[r]
            fast = correct(q, tree, plan, loops, settings, ws, branch, 0.5 * dist) == OK
            if fast:
                planned_poses(q, tree, plan, plan.n_first, tree.parent.shape[0], ws.rot, ws.pos, ws.trig)
            else:
                for k in range(n_dof):
                    q[k] = q_last[k]
        if not fast:
            fresh = work.fallback  # as a new workspace: no angle of its walk anchored yet
            for n in range(fresh.trig.shape[0]):
                fresh.trig[n, 2] = np.nan
            tangent_into(q, tree, plan, loops, fresh, work.s)
            code = continue_to(path[p], q, branch, tree, plan, loops, settings, fresh, work.s, work.start, work.trial)
            if code != OK:
                status[p] = code
                return p
            factor_pose(q, tree, plan, loops, ws)
        pose_entries(tree, plan, bodies, loops, params, active, ws, scratch, out[p])
    return -1




@njit(cache=True, inline="always")
def _body_motion(w, al, ac, nb, rb, out):
    """Body-axis ``(w, al, acc)`` of a body on node ``nb`` (rotation ``rb``) from the node motions into ``out``."""
    if nb < 0:
        for r in range(3):
            for i in range(3):
                out[r, i] = 0.0
        return
    for i in range(3):
        out[0, i] = rb[0, i] * w[nb, 0] + rb[1, i] * w[nb, 1] + rb[2, i] * w[nb, 2]
        out[1, i] = rb[0, i] * al[nb, 0] + rb[1, i] * al[nb, 1] + rb[2, i] * al[nb, 2]
        out[2, i] = rb[0, i] * ac[nb, 0] + rb[1, i] * ac[nb, 1] + rb[2, i] * ac[nb, 2]


@njit(cache=True)
def actuated_regressor(qs, tree, plan, bodies, loops):
    """Regressor of the entries (unique H, C, G) in actuated coordinates at closed full poses ``qs`` (P, N):
    (P, E, 10 B), and the pivot ratio of ``Phi_p`` per pose (0: singular). Body axes throughout."""
    n_pose, n_dof = qs.shape
    body_node, gravity = bodies.body_node, bodies.gravity
    na = loops.actuated.shape[0]
    n_body = body_node.shape[0]
    m = na * (na + 1) // 2
    n_entries = m + na * m + na
    out = np.zeros((n_pose, n_entries, 10 * n_body))
    ratios = np.zeros(n_pose)
    ws = closure_scratch(tree.parent.shape[0], n_dof, na, loops.passive, n_body)
    rot, w, al, ac, ja = ws.rot, ws.w, ws.al, ws.ac, ws.ja
    jab = np.zeros((n_body, 6, na))
    rb = np.zeros((n_body, 3, 3))
    mb = np.zeros((3, 3))
    yh = np.zeros((na, na, 10))
    yg = np.zeros((na, 10))
    cs = np.zeros((m, n_body, na, 10))
    wrench = np.zeros((6, 10))
    empty = np.zeros(0)
    for p in range(n_pose):
        ratio, _ = factor_pose(qs[p], tree, plan, loops, ws)
        ratios[p] = ratio
        if ratio == 0.0:
            continue
        reduce_pose(tree, plan, body_node, loops, ws)
        for b in range(n_body):
            nb = body_node[b]
            for i in range(3):
                for k in range(3):
                    rb[b, i, k] = rotation_entry(rot, nb, i, k)
            for i in range(3):
                for j in range(na):
                    jab[b, i, j] = rb[b, 0, i] * ja[b, 0, j] + rb[b, 1, i] * ja[b, 1, j] + rb[b, 2, i] * ja[b, 2, j]
                    jab[b, 3 + i, j] = rb[b, 0, i] * ja[b, 3, j] + rb[b, 1, i] * ja[b, 4, j] + rb[b, 2, i] * ja[b, 5, j]
        st = 0
        for j in range(na):
            for k in range(j, na):
                velocity_state(empty, j, k, tree.axis, plan, bodies.motion, loops, ws)
                for b in range(n_body):
                    _body_motion(w, al, ac, body_node[b], rb[b], mb)
                    _wrench_regressor(mb[0], mb[1], mb[2], wrench)
                    for i in range(na):
                        for c in range(10):
                            acc = 0.0
                            for r in range(6):
                                acc += jab[b, r, i] * wrench[r, c]
                            cs[st, b, i, c] = acc
                st += 1
        for b in range(n_body):
            yh[:] = 0.0
            yg[:] = 0.0
            body_regressor(jab[b], rb[b], gravity, yh, yg, 0)
            col = 10 * b
            e = 0
            for i in range(na):
                for j in range(i, na):
                    for c in range(10):
                        out[p, e, col + c] = yh[i, j, c]
                    e += 1
            for i in range(na):
                st = 0
                for j in range(na):
                    for k in range(j, na):
                        for c in range(10):
                            value = cs[st, b, i, c]
                            if k != j:
                                value -= cs[_state(j, na), b, i, c] + cs[_state(k, na), b, i, c]
                            out[p, m + i * m + st, col + c] = value
                        st += 1
            for i in range(na):
                for c in range(10):
                    out[p, m + na * m + i, col + c] = yg[i, c]
    return out, ratios
