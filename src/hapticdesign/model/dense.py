"""Small dense linear solves inside compiled kernels (numba): Gaussian elimination with partial pivoting.

The closed-loop kernels factor the passive block of the constraint Jacobian, ``Phi_p`` (a few rows),
at every Newton iteration and every pose (:func:`lu_in_place`, with the pivot ratio they judge conditioning
by); the rendering loop solves ``H qdd = rhs`` for its free joints at every RK4 stage (:func:`solve_leading`,
inlined into the loop: a call per stage costs the 3-DOF Phantom's 5-s run about 14 %). A library call would
allocate, so both are written here, in place. The design indices take the eigenvalues of thousands of small
symmetric positive definite matrices at once (:func:`symmetric_eigenvalues`), where LAPACK's cost per call
would dominate.
"""

from __future__ import annotations

import numpy as np
from numba import njit

JACOBI_SWEEPS = 40
"""Most sweeps of the cyclic Jacobi iteration of :func:`symmetric_eigenvalues` (a few converge quadratically)."""


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


def symmetric_eigenvalues(a: np.ndarray) -> np.ndarray:
    """The eigenvalues (..., k), ascending, of symmetric positive (semi)definite matrices ``a`` (..., k, k), by cyclic
    Jacobi rotations (each to within a few ulps of the largest, as LAPACK's ``eigvalsh``; the lower triangle is
    read)."""
    a = np.asarray(a, dtype=float)
    k = a.shape[-1]
    flat = np.ascontiguousarray(a).reshape(-1, k, k)
    out = np.empty((len(flat), k))
    _jacobi_eigenvalues(flat, out)
    return out.reshape(*a.shape[:-1])


@njit(cache=True)
def _jacobi_eigenvalues(a, out):
    """:func:`symmetric_eigenvalues` of ``a`` (P, k, k) into ``out`` (P, k)."""
    k = a.shape[1]
    eps = np.finfo(np.float64).eps
    w = np.empty((k, k))
    for p in range(a.shape[0]):
        for i in range(k):
            for j in range(i + 1):
                w[i, j] = a[p, i, j]
                w[j, i] = a[p, i, j]
        for _ in range(JACOBI_SWEEPS):
            rotated = False
            for r in range(k - 1):
                for c in range(r + 1, k):
                    off = w[r, c]
                    if off == 0.0 or abs(off) <= eps * np.sqrt(abs(w[r, r] * w[c, c])):
                        continue
                    rotated = True
                    theta = (w[c, c] - w[r, r]) / (2.0 * off)
                    t = (1.0 if theta >= 0.0 else -1.0) / (abs(theta) + np.sqrt(theta * theta + 1.0))
                    cs = 1.0 / np.sqrt(t * t + 1.0)
                    sn = t * cs
                    w[r, r] -= t * off
                    w[c, c] += t * off
                    w[r, c] = 0.0
                    w[c, r] = 0.0
                    for i in range(k):
                        if i != r and i != c:
                            wr, wc = w[i, r], w[i, c]
                            w[i, r] = cs * wr - sn * wc
                            w[r, i] = w[i, r]
                            w[i, c] = sn * wr + cs * wc
                            w[c, i] = w[i, c]
            if not rotated:
                break
        for i in range(k):
            out[p, i] = w[i, i]
        for i in range(1, k):  # insertion sort, ascending
            at = i
            while at > 0 and out[p, at] < out[p, at - 1]:
                out[p, at], out[p, at - 1] = out[p, at - 1], out[p, at]
                at -= 1
