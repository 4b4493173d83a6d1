"""Compiled (numba) kernels of loop closure: residual, constraint Jacobian, bias, Newton, continuation.

Closure ``l`` asks frames ``A = frame_a[l]`` and ``B = frame_b[l]`` (tree nodes, ``-1`` the base)
to coincide in chosen base-frame components (:mod:`hapticdesign.model.loops`). With ``rows`` the
selected components of all closures:

- residual ``phi``: ``p_A - p_B`` (x, y, z) and the vector of the skew part of ``R_A R_B^T``
  (rx, ry, rz: ``sin(angle) axis``, zero at closure);
- constraint Jacobian ``Phi = select(J_A - J_B)`` (m x N) with ``J`` the world-frame geometric
  Jacobian of a frame origin (seed 000 eq. 2.20-2.26: rotation axis ``u`` through the node,
  ``v = u x (p - p_node)``, as :func:`hapticdesign.model.walk.frame_jacobian`); it is the exact
  derivative of ``phi`` at closure;
- bias ``Phidot qd = select(a_A - a_B)`` with ``a`` the accelerations of the frames at ``qdd = 0``
  (:func:`hapticdesign.model.walk.node_motion`, the time derivative of eq. 2.38-2.41).

Passive values follow by Newton on ``phi(q_a, q_p) = 0`` from a start near the branch, and along a
motion by continuation with a tangent predictor ``dq_p = S dq_a``, ``S = -Phi_p^-1 Phi_a``.
The sign of ``det Phi_p`` labels the assembly branch: it can only change through a singular
``Phi_p``, so a change between two steps means the motion left the branch. :func:`correct` is the one
continuation step every caller takes (the path solver, the entries along a motion, the plant): Newton from
a predicted pose and the rule that accepts its result.

The kernels take the records of :mod:`.records` and :mod:`hapticdesign.model.walk`: ``tree``
(:class:`~hapticdesign.model.walk.Tree`), ``plan`` (:class:`~hapticdesign.model.walk.WalkPlan`, the
closures' nodes first), ``loops`` (:class:`~.records.Closures`), ``settings``
(:class:`~.records.Settings`) and ``ws`` (:class:`~.records.ClosureScratch`). The residual and the constraint
Jacobian are inlined into their callers (a call copies the records' fields).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hapticdesign.analysis.loops.records import BRANCH_CHANGE, ILL_CONDITIONED, NO_CLOSURE, OK, SINGULAR, closure_scratch
from hapticdesign.model.dense import lu_in_place
from hapticdesign.model.walk import planned_poses, unit_twist

POLISH = 3
"""Newton iterations past the closure tolerance, at most, to bring the error bound within the accuracy."""
MAX_NEWTON_STEP = 0.25
"""Largest Newton update of a passive coordinate per iteration (rad or m)."""
JUMP_SLACK = 1e-9
"""Absolute slack (rad or m) of :func:`correct`'s bound on the corrector."""


@njit(cache=True, inline="always")
def rotation_entry(rot, node, i, k):
    """Entry ``(i, k)`` of the world rotation of ``node`` (the identity for the base, ``node < 0``)."""
    if node >= 0:
        return rot[node, i, k]
    return 1.0 if i == k else 0.0


@njit(cache=True, inline="always")
def _component(c, v0, v1, v2, w0, w1, w2):
    """Component ``c`` (x, y, z, rx, ry, rz) of the twist ``(v, w)``: a branch, where indexing the tuple by a value
    known only at run time would store it first (half :func:`closure_jacobian`'s time)."""
    if c < 3:
        return v0 if c == 0 else (v1 if c == 1 else v2)
    return w0 if c == 3 else (w1 if c == 4 else w2)


@njit(cache=True, _nrt=False, forceinline=True)
def closure_residual(loops, rot, pos, out):
    """``phi`` (m,): origin differences and the skew-part vector of ``R_A R_B^T`` in the base frame."""
    frame_a, frame_b, row_loop, row_comp = loops.frame_a, loops.frame_b, loops.row_loop, loops.row_comp
    for i in range(row_loop.shape[0]):
        na = frame_a[row_loop[i]]
        nb = frame_b[row_loop[i]]
        c = row_comp[i]
        if c < 3:
            pa = pos[na, c] if na >= 0 else 0.0
            pb = pos[nb, c] if nb >= 0 else 0.0
            out[i] = pa - pb
        else:
            # 0.5 (M[r, t] - M[t, r]) of M = R_A R_B^T, with (r, t) = (2, 1), (0, 2), (1, 0) for rx, ry, rz
            r = (c - 1) % 3
            t = (c + 1) % 3
            acc = 0.0
            for k in range(3):
                acc += (rotation_entry(rot, na, r, k) * rotation_entry(rot, nb, t, k)
                        - rotation_entry(rot, na, t, k) * rotation_entry(rot, nb, r, k))
            out[i] = 0.5 * acc


