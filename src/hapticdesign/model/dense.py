"""Small dense linear solves inside compiled kernels (numba): Gaussian elimination with partial pivoting.

The closed-loop kernels factor the passive block of the constraint Jacobian, ``Phi_p`` (a few rows),
at every Newton iteration and every pose (:func:`lu_in_place`, with the pivot ratio they judge conditioning
by); the rendering loop solves ``H qdd = rhs`` for its free joints at every RK4 stage (:func:`solve_leading`,
inlined into the loop: a call per stage costs the 3-DOF Phantom's 5-s run about 14 %). A library call would
allocate, so both are written here, in place.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, _nrt=False)
def lu_in_place(u, x):
    """Solve ``u x = b`` (m x m, m x k) by Gaussian elimination with partial pivoting: ``x`` holds ``b`` on entry
    and the solution on return, ``u`` is overwritten (no allocation; one division per pivot).

    Returns the pivot ratio ``min |u_ii| / max |u_ii|`` (0 when singular; a cheap estimate of the
    reciprocal condition number) and the sign of ``det u``.
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


@njit(cache=True, error_model="numpy", inline="always")
def solve_leading(a, b, n):
    """Solve the leading ``n x n`` block ``a[:n, :n] x = b[:n]`` by Gaussian elimination with partial pivoting;
    ``b`` holds the solution on return, ``a`` is overwritten (a singular block gives inf or NaN)."""
    for col in range(n):
        piv = col
        for r in range(col + 1, n):
            if abs(a[r, col]) > abs(a[piv, col]):
                piv = r
        if piv != col:
            for k in range(n):
                a[col, k], a[piv, k] = a[piv, k], a[col, k]
            b[col], b[piv] = b[piv], b[col]
        for r in range(col + 1, n):
            f = a[r, col] / a[col, col]
            for k in range(col, n):
                a[r, k] -= f * a[col, k]
            b[r] -= f * b[col]
    for col in range(n - 1, -1, -1):
        s = b[col]
        for k in range(col + 1, n):
            s -= a[col, k] * b[k]
        b[col] = s / a[col, col]
