"""Exact finite bases for the configuration dependence of H, C and G.

With revolute joints, every entry of H, C and G is a trigonometric polynomial in each joint
angle (seed 000 §3.1: degree at most 2 for the Phantom); with prismatic joints it is a
polynomial in the joint displacement. On a tensor grid of ``2d + 1`` equally spaced angles
(``d + 1`` displacements) such a function is interpolated exactly, which gives the exact
coefficients used for fast evaluation, for C (differentiation of the basis) and for the exact
Linearity Number (averages of products of basis functions).

The basis functions are evaluated in one compiled place (:func:`coordinate_values`, multiples of
the angle by the angle-addition recurrence: two libm calls per joint, not two per degree), used
by :class:`CoordinateBasis`, the dynamics model and the simulation's sampled-data kernel.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np
from numba import njit

CYCLIC_CODE, REVOLUTE_CODE, PRISMATIC_CODE = 0, 1, 2
"""Integer codes of the coordinate kinds in the compiled evaluation."""


class CoordinateKind(str, Enum):
    CYCLIC = "cyclic"  # does not enter H, C, G (theta1 of the Phantom)
    REVOLUTE = "revolute"  # 1, cos q, sin q, cos 2q, sin 2q, ...
    PRISMATIC = "prismatic"  # 1, q, q^2, ...


KIND_CODES = {CoordinateKind.CYCLIC: CYCLIC_CODE, CoordinateKind.REVOLUTE: REVOLUTE_CODE,
              CoordinateKind.PRISMATIC: PRISMATIC_CODE}


@njit(cache=True, error_model="numpy", inline="always")
def basis_size(kind, degree):
    """Number of 1-D basis functions of a coordinate of kind code ``kind`` and ``degree``."""
    if kind == REVOLUTE_CODE:
        return 2 * degree + 1
    if kind == PRISMATIC_CODE:
        return degree + 1
    return 1


@njit(cache=True, error_model="numpy", inline="always")
def coordinate_values(q, kind, degree, out):
    """1-D basis functions of one coordinate at ``q`` into ``out[:size]``.

    Revolute: ``1, cos q, sin q, cos 2q, sin 2q, ...`` (angle addition); prismatic: ``1, q, q^2, ...``;
    cyclic: ``1``.
    """
    out[0] = 1.0
    if kind == REVOLUTE_CODE and degree > 0:
        c1, s1 = np.cos(q), np.sin(q)
        out[1] = c1
        out[2] = s1
        for j in range(2, degree + 1):
            cj, sj = out[2 * j - 3], out[2 * j - 2]
            out[2 * j - 1] = c1 * cj - s1 * sj
            out[2 * j] = s1 * cj + c1 * sj
    elif kind == PRISMATIC_CODE:
        for j in range(1, degree + 1):
            out[j] = out[j - 1] * q


@njit(cache=True, error_model="numpy", inline="always")
def basis_functions(q, kinds, degrees, index, values, phi):
    """Tensor-product basis functions at one pose ``q`` (N,) into ``phi`` (B,) for multi-indices ``index`` (B, N).

    ``values`` (N, :func:`basis_width`) is workspace.
    """
    n = q.shape[0]
    for k in range(n):
        coordinate_values(q[k], kinds[k], degrees[k], values[k])
    for b in range(index.shape[0]):
        v = 1.0
        for k in range(n):
            v *= values[k, index[b, k]]
        phi[b] = v


@njit(cache=True)
def basis_width(kinds, degrees):
    """Largest 1-D basis size over the coordinates (columns of the ``values`` workspace)."""
    width = 1
    for k in range(kinds.shape[0]):
        width = max(width, basis_size(kinds[k], degrees[k]))
    return width


@njit(cache=True)
def basis_kernel(qs, kinds, degrees, index):
    """Basis functions at poses ``qs`` (P, N) -> (P, B) (:func:`basis_functions` pose by pose)."""
    values = np.empty((qs.shape[1], basis_width(kinds, degrees)))
    out = np.empty((qs.shape[0], index.shape[0]))
    for p in range(qs.shape[0]):
        basis_functions(qs[p], kinds, degrees, index, values, out[p])
    return out


@dataclass(frozen=True)
class CoordinateBasis:
    """One-dimensional basis of one coordinate: ``size`` functions, interpolated on ``nodes``."""

    kind: CoordinateKind
    degree: int
    scale: float = 0.1

    @property
    def size(self) -> int:
        return basis_size(KIND_CODES[self.kind], self.degree)

    @property
    def nodes(self) -> np.ndarray:
        if self.kind is CoordinateKind.CYCLIC:
            return np.zeros(1)
        if self.kind is CoordinateKind.REVOLUTE:
            return 2 * np.pi * np.arange(self.size) / self.size
        return self.scale * np.linspace(-1.0, 1.0, self.size)

    def values(self, q: np.ndarray) -> np.ndarray:
        """Basis functions at ``q`` (P,) -> (P, size)."""
        q = np.asarray(q, dtype=float)
        flat = np.ascontiguousarray(q.reshape(-1, 1))
        code, degree = np.array([KIND_CODES[self.kind]]), np.array([self.degree])
        out = basis_kernel(flat, code, degree, np.arange(self.size).reshape(-1, 1))
        return out.reshape(q.shape + (self.size,))

    def derivative(self) -> np.ndarray:
        """Matrix ``D`` with ``d/dq phi_i = sum_j D[i, j] phi_j``."""
        d = np.zeros((self.size, self.size))
        if self.kind is CoordinateKind.REVOLUTE:
            for j in range(1, self.degree + 1):
                d[2 * j - 1, 2 * j] = -j
                d[2 * j, 2 * j - 1] = j
        elif self.kind is CoordinateKind.PRISMATIC:
            for j in range(1, self.size):
                d[j, j - 1] = j
        return d

    def interpolation(self) -> np.ndarray:
        """Matrix mapping values on ``nodes`` to basis coefficients."""
        return np.linalg.inv(self.values(self.nodes))

    def mean_gram(self) -> np.ndarray:
        """``E[phi_i phi_j]`` for the angle uniform on [0, 2 pi] (revolute, cyclic only)."""
        if self.kind is CoordinateKind.PRISMATIC:
            raise ValueError("the torus average is defined for revolute coordinates only")
        g = np.zeros((self.size, self.size))
        g[0, 0] = 1.0
        for i in range(1, self.size):
            g[i, i] = 0.5
        return g


def grid(bases: list[CoordinateBasis]) -> np.ndarray:
    """All tensor-grid poses, (prod sizes, N), last coordinate fastest."""
    mesh = np.meshgrid(*[b.nodes for b in bases], indexing="ij")
    return np.stack([m.ravel() for m in mesh], axis=-1)


def tensor_values(bases: list[CoordinateBasis], qs: np.ndarray, index: np.ndarray) -> np.ndarray:
    """Products of 1-D basis functions for the multi-indices ``index`` (B, N) at poses (P, N)."""
    qs = np.ascontiguousarray(np.atleast_2d(np.asarray(qs, dtype=float)))
    kinds = np.array([KIND_CODES[b.kind] for b in bases], dtype=np.int64)
    degrees = np.array([b.degree for b in bases], dtype=np.int64)
    return basis_kernel(qs, kinds, degrees, np.ascontiguousarray(index, dtype=np.int64))


def apply_along(tensor: np.ndarray, matrix: np.ndarray, axis: int) -> np.ndarray:
    """Contract ``matrix`` (n_out, n_in) with one axis of ``tensor``."""
    moved = np.tensordot(matrix, tensor, axes=([1], [axis]))
    return np.moveaxis(moved, 0, axis)