@njit(cache=True, _nrt=False, forceinline=True)
def closure_jacobian(loops, tree, plan, rot, pos, phi):
    """``Phi = select(J_A - J_B)`` (m x N) at the current node poses.

    Each frame's path to the base is walked once per loop; a column of ``J`` is as in
    :func:`~hapticdesign.model.walk.frame_jacobian`, from the plan's sparse coupling coefficients. The rows
    of a loop are consecutive, loop after loop.
    """
    frame_a, frame_b, row_loop, row_comp = loops.frame_a, loops.frame_b, loops.row_loop, loops.row_comp
    parent, axis = tree.parent, tree.axis
    ptr, index, value = plan.ptr, plan.index, plan.value
    m = row_loop.shape[0]
    for i in range(m):
        for k in range(phi.shape[1]):
            phi[i, k] = 0.0
    stop = 0
    for loop in range(frame_a.shape[0]):
        start = stop
        while stop < m and row_loop[stop] == loop:
            stop += 1
        for side in range(2):
            node = frame_a[loop] if side == 0 else frame_b[loop]
            f = 1.0 if side == 0 else -1.0
            e = node
            while e >= 0:
                if ptr[e] != ptr[e + 1]:  # a node some coordinate moves
                    v0, v1, v2, w0, w1, w2 = unit_twist(rot, pos, axis, e, node)
                    for i in range(start, stop):
                        t = f * _component(row_comp[i], v0, v1, v2, w0, w1, w2)
                        for k in range(ptr[e], ptr[e + 1]):
                            phi[i, index[k]] += value[k] * t
                e = parent[e]


@njit(cache=True, _nrt=False)
def closure_bias(loops, al, ac, out):
    """``Phidot qd = select(a_A - a_B)`` from node accelerations computed at ``qdd = 0``."""
    frame_a, frame_b, row_loop, row_comp = loops.frame_a, loops.frame_b, loops.row_loop, loops.row_comp
    for i in range(row_loop.shape[0]):
        na = frame_a[row_loop[i]]
        nb = frame_b[row_loop[i]]
        c = row_comp[i]
        src_a = ac if c < 3 else al
        k = c % 3
        va = src_a[na, k] if na >= 0 else 0.0
        vb = src_a[nb, k] if nb >= 0 else 0.0
        out[i] = va - vb


@njit(cache=True)
def velocity_map(phi, actuated, passive):
    """``S = -Phi_p^-1 Phi_a`` (n_p x n_a), the pivot ratio and the sign of ``det Phi_p``."""
    m = passive.shape[0]
    s = np.empty((m, actuated.shape[0]))
    ratio, sign = velocity_map_into(phi, actuated, passive, np.empty((m, m)), s)
    return s, ratio, sign


@njit(cache=True, _nrt=False)
def velocity_map_into(phi, actuated, passive, pp, s):
    """:func:`velocity_map` into ``s`` (n_p x n_a) with the scratch ``pp`` (n_p x n_p); returns (ratio, sign)."""
    for i in range(passive.shape[0]):
        for j in range(actuated.shape[0]):
            s[i, j] = -phi[i, actuated[j]]
        for j in range(passive.shape[0]):
            pp[i, j] = phi[i, passive[j]]
    return lu_in_place(pp, s)


@njit(cache=True)
def newton(q, tree, plan, loops, settings):
    """:func:`newton_into` on a workspace of its own."""
    ws = closure_scratch(tree.parent.shape[0], q.shape[0], loops.actuated.shape[0], loops.passive, np.int64(0))
    return newton_into(q, tree, plan, loops, settings, ws)


