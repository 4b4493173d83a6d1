"""Compiled (numba) kernel: inertia-matrix and gravity regressors of any frame tree.

For every body ``b`` with body-frame Jacobian ``J_b = [Jv; Jw]`` (6 x N), the kinetic energy
``1/2 qd^T H qd`` is linear in the standard parameters ``(m, h, J)`` of the body
(see :mod:`hapticdesign.model.inertia`)::

    H_b = m Jv^T Jv + sum_a h_a (A_a + A_a^T) + sum_ab J_ab Jw_a^T Jw_b,   A_a = Jw^T S(e_a) Jv

and the gravity torque of the potential of seed 000 eq. 2.46 is
``G_k = -(R_b^T g) . (m Jv_k + Jw_k x h)``. This is the regressor form of eq. 2.44-2.49.
The Jacobian column of a variable elementary transform ``e`` is its unit twist moved to the
body frame; dependent coordinates contribute through their affine coefficients (the walk of
:mod:`hapticdesign.model.walk`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hapticdesign.model.walk import frame_jacobian, node_poses


@njit(cache=True)
def body_jacobian(b, body_node, parent, axis, coef, rot, pos, eye, jac):
    """Body-frame Jacobian of body slot ``b`` into ``jac`` (6 x N); returns the body's world rotation.

    The rotation returned is a view of ``rot`` (valid until the next pose), or ``eye`` for a body on
    the base; no allocation.
    """
    nb = body_node[b]
    frame_jacobian(nb, parent, axis, coef, rot, pos, np.bool_(True), jac)  # a literal would compile its own copy
    return rot[nb] if nb >= 0 else eye


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
def regressor_kernel(qs, parent, axis, coef, offset, const_rot, const_pos, body_node, gravity):
    """H and G regressors at poses ``qs`` (P, N) on a :class:`~hapticdesign.model.walk.KinematicTree`.

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
    eye = np.eye(3)
    for p in range(n_pose):
        node_poses(qs[p], parent, axis, coef, offset, const_rot, const_pos, n_node - 1, rot, pos)
        for b in range(n_body):
            rb = body_jacobian(b, body_node, parent, axis, coef, rot, pos, eye, jac)
            body_regressor(jac, rb, gravity, yh[p], yg[p], 10 * b)
    return yh, yg
