"""Equations of motion as coefficient tables, evaluated inside numba (seed 000 eq. 2.50).

The :class:`~hapticdesign.analysis.dynamics.model.DynamicsModel` writes every entry of H, C and
G as ``sum_b phi_b(q) coef[b, e]`` with ``phi_b`` a product of 1-D basis functions (revolute:
``1, cos q, sin q, cos 2q, sin 2q, ...``; cyclic: ``1``; prescribed: ``1, q, q^2, ...``) chosen
by the multi-index ``index[b]``. Entries are ``[unique H upper triangle (row-major) | C rows
flattened (N x N(N+1)/2) | G]``. This module carries those tables into numba, as the non-zero
coefficients only (for the 3-DOF Phantom 55 of 19 x 27: most entries of C are zero, and the exact
interpolation leaves round-off of ~1e-17 where a coefficient is zero; coefficients below
``1e-13`` of the largest are dropped).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numba as nb
import numpy as np

from hapticdesign.analysis.dynamics.basis import basis_functions, basis_width
from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.model.device import Device


@dataclass(frozen=True)
class DynamicsTables:
    """Basis coefficients of H, C, G for one parameter set, ready for :func:`evaluate_entries`."""

    coef: np.ndarray  # (n_basis, E)
    index: np.ndarray  # (n_basis, N), int64
    kinds: np.ndarray  # (N,), int64 kind codes (analysis.dynamics.basis.KIND_CODES)
    degrees: np.ndarray  # (N,), int64

    @property
    def n_dof(self) -> int:
        return self.index.shape[1]

    @property
    def n_entries(self) -> int:
        return self.coef.shape[1]

    @cached_property
    def sparse(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(basis rows, entry columns, values)`` of the coefficients that matter."""
        scale = float(np.abs(self.coef).max()) if self.coef.size else 0.0
        rows, cols = np.nonzero(np.abs(self.coef) > 1e-13 * scale)
        return (np.ascontiguousarray(rows, dtype=np.int64), np.ascontiguousarray(cols, dtype=np.int64),
                np.ascontiguousarray(self.coef[rows, cols]))

    @classmethod
    def from_device(cls, device: Device) -> "DynamicsTables":
        model = dynamics_of(device)
        kinds, degrees, index = model.basis_tables
        return cls(np.ascontiguousarray(model.coefficients_for(device.standard_parameters())), index, kinds, degrees)

    @classmethod
    def constant_inertia(cls, inertia: float) -> "DynamicsTables":
        """A 1-DOF body of constant inertia ``J`` (no Coriolis, no gravity): ``tau = J qdd``."""
        return cls(
            coef=np.array([[float(inertia), 0.0, 0.0]]),
            index=np.zeros((1, 1), dtype=np.int64),
            kinds=np.zeros(1, dtype=np.int64),
            degrees=np.zeros(1, dtype=np.int64),
        )


@nb.njit(cache=True, error_model="numpy", inline="always")
def evaluate_entries(q, rows, cols, vals, index, kinds, degrees, values, phi, out):
    """All entries at ``q`` into ``out`` (E,) from the sparse table ``(rows, cols, vals)``;
    ``values`` (N, max basis size) and ``phi`` (n_basis,) are workspace
    (:func:`~hapticdesign.analysis.dynamics.basis.basis_functions`)."""
    basis_functions(q, kinds, degrees, index, values, phi)
    out[:] = 0.0
    for t in range(rows.shape[0]):
        out[cols[t]] += phi[rows[t]] * vals[t]


@nb.njit(cache=True, error_model="numpy", inline="always")
def unpack_entries(entries, n, h, c, g):
    """Entries -> ``H`` (N, N), ``C`` (N, N(N+1)/2) and ``G`` (N,)."""
    m = n * (n + 1) // 2
    u = 0
    for i in range(n):
        for j in range(i, n):
            h[i, j] = entries[u]
            h[j, i] = entries[u]
            u += 1
    for i in range(n):
        for col in range(m):
            c[i, col] = entries[m + i * m + col]
    for i in range(n):
        g[i] = entries[m + n * m + i]


def workspace_size(tables: DynamicsTables) -> int:
    """Columns of the per-coordinate basis workspace."""
    return int(basis_width(tables.kinds, tables.degrees))
