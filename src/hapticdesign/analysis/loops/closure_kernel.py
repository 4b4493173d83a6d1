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
  (:func:`node_motion`, the time derivative of eq. 2.38-2.41).

Passive values follow by Newton on ``phi(q_a, q_p) = 0`` from a start near the branch, and along a
motion by continuation with a tangent predictor ``dq_p = S dq_a``, ``S = -Phi_p^-1 Phi_a``.
The sign of ``det Phi_p`` labels the assembly branch: it can only change through a singular
``Phi_p``, so a change between two steps means the motion left the branch.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hapticdesign.model.walk import planned_poses, trig_workspace, unit_twist

OK, NO_CLOSURE, SINGULAR, BRANCH_CHANGE = 0, 1, 2, 3
MAX_NEWTON_STEP = 0.25
"""Largest Newton update of a passive coordinate per iteration (rad or m)."""


@njit(cache=True)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True)
def node_motion(rate, motion, axis, rot, pos, w, al, ac):
    """World angular velocity ``w`` and, at zero joint accelerations, the angular and origin accelerations
    ``al``, ``ac`` of the nodes of a motion plan (:class:`~.solver.MotionPlan` arrays ``motion``), for the rate
    ``rate[n]`` of each node's joint value.

    From the kept ancestor ``k`` (the base: at rest), over the origin difference ``d = p_n - p_k``:
    rotation node (axis ``u``, rate ``s``): ``w = w_k + s u``, ``al = al_k + w_k x s u``,
    ``ac = ac_k + al_k x d + w_k x (w_k x d)``; translation node: ``w = w_k``, ``al = al_k``,
    ``ac = ac_k + al_k x d + w_k x (w_k x d) + 2 w_k x s u`` (the time derivative of seed 000 eq. 2.38-2.41).
    """
    order, kept, moves = motion
    for i in range(order.shape[0]):
        n = order[i]
        p = kept[i]
        s = rate[n]
        a = axis[n] % 3
        u0, u1, u2 = rot[n, 0, a], rot[n, 1, a], rot[n, 2, a]
        if p >= 0:
            w0, w1, w2 = w[p, 0], w[p, 1], w[p, 2]
            l0, l1, l2 = al[p, 0], al[p, 1], al[p, 2]
            a0, a1, a2 = ac[p, 0], ac[p, 1], ac[p, 2]
        else:
            w0 = w1 = w2 = l0 = l1 = l2 = a0 = a1 = a2 = 0.0
        if p >= 0 and moves[i]:
            d0, d1, d2 = pos[n, 0] - pos[p, 0], pos[n, 1] - pos[p, 1], pos[n, 2] - pos[p, 2]
            wd0, wd1, wd2 = _cross(w0, w1, w2, d0, d1, d2)
            ww0, ww1, ww2 = _cross(w0, w1, w2, wd0, wd1, wd2)
            ld0, ld1, ld2 = _cross(l0, l1, l2, d0, d1, d2)
            a0, a1, a2 = a0 + ld0 + ww0, a1 + ld1 + ww1, a2 + ld2 + ww2
        x0, x1, x2 = _cross(w0, w1, w2, s * u0, s * u1, s * u2)
        if axis[n] < 3:
            w[n, 0], w[n, 1], w[n, 2] = w0 + s * u0, w1 + s * u1, w2 + s * u2
            al[n, 0], al[n, 1], al[n, 2] = l0 + x0, l1 + x1, l2 + x2
            ac[n, 0], ac[n, 1], ac[n, 2] = a0, a1, a2
        else:
            w[n, 0], w[n, 1], w[n, 2] = w0, w1, w2
            al[n, 0], al[n, 1], al[n, 2] = l0, l1, l2
            ac[n, 0], ac[n, 1], ac[n, 2] = a0 + 2.0 * x0, a1 + 2.0 * x1, a2 + 2.0 * x2


@njit(cache=True, inline="always")
def rotation_entry(rot, node, i, k):
    """Entry ``(i, k)`` of the world rotation of ``node`` (the identity for the base, ``node < 0``)."""
    if node >= 0:
        return rot[node, i, k]
    return 1.0 if i == k else 0.0