@njit(cache=True, _nrt=False)
def newton_into(q, tree, plan, loops, settings, ws):
    """Newton on the passive entries of ``q`` (in place). Returns (status, det sign, pivot ratio).

    Each iteration walks only the plan's first part (the nodes of the closures; after the first, only those
    the passive coordinates move, the plan's ``n_still`` being the others). On return ``ws.res`` holds the
    last residual; on success ``ws.rot``, ``ws.pos`` and ``ws.trig`` hold those nodes' poses, ``ws.phi`` the
    constraint Jacobian and ``ws.pinv`` ``Phi_p^-1`` at the returned ``q`` (the last iteration factors
    ``Phi_p`` for the inverse instead of a Newton step). The pivot ratio estimates the reciprocal condition
    number of ``Phi_p`` (:func:`hapticdesign.model.dense.lu_in_place`).

    **Trust.** A residual ``r`` leaves the passive coordinates off by up to ``|r| / sigma_min`` and ``T`` (so
    H, C, G) off by about ``sigma_max |r| / sigma_min^2`` relative, with the singular values of ``Phi_p``
    estimated by its pivots. Near a singular configuration that bound exceeds ``settings.accuracy`` although
    the residual meets the tolerance: Newton then polishes (at most :data:`POLISH` more iterations, the
    residual falling to its rounding floor ``settings.floor``), and a pose whose bound stays above the
    accuracy is ``ILL_CONDITIONED``: refused rather than returned wrong.
    """
    passive = loops.passive
    rot, pos, trig, res, phi, rhs, pp, pinv = ws.rot, ws.pos, ws.trig, ws.res, ws.phi, ws.rhs, ws.lu, ws.pinv
    m = passive.shape[0]
    n_first, n_still = plan.n_first, plan.n_still
    polished = 0
    for it in range(settings.max_iter + POLISH + 1):
        # a Newton step moves only passive coordinates: the nodes they do not move stay where they were
        planned_poses(q, tree, plan, 0 if it == 0 else n_still, n_first, rot, pos, trig)
        closure_residual(loops, rot, pos, res)
        closure_jacobian(loops, tree, plan, rot, pos, phi)
        big = 0.0
        for i in range(m):
            big = max(big, abs(res[i]))
        closed = big <= settings.tol
        for i in range(m):
            rhs[i, 0] = -res[i]
            for j in range(m):
                pp[i, j] = phi[i, passive[j]]
                pinv[i, j] = 1.0 if i == j else 0.0
        if closed:
            ratio, sign = lu_in_place(pp, pinv)
        else:
            ratio, sign = lu_in_place(pp, rhs)
        if not np.isfinite(ratio) or ratio <= settings.singular_ratio:
            return SINGULAR, sign, ratio
        if closed:
            small = 0.0  # the LU keeps the pivots' reciprocals on its diagonal
            for i in range(m):
                small = max(small, abs(pp[i, i]))
            if max(big, settings.floor) * small / ratio <= settings.accuracy:
                return OK, sign, ratio
            if polished == POLISH or big <= settings.floor:
                return ILL_CONDITIONED, sign, ratio
            polished += 1
            for j in range(m):  # a Newton step with the inverse just formed
                step = 0.0
                for i in range(m):
                    step -= pinv[j, i] * res[i]
                q[passive[j]] += step
            continue
        if it >= settings.max_iter:
            break
        # damped: at most MAX_NEWTON_STEP per iteration, so that a rough start reaches its nearest branch
        big = 0.0
        for j in range(m):
            big = max(big, abs(rhs[j, 0]))
        scale = 1.0 if big <= MAX_NEWTON_STEP else MAX_NEWTON_STEP / big
        for j in range(m):
            q[passive[j]] += scale * rhs[j, 0]
    return NO_CLOSURE, 0.0, 0.0


@njit(cache=True, _nrt=False)
def correct(q, tree, plan, loops, settings, ws, branch, bound):
    """One continuation step: Newton (:func:`newton_into`) from the predicted pose ``q`` (in place) and the
    rule that accepts it. Returns the status.

    Accepted (``OK``) when Newton closes the loops on the branch ``branch`` (sign of ``det Phi_p``; another
    sign is ``BRANCH_CHANGE``) with every passive coordinate within ``bound`` (plus :data:`JUMP_SLACK`)
    of its prediction: the corrector of a predictor along the motion is of higher order in the step, so a
    large one means Newton jumped (to another branch, or by whole turns) and is ``NO_CLOSURE``.
    """
    passive = loops.passive
    for r in range(passive.shape[0]):
        ws.predicted[r] = q[passive[r]]
    code, sign, _ = newton_into(q, tree, plan, loops, settings, ws)
    if code == OK and sign != branch:
        code = BRANCH_CHANGE
    if code == OK:
        for r in range(passive.shape[0]):
            if not abs(q[passive[r]] - ws.predicted[r]) <= bound + JUMP_SLACK:
                code = NO_CLOSURE
    return code


