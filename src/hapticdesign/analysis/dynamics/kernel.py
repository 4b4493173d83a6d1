"""Compiled (numba) kernel: inertia-matrix and gravity regressors of any frame tree.

For every body ``b`` with body-frame Jacobian ``J_b = [Jv; Jw]`` (6 x N), the kinetic energy
``1/2 qd^T H qd`` is linear in the standard parameters ``(m, h, J)`` of the body
(see :mod:`hapticdesign.model.inertia`)::

    H_b = m Jv^T Jv + sum_a h_a (A_a + A_a^T) + sum_ab J_ab Jw_a^T Jw_b,   A_a = Jw^T S(e_a) Jv

and the gravity torque of the potential of seed 000 eq. 2.46 is
``G_k = -(R_b^T g) . (m Jv_k + Jw_k x h)``. This is the regressor form of eq. 2.44-2.49.
The Jacobian column of a variable elementary transform ``e`` is its unit twist moved to the
body frame; dependent coordinates contribute through their affine coefficients.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _node_poses(q, parent, axis, coef, offset, rot, pos):
    for n in range(parent.shape[0]):
        v = offset[n]
        for k in range(q.shape[0]):
            v += coef[n, k] * q[k]
        pn = parent[n]
        for i in range(3):
            for j in range(3):
                rot[n, i, j] = 1.0 if (pn < 0 and i == j) else (rot[pn, i, j] if pn >= 0 else 0.0)
            pos[n, i] = pos[pn, i] if pn >= 0 else 0.0
        a = axis[n] % 3
        if axis[n] < 3:
            b = (a + 1) % 3
            c = (a + 2) % 3
            cv = np.cos(v)
            sv = np.sin(v)
            for i in range(3):
                rb = rot[n, i, b]
                rc = rot[n, i, c]
                rot[n, i, b] = rb * cv + rc * sv
                rot[n, i, c] = -rb * sv + rc * cv
        else:
            for i in range(3):
                pos[n, i] += rot[n, i, a] * v


@njit(cache=True)
def _body_jacobian(b, body_node, body_path, axis, coef, rot, pos, jac):
    """Body-frame Jacobian of body slot ``b`` into ``jac`` (6 x N); returns the body's world rotation.

    The rotation returned is a view of ``rot`` (valid until the next pose); no allocation unless the
    body sits on the base.
    """
    n_dof = jac.shape[1]
    nb = body_node[b]
    if nb >= 0:
        rb = rot[nb]
        pb0, pb1, pb2 = pos[nb, 0], pos[nb, 1], pos[nb, 2]
    else:
        rb = np.eye(3)
        pb0 = pb1 = pb2 = 0.0
    for i in range(6):
        for k in range(n_dof):
            jac[i, k] = 0.0
    for t in range(body_path.shape[1]):
        e = body_path[b, t]
        if e < 0:
            break
        a = axis[e] % 3
        u0 = rb[0, 0] * rot[e, 0, a] + rb[1, 0] * rot[e, 1, a] + rb[2, 0] * rot[e, 2, a]
        u1 = rb[0, 1] * rot[e, 0, a] + rb[1, 1] * rot[e, 1, a] + rb[2, 1] * rot[e, 2, a]
        u2 = rb[0, 2] * rot[e, 0, a] + rb[1, 2] * rot[e, 1, a] + rb[2, 2] * rot[e, 2, a]
        if axis[e] < 3:
            d0 = pos[e, 0] - pb0
            d1 = pos[e, 1] - pb1
            d2 = pos[e, 2] - pb2
            r0 = rb[0, 0] * d0 + rb[1, 0] * d1 + rb[2, 0] * d2
            r1 = rb[0, 1] * d0 + rb[1, 1] * d1 + rb[2, 1] * d2
            r2 = rb[0, 2] * d0 + rb[1, 2] * d1 + rb[2, 2] * d2
            v0 = r1 * u2 - r2 * u1
            v1 = r2 * u0 - r0 * u2
            v2 = r0 * u1 - r1 * u0
            for k in range(n_dof):
                c = coef[e, k]
                if c != 0.0:
                    jac[0, k] += c * v0
                    jac[1, k] += c * v1
                    jac[2, k] += c * v2
                    jac[3, k] += c * u0
                    jac[4, k] += c * u1
                    jac[5, k] += c * u2
        else:
            for k in range(n_dof):
                c = coef[e, k]
                if c != 0.0:
                    jac[0, k] += c * u0
                    jac[1, k] += c * u1
                    jac[2, k] += c * u2
    return rb


@njit(cache=True)
def _cross_axis(a, w0, w1, w2):
    """Components of ``w x e_a``."""
    if a == 0:
        return 0.0, w2, -w1
    if a == 1:
        return -w2, 0.0, w0
    return w1, -w0, 0.0


@njit(cache=True)
def body_regressor(jac, rb, gravity, yh, yg, col):
    """Add one body's H and G regressor columns ``col .. col + 9`` for a body Jacobian ``jac`` (6 x n).

    ``yh`` is (n, n, columns), ``yg`` (n, columns); ``jac`` may be over any coordinates, e.g. the
    actuated ones of a closed loop (``J T``, :mod:`.actuated_kernel`).
    """
    n_dof = jac.shape[1]
    g0 = rb[0, 0] * gravity[0] + rb[1, 0] * gravity[1] + rb[2, 0] * gravity[2]
    g1 = rb[0, 1] * gravity[0] + rb[1, 1] * gravity[1] + rb[2, 1] * gravity[2]
    g2 = rb[0, 2] * gravity[0] + rb[1, 2] * gravity[1] + rb[2, 2] * gravity[2]
    for i in range(n_dof):
        yg[i, col] -= g0 * jac[0, i] + g1 * jac[1, i] + g2 * jac[2, i]
        for a in range(3):
            c0, c1, c2 = _cross_axis(a, jac[3, i], jac[4, i], jac[5, i])
            yg[i, col + 1 + a] -= g0 * c0 + g1 * c1 + g2 * c2
        for j in range(n_dof):
            yh[i, j, col] += jac[0, i] * jac[0, j] + jac[1, i] * jac[1, j] + jac[2, i] * jac[2, j]
            for a in range(3):
                # A_a[i, j] = Jw_i . (e_a x Jv_j) = (Jw_i x e_a) . Jv_j
                c0, c1, c2 = _cross_axis(a, jac[3, i], jac[4, i], jac[5, i])
                aij = c0 * jac[0, j] + c1 * jac[1, j] + c2 * jac[2, j]
                d0, d1, d2 = _cross_axis(a, jac[3, j], jac[4, j], jac[5, j])
                aji = d0 * jac[0, i] + d1 * jac[1, i] + d2 * jac[2, i]
                yh[i, j, col + 1 + a] += aij + aji
            w0i, w1i, w2i = jac[3, i], jac[4, i], jac[5, i]
            w0j, w1j, w2j = jac[3, j], jac[4, j], jac[5, j]
            yh[i, j, col + 4] += w0i * w0j
            yh[i, j, col + 5] += w1i * w1j
            yh[i, j, col + 6] += w2i * w2j
            yh[i, j, col + 7] += w0i * w1j + w1i * w0j
            yh[i, j, col + 8] += w0i * w2j + w2i * w0j
            yh[i, j, col + 9] += w1i * w2j + w2i * w1j


@njit(cache=True)
def regressor_kernel(qs, parent, axis, coef, offset, body_node, body_path, gravity):
    """H and G regressors at poses ``qs`` (P, N).

    Returns ``YH`` (P, N, N, 10 B) and ``YG`` (P, N, 10 B), with the standard parameters of
    body ``b`` in columns ``10 b .. 10 b + 9`` ordered ``m, hx, hy, hz, Jxx, Jyy, Jzz, Jxy, Jxz, Jyz``.
    """
    n_pose, n_dof = qs.shape
    n_body = body_node.shape[0]
    n_node = parent.shape[0]
    yh = np.zeros((n_pose, n_dof, n_dof, 10 * n_body))
    yg = np.zeros((n_pose, n_dof, 10 * n_body))
    rot = np.zeros((max(n_node, 1), 3, 3))
    pos = np.zeros((max(n_node, 1), 3))
    jac = np.zeros((6, n_dof))
    for p in range(n_pose):
        _node_poses(qs[p], parent, axis, coef, offset, rot, pos)
        for b in range(n_body):
            rb = _body_jacobian(b, body_node, body_path, axis, coef, rot, pos, jac)
            body_regressor(jac, rb, gravity, yh[p], yg[p], 10 * b)
    return yh, yg


@njit(cache=True)
def jacobian_kernel(q, parent, axis, coef, offset, body_node, body_path, b):
    """World pose ``(R, p)`` and body-frame Jacobian (6 x N, rows v then w) of body slot ``b``."""
    n_node = parent.shape[0]
    rot = np.zeros((max(n_node, 1), 3, 3))
    pos = np.zeros((max(n_node, 1), 3))
    jac = np.zeros((6, q.shape[0]))
    _node_poses(q, parent, axis, coef, offset, rot, pos)
    rb = _body_jacobian(b, body_node, body_path, axis, coef, rot, pos, jac).copy()
    nb = body_node[b]
    pb = pos[nb].copy() if nb >= 0 else np.zeros(3)
    return rb, pb, jac


@njit(cache=True)
def basis_kernel(qs, kinds, degrees, index):
    """Tensor-product basis functions (see :mod:`.basis`) at poses ``qs`` (P, N) -> (P, B).

    ``kinds``: 0 cyclic, 1 revolute (1, cos q, sin q, cos 2q, sin 2q, ...), 2 prismatic
    (1, q, q^2, ...); multiples of the angle come from the angle-addition recurrence.
    """
    n_pose, n_dof = qs.shape
    n_basis = index.shape[0]
    width = 1
    for k in range(n_dof):
        width = max(width, 2 * degrees[k] + 1)
    values = np.empty((n_dof, width))
    out = np.empty((n_pose, n_basis))
    for p in range(n_pose):
        for k in range(n_dof):
            values[k, 0] = 1.0
            if kinds[k] == 1:
                c = np.cos(qs[p, k])
                s = np.sin(qs[p, k])
                cj, sj = 1.0, 0.0
                for j in range(1, degrees[k] + 1):
                    cj, sj = cj * c - sj * s, sj * c + cj * s
                    values[k, 2 * j - 1] = cj
                    values[k, 2 * j] = sj
            elif kinds[k] == 2:
                for j in range(1, degrees[k] + 1):
                    values[k, j] = values[k, j - 1] * qs[p, k]
        for b in range(n_basis):
            v = 1.0
            for k in range(n_dof):
                if kinds[k] != 0:
                    v *= values[k, index[b, k]]
            out[p, b] = v
    return out
