"""Compiled (numba) kernel: H, C, G of a closed-loop mechanism in its actuated coordinates, as a regressor.

On the loop-opened tree (all joints are coordinates ``q``, seed 000 eq. 2.44-2.50) the passive rates
follow the actuated ones, ``qd = T qd_a`` with ``T = [I; S]``, ``S = -Phi_p^-1 Phi_a``
(:mod:`hapticdesign.analysis.loops`). The virtual power of the tree's generalized forces
(d'Alembert) on the admissible motions gives the reduced equations ``T^T (H qdd + c(q, qd) + G) = tau_a``
with ``qdd = T qdd_a + [0; gamma]`` and ``gamma = -Phi_p^-1 (Phidot qd)``:

- ``H_a = T^T H T``: the body regressor of :func:`.kernel.body_regressor` fed with the reduced
  body Jacobians ``J_b T`` (eq. 2.44);
- ``G_a = T^T G``: likewise (eq. 2.46);
- the velocity terms ``T^T (H [0; gamma] + c(q, T qd_a))`` (``T^T (H Tdot + C-terms T)``): per body the
  Newton-Euler wrench ``f = m a + al x h + w x (w x h)``, ``n = J al + w x (J w) + h x a`` at the body
  velocities of ``qd = T qd_a`` and accelerations of ``qdd = [0; gamma]``, which is linear in the ten
  standard parameters ``(m, h, J)``, projected by ``(J_b T)^T``. It is a quadratic form in ``qd_a``;
  its coefficients (the columns of eq. 2.50's ``C``: ``Gamma_ijj`` and ``2 Gamma_ijk``) follow by
  polarization from ``n_a (n_a + 1) / 2`` rate vectors ``e_j`` and ``e_j + e_k``.

Everything is linear in the standard inertial parameters, so the kernel returns a regressor (or its
product with given parameter sets), entry by entry in :class:`.model.DynamicsModel`'s order.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hapticdesign.analysis.dynamics.kernel import body_jacobian, body_regressor
from hapticdesign.analysis.loops.closure_kernel import closure_bias, closure_jacobian, lu_solve, node_motion
from hapticdesign.model.walk import node_poses


@njit(cache=True)
def _wrench_regressor(w, vel, al, acc, out):
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


@njit(cache=True)
def actuated_kernel(qs, parent, axis, coef, offset, const_rot, const_pos, body_node, gravity,
                    frame_a, frame_b, row_loop, row_comp, actuated, passive, params, regressor):
    """Entries (unique H, C, G) in actuated coordinates at closed full poses ``qs`` (P, N).

    The tree is a :class:`~hapticdesign.model.walk.KinematicTree` (``parent .. const_pos``, ``body_node``).
    ``regressor``: returns (P, E, 10 B), the regressor; otherwise (P, K, E) for parameter sets
    ``params`` (K, 10 B). The second output is the pivot ratio of ``Phi_p`` per pose (0: singular).
    """
    n_pose, n_dof = qs.shape
    na = actuated.shape[0]
    npas = passive.shape[0]
    n_body = body_node.shape[0]
    n_node = max(parent.shape[0], 1)
    m = na * (na + 1) // 2
    n_entries = m + na * m + na
    n_states = m
    if regressor:
        out = np.zeros((n_pose, n_entries, 10 * n_body))
    else:
        out = np.zeros((n_pose, params.shape[0], n_entries))
    ratios = np.zeros(n_pose)
    rot = np.zeros((n_node, 3, 3))
    pos = np.zeros((n_node, 3))
    w = np.zeros((n_node, 3))
    v = np.zeros((n_node, 3))
    al = np.zeros((n_node, 3))
    ac = np.zeros((n_node, 3))
    phi = np.empty((npas, n_dof))
    bias = np.empty(npas)
    t = np.zeros((n_dof, na))
    jb = np.zeros((n_body, 6, n_dof))
    ja = np.zeros((n_body, 6, na))
    rbs = np.zeros((n_body, 3, 3))
    jac = np.zeros((6, n_dof))
    yh = np.zeros((na, na, 10))
    yg = np.zeros((na, 10))
    cs = np.zeros((n_states, n_body, na, 10))
    wrench = np.zeros((6, 10))
    buf = np.zeros((n_entries, 10))
    zero = np.zeros(n_dof)
    qd = np.zeros(n_dof)
    eye = np.eye(npas)
    eye3 = np.eye(3)
    state_j = np.empty(n_states, dtype=np.int64)
    state_k = np.empty(n_states, dtype=np.int64)
    col = 0
    for j in range(na):
        for k in range(j, na):
            state_j[col], state_k[col] = j, k
            col += 1
    pp = np.empty((npas, npas))
    pa = np.empty((npas, na))
    s = np.empty((npas, na))
    gamma = np.empty(npas)
    wb = np.empty(3)
    vb = np.empty(3)
    lb = np.empty(3)
    ab = np.empty(3)
    for p in range(n_pose):
        node_poses(qs[p], parent, axis, coef, offset, const_rot, const_pos, parent.shape[0] - 1, rot, pos)
        closure_jacobian(frame_a, frame_b, row_loop, row_comp, parent, axis, coef, rot, pos, phi)
        for i in range(npas):
            for j in range(npas):
                pp[i, j] = phi[i, passive[j]]
            for j in range(na):
                pa[i, j] = -phi[i, actuated[j]]
        pinv, ratio, _ = lu_solve(pp, eye)
        ratios[p] = ratio
        if ratio == 0.0:
            continue
        for r in range(npas):
            for j in range(na):
                acc = 0.0
                for i in range(npas):
                    acc += pinv[r, i] * pa[i, j]
                s[r, j] = acc
        for i in range(n_dof):
            for j in range(na):
                t[i, j] = 0.0
        for j in range(na):
            t[actuated[j], j] = 1.0
        for r in range(npas):
            for j in range(na):
                t[passive[r], j] = s[r, j]
        for b in range(n_body):
            rbs[b] = body_jacobian(b, body_node, parent, axis, coef, rot, pos, eye3, jac)
            for r in range(6):
                for k in range(n_dof):
                    jb[b, r, k] = jac[r, k]
                for j in range(na):
                    acc = 0.0
                    for k in range(n_dof):
                        acc += jac[r, k] * t[k, j]
                    ja[b, r, j] = acc
        # velocity terms: one rate vector e_j (+ e_k) per state
        for st in range(n_states):
            for k in range(n_dof):
                qd[k] = t[k, state_j[st]] + (t[k, state_k[st]] if state_k[st] != state_j[st] else 0.0)
            node_motion(qd, zero, parent, axis, coef, rot, pos, w, v, al, ac)
            closure_bias(frame_a, frame_b, row_loop, row_comp, al, ac, bias)
            for r in range(npas):
                acc = 0.0
                for i in range(npas):
                    acc -= pinv[r, i] * bias[i]
                gamma[r] = acc
            for b in range(n_body):
                nb = body_node[b]
                if nb < 0:
                    for i in range(na):
                        for c in range(10):
                            cs[st, b, i, c] = 0.0
                    continue
                rb = rbs[b]
                for i in range(3):
                    wb[i] = rb[0, i] * w[nb, 0] + rb[1, i] * w[nb, 1] + rb[2, i] * w[nb, 2]
                    vb[i] = rb[0, i] * v[nb, 0] + rb[1, i] * v[nb, 1] + rb[2, i] * v[nb, 2]
                    lb[i] = rb[0, i] * al[nb, 0] + rb[1, i] * al[nb, 1] + rb[2, i] * al[nb, 2]
                    ab[i] = rb[0, i] * ac[nb, 0] + rb[1, i] * ac[nb, 1] + rb[2, i] * ac[nb, 2]
                    for r in range(npas):
                        ab[i] += jb[b, i, passive[r]] * gamma[r]
                        lb[i] += jb[b, 3 + i, passive[r]] * gamma[r]
                _wrench_regressor(wb, vb, lb, ab, wrench)
                for i in range(na):
                    for c in range(10):
                        acc = 0.0
                        for r in range(6):
                            acc += ja[b, r, i] * wrench[r, c]
                        cs[st, b, i, c] = acc
        for b in range(n_body):
            yh[:] = 0.0
            yg[:] = 0.0
            body_regressor(ja[b], rbs[b], gravity, yh, yg, 0)
            e = 0
            for i in range(na):
                for j in range(i, na):
                    for c in range(10):
                        buf[e, c] = yh[i, j, c]
                    e += 1
            for i in range(na):
                for st in range(n_states):
                    j, k = state_j[st], state_k[st]
                    for c in range(10):
                        if j == k:
                            buf[m + i * m + st, c] = cs[st, b, i, c]
                        else:
                            sj = j * na - j * (j - 1) // 2  # state of (j, j)
                            sk = k * na - k * (k - 1) // 2  # state of (k, k)
                            buf[m + i * m + st, c] = cs[st, b, i, c] - cs[sj, b, i, c] - cs[sk, b, i, c]
            for i in range(na):
                for c in range(10):
                    buf[m + na * m + i, c] = yg[i, c]
            col = 10 * b
            if regressor:
                for e in range(n_entries):
                    for c in range(10):
                        out[p, e, col + c] += buf[e, c]
            else:
                for kset in range(params.shape[0]):
                    for e in range(n_entries):
                        acc = 0.0
                        for c in range(10):
                            acc += buf[e, c] * params[kset, col + c]
                        out[p, kset, e] += acc
    return out, ratios