@njit(cache=True, _nrt=False)
def tangent_into(q, tree, plan, loops, ws, s):
    """``S = -Phi_p^-1 Phi_a`` (n_p x n_a) into ``s`` at the closed full pose ``q`` (the continuation's tangent)."""
    planned_poses(q, tree, plan, np.int64(0), plan.n_first, ws.rot, ws.pos, ws.trig)  # a literal would compile its own copy
    closure_jacobian(loops, tree, plan, ws.rot, ws.pos, ws.phi)
    velocity_map_into(ws.phi, loops.actuated, loops.passive, ws.lu, s)


@njit(cache=True, _nrt=False)
def continue_to(target, q, branch, tree, plan, loops, settings, ws, s, start, trial):
    """Continue the closed full pose ``q`` (in place) to the actuated pose ``target`` (n_a,) with the tangent ``s``
    at ``q`` (:func:`tangent_into`; updated along). Returns the status.

    The segment is split into steps of at most ``settings.max_step`` (actuated infinity norm) with a tangent
    predictor; a step :func:`correct` refuses (Newton fails, another sign of ``det Phi_p``, a corrector above
    half the step) is halved down to ``settings.min_fraction`` of the segment. ``start`` (n_a) and ``trial``
    (N): scratch; nothing is allocated.
    """
    actuated, passive = loops.actuated, loops.passive
    m = passive.shape[0]
    na = actuated.shape[0]
    n_dof = q.shape[0]
    phi, pinv = ws.phi, ws.pinv
    for j in range(na):
        start[j] = q[actuated[j]]
    dist = 0.0
    for j in range(na):
        dist = max(dist, abs(target[j] - start[j]))
    done = 0.0
    step = 1.0 if dist <= settings.max_step else settings.max_step / dist
    code = OK
    while done < 1.0:
        f = min(1.0, done + step)
        for k in range(n_dof):
            trial[k] = q[k]
        for j in range(na):
            delta = start[j] + f * (target[j] - start[j]) - q[actuated[j]]
            trial[actuated[j]] += delta
            for r in range(m):
                trial[passive[r]] += s[r, j] * delta
        code = correct(trial, tree, plan, loops, settings, ws, branch, 0.5 * step * dist)
        if code == OK:
            for k in range(n_dof):
                q[k] = trial[k]
            done = f
            for r in range(m):
                for j in range(na):
                    acc = 0.0
                    for i in range(m):
                        acc -= pinv[r, i] * phi[i, actuated[j]]
                    s[r, j] = acc
        else:
            step *= 0.5
            if step < settings.min_fraction:
                break
    return code


@njit(cache=True)
def solve_path(qa_path, q_start, branch, tree, plan, loops, settings):
    """Continue the closure from ``q_start`` (full, closed) through the actuated poses ``qa_path`` in order
    (:func:`continue_to` from pose to pose). Returns full poses (P, N), per-pose status (OK until the first
    failure) and the index of the first failed pose (-1 if none).
    """
    n_pose = qa_path.shape[0]
    n_dof = q_start.shape[0]
    m = loops.passive.shape[0]
    na = loops.actuated.shape[0]
    ws = closure_scratch(tree.parent.shape[0], n_dof, na, loops.passive, np.int64(0))
    s = np.empty((m, na))
    start = np.empty(na)
    out = np.empty((n_pose, n_dof))
    status = np.zeros(n_pose, dtype=np.int64)
    q = q_start.copy()
    trial = q.copy()
    tangent_into(q, tree, plan, loops, ws, s)
    for p in range(n_pose):
        code = continue_to(qa_path[p], q, branch, tree, plan, loops, settings, ws, s, start, trial)
        if code != OK:
            status[p] = code
            return out, status, p
        for k in range(n_dof):
            out[p, k] = q[k]
    return out, status, -1