@njit(cache=True)
def add_joint_accelerations(acc, motion, axis, rot, pos, al, ac, dal, dac):
    """Add to the node accelerations ``al``, ``ac`` those of the joint-value accelerations ``acc[n]`` at zero rates
    (the nodes of a motion plan, as :func:`node_motion`).

    The rate-free part of :func:`node_motion` (linear in ``acc``): from the kept ancestor ``k``, a node carries
    its angular acceleration ``dal_k`` over the origin difference ``d`` (``dac = dac_k + dal_k x d``) and adds
    ``acc u`` to the angular acceleration (rotation) or to the origin's (translation). ``dal``, ``dac``:
    scratch (M x 3).
    """
    order, kept, moves = motion
    for i in range(order.shape[0]):
        n = order[i]
        p = kept[i]
        s = acc[n]
        a = axis[n] % 3
        u0, u1, u2 = s * rot[n, 0, a], s * rot[n, 1, a], s * rot[n, 2, a]
        if p >= 0:
            l0, l1, l2 = dal[p, 0], dal[p, 1], dal[p, 2]
            a0, a1, a2 = dac[p, 0], dac[p, 1], dac[p, 2]
            if moves[i]:
                x0, x1, x2 = _cross(l0, l1, l2, pos[n, 0] - pos[p, 0], pos[n, 1] - pos[p, 1], pos[n, 2] - pos[p, 2])
                a0, a1, a2 = a0 + x0, a1 + x1, a2 + x2
        else:
            l0 = l1 = l2 = a0 = a1 = a2 = 0.0
        if axis[n] < 3:
            l0, l1, l2 = l0 + u0, l1 + u1, l2 + u2
        else:
            a0, a1, a2 = a0 + u0, a1 + u1, a2 + u2
        dal[n, 0], dal[n, 1], dal[n, 2] = l0, l1, l2
        dac[n, 0], dac[n, 1], dac[n, 2] = a0, a1, a2
        al[n, 0] += l0
        al[n, 1] += l1
        al[n, 2] += l2
        ac[n, 0] += a0
        ac[n, 1] += a1
        ac[n, 2] += a2


@njit(cache=True)
def closure_residual(frame_a, frame_b, row_loop, row_comp, rot, pos, out):
    """``phi`` (m,): origin differences and the skew-part vector of ``R_A R_B^T`` in the base frame."""
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


@njit(cache=True)
def closure_jacobian(frame_a, frame_b, row_loop, row_comp, parent, axis, plan, rot, pos, phi):
    """``Phi = select(J_A - J_B)`` (m x N) at the current node poses.

    ``plan``: the arrays of a :class:`~hapticdesign.model.walk.WalkPlan` (its sparse coupling coefficients).
    Each frame's path to the base is walked once per loop; a column of ``J`` is as in
    :func:`~hapticdesign.model.walk.frame_jacobian`. The rows of a loop are consecutive, loop after loop.
    """
    _, _, ptr, index, value, _, _, _ = plan
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
                    twist = unit_twist(rot, pos, axis, e, node)
                    for i in range(start, stop):
                        t = f * twist[row_comp[i]]
                        for k in range(ptr[e], ptr[e + 1]):
                            phi[i, index[k]] += value[k] * t
                e = parent[e]


@njit(cache=True)
def closure_bias(frame_a, frame_b, row_loop, row_comp, al, ac, out):
    """``Phidot qd = select(a_A - a_B)`` from node accelerations computed at ``qdd = 0``."""
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
def lu_in_place(u, x):
    """Solve ``u x = b`` (m x m, m x k) by Gaussian elimination with partial pivoting: ``x`` holds ``b`` on entry
    and the solution on return, ``u`` is overwritten (no allocation; one division per pivot).

    Returns the pivot ratio ``min |u_ii| / max |u_ii|`` (0 when singular) and the sign of ``det u``.
    """
    m = u.shape[0]
    sign = 1.0
    big, small = 0.0, np.inf
    for c in range(m):
        best = c
        for r in range(c + 1, m):
            if abs(u[r, c]) > abs(u[best, c]):
                best = r
        if best != c:
            sign = -sign
            for k in range(c, m):
                u[c, k], u[best, k] = u[best, k], u[c, k]
            for k in range(x.shape[1]):
                x[c, k], x[best, k] = x[best, k], x[c, k]
        pivot = u[c, c]
        big = max(big, abs(pivot))
        small = min(small, abs(pivot))
        if pivot == 0.0:
            return 0.0, 0.0
        if pivot < 0.0:
            sign = -sign
        inverse = 1.0 / pivot
        u[c, c] = inverse
        for r in range(c + 1, m):
            f = u[r, c] * inverse
            if f != 0.0:
                for k in range(c + 1, m):
                    u[r, k] -= f * u[c, k]
                for k in range(x.shape[1]):
                    x[r, k] -= f * x[c, k]
    for c in range(m - 1, -1, -1):
        for k in range(x.shape[1]):
            t = x[c, k]
            for j in range(c + 1, m):
                t -= u[c, j] * x[j, k]
            x[c, k] = t * u[c, c]
    return small / big, sign


