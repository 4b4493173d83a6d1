"""Exact finite bases for the configuration dependence of H, C and G.

With revolute joints, every entry of H, C and G is a trigonometric polynomial in each joint
angle (seed 000 §3.1: degree at most 2 for the Phantom); with prismatic joints it is a
polynomial in the joint displacement. On a tensor grid of ``2d + 1`` equally spaced angles
(``d + 1`` displacements) such a function is interpolated exactly, which gives the exact
coefficients used for fast evaluation, for C (differentiation of the basis) and for the exact
Linearity Number (averages of products of basis functions).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np


class CoordinateKind(str, Enum):
    CYCLIC = "cyclic"  # does not enter H, C, G (theta1 of the Phantom)
    REVOLUTE = "revolute"  # 1, cos q, sin q, cos 2q, sin 2q, ...
    PRISMATIC = "prismatic"  # 1, q, q^2, ...


@dataclass(frozen=True)
class CoordinateBasis:
    """One-dimensional basis of one coordinate: ``size`` functions, interpolated on ``nodes``."""

    kind: CoordinateKind
    degree: int
    scale: float = 0.1

    @property
    def size(self) -> int:
        if self.kind is CoordinateKind.CYCLIC:
            return 1
        if self.kind is CoordinateKind.REVOLUTE:
            return 2 * self.degree + 1
        return self.degree + 1

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
        out = np.empty(q.shape + (self.size,))
        out[..., 0] = 1.0
        if self.kind is CoordinateKind.REVOLUTE:
            for j in range(1, self.degree + 1):
                out[..., 2 * j - 1] = np.cos(j * q)
                out[..., 2 * j] = np.sin(j * q)
        elif self.kind is CoordinateKind.PRISMATIC:
            for j in range(1, self.size):
                out[..., j] = q**j
        return out

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
    qs = np.atleast_2d(np.asarray(qs, dtype=float))
    out = np.ones((qs.shape[0], index.shape[0]))
    for k, b in enumerate(bases):
        if b.size == 1:
            continue
        out *= b.values(qs[:, k])[:, index[:, k]]
    return out


def apply_along(tensor: np.ndarray, matrix: np.ndarray, axis: int) -> np.ndarray:
    """Contract ``matrix`` (n_out, n_in) with one axis of ``tensor``."""
    moved = np.tensordot(matrix, tensor, axes=([1], [axis]))
    return np.moveaxis(moved, 0, axis)