@njit(cache=True)
def velocity_map(phi, actuated, passive):
    """``S = -Phi_p^-1 Phi_a`` (n_p x n_a), the pivot ratio and the sign of ``det Phi_p``."""
    m = passive.shape[0]
    s = np.empty((m, actuated.shape[0]))
    ratio, sign = velocity_map_into(phi, actuated, passive, np.empty((m, m)), s)
    return s, ratio, sign


@njit(cache=True)
def velocity_map_into(phi, actuated, passive, pp, s):
    """:func:`velocity_map` into ``s`` (n_p x n_a) with the scratch ``pp`` (n_p x n_p); returns (ratio, sign)."""
    for i in range(passive.shape[0]):
        for j in range(actuated.shape[0]):
            s[i, j] = -phi[i, actuated[j]]
        for j in range(passive.shape[0]):
            pp[i, j] = phi[i, passive[j]]
    return lu_in_place(pp, s)


@njit(cache=True)
def newton(q, actuated, passive, parent, axis, offset, const_rot, const_pos, plan, frame_a, frame_b, row_loop, row_comp,
           tol, max_iter, singular_ratio, rot, pos, trig):
    """Newton on the passive entries of ``q`` (in place). Returns (status, det sign, pivot ratio).

    ``plan``: the arrays of a :class:`~hapticdesign.model.walk.WalkPlan` whose first part is the nodes the
    closures need (those that the passive coordinates do not move first); ``rot``, ``pos``, ``trig``: the
    node poses and the plan's scratch.
    """
    m = passive.shape[0]
    return newton_into(q, actuated, passive, parent, axis, offset, const_rot, const_pos, plan, frame_a, frame_b, row_loop,
                       row_comp, tol, max_iter, singular_ratio, rot, pos, trig, np.empty(m), np.empty((m, q.shape[0])),
                       np.empty((m, 1)), np.empty((m, m)), np.empty((m, m)))


@njit(cache=True)
def newton_into(q, actuated, passive, parent, axis, offset, const_rot, const_pos, plan, frame_a, frame_b, row_loop, row_comp,
                tol, max_iter, singular_ratio, rot, pos, trig, res, phi, rhs, pp, pinv):
    """:func:`newton` on the caller's scratch ``res`` (m), ``phi`` (m x N), ``rhs`` (m x 1), ``pp`` (m x m) and
    ``pinv`` (m x m).

    Each iteration walks only the plan's first part (the nodes of the closures; after the first, only those
    the passive coordinates move, the plan's ``n_still`` being the others). On success ``rot``, ``pos``
    and ``trig`` hold those nodes' poses, ``phi`` the constraint Jacobian and ``pinv`` ``Phi_p^-1`` at the
    returned ``q`` (the last iteration factors ``Phi_p`` for the inverse instead of a Newton step).
    """
    m = passive.shape[0]
    n_first, n_still = plan[1], plan[7]
    for it in range(max_iter + 1):
        # a Newton step moves only passive coordinates: the nodes they do not move stay where they were
        planned_poses(q, parent, axis, offset, const_rot, const_pos, plan, 0 if it == 0 else n_still, n_first, rot, pos,
                      trig)
        closure_residual(frame_a, frame_b, row_loop, row_comp, rot, pos, res)
        closure_jacobian(frame_a, frame_b, row_loop, row_comp, parent, axis, plan, rot, pos, phi)
        big = 0.0
        for i in range(m):
            big = max(big, abs(res[i]))
        closed = big <= tol
        for i in range(m):
            rhs[i, 0] = -res[i]
            for j in range(m):
                pp[i, j] = phi[i, passive[j]]
                pinv[i, j] = 1.0 if i == j else 0.0
        if closed:
            ratio, sign = lu_in_place(pp, pinv)
        else:
            ratio, sign = lu_in_place(pp, rhs)
        if not np.isfinite(ratio) or ratio <= singular_ratio:
            return SINGULAR, sign, ratio
        if closed:
            return OK, sign, ratio
        if it == max_iter:
            break
        # damped: at most MAX_NEWTON_STEP per iteration, so that a rough start reaches its nearest branch
        big = 0.0
        for j in range(m):
            big = max(big, abs(rhs[j, 0]))
        scale = 1.0 if big <= MAX_NEWTON_STEP else MAX_NEWTON_STEP / big
        for j in range(m):
            q[passive[j]] += scale * rhs[j, 0]
    return NO_CLOSURE, 0.0, 0.0


@njit(cache=True)
def solve_path(qa_path, q_start, sign0, actuated, passive, parent, axis, offset, const_rot, const_pos, plan, frame_a, frame_b,
               row_loop, row_comp, max_step, tol, max_iter, singular_ratio, min_fraction):
    """Continue the closure from ``q_start`` (full, closed) through the actuated poses ``qa_path`` in order.

    Each segment is split into steps of at most ``max_step`` (actuated infinity norm); a step whose
    Newton fails, lands on the other sign of ``det Phi_p`` or corrects the tangent predictor by more
    than half the step (a jump), is halved down to ``min_fraction`` of the segment. Returns full poses (P, N), per-pose status (OK until the first failure) and the
    index of the first failed pose (-1 if none).
    """
    n_pose = qa_path.shape[0]
    n_dof = q_start.shape[0]
    m = passive.shape[0]
    n_node = max(parent.shape[0], 1)
    na = actuated.shape[0]
    rot = np.zeros((n_node, 3, 3))
    pos = np.zeros((n_node, 3))
    trig = trig_workspace(n_node)
    phi = np.empty((m, n_dof))
    res, rhs, pp, pinv = np.empty(m), np.empty((m, 1)), np.empty((m, m)), np.empty((m, m))
    s = np.empty((m, na))
    start = np.empty(na)
    out = np.empty((n_pose, n_dof))
    status = np.zeros(n_pose, dtype=np.int64)
    q = q_start.copy()
    trial = q.copy()
    predicted = np.empty(m)
    # tangent at the current closed pose; after each accepted step, S = -Phi_p^-1 Phi_a from Newton's last iteration
    planned_poses(q, parent, axis, offset, const_rot, const_pos, plan, 0, plan[1], rot, pos, trig)
    closure_jacobian(frame_a, frame_b, row_loop, row_comp, parent, axis, plan, rot, pos, phi)
    velocity_map_into(phi, actuated, passive, pp, s)
    for p in range(n_pose):
        for j in range(actuated.shape[0]):
            start[j] = q[actuated[j]]
        dist = 0.0
        for j in range(actuated.shape[0]):
            dist = max(dist, abs(qa_path[p, j] - start[j]))
        done = 0.0
        step = 1.0 if dist <= max_step else max_step / dist
        code = OK
        while done < 1.0:
            f = min(1.0, done + step)
            for k in range(n_dof):
                trial[k] = q[k]
            for j in range(actuated.shape[0]):
                delta = start[j] + f * (qa_path[p, j] - start[j]) - q[actuated[j]]
                trial[actuated[j]] += delta
                for r in range(m):
                    trial[passive[r]] += s[r, j] * delta
            for r in range(m):
                predicted[r] = trial[passive[r]]
            code, sign, _ = newton_into(trial, actuated, passive, parent, axis, offset, const_rot, const_pos, plan, frame_a,
                                        frame_b, row_loop, row_comp, tol, max_iter, singular_ratio, rot, pos, trig, res,
                                        phi, rhs, pp, pinv)
            if code == OK and sign != sign0:
                code = BRANCH_CHANGE
            if code == OK:
                # the corrector of a tangent predictor is second order in the step: a large one
                # means Newton jumped (to another branch or by whole turns); retry with a smaller step
                for r in range(m):
                    if abs(trial[passive[r]] - predicted[r]) > 0.5 * step * dist + 1e-9:
                        code = NO_CLOSURE
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
                if step < min_fraction:
                    break
        if code != OK:
            status[p] = code
            return out, status, p
        for k in range(n_dof):
            out[p, k] = q[k]
    return out, status, -1
