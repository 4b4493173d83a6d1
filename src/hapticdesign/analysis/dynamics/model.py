"""Equations of motion in the seed's form (seed 000 eq. 2.50-2.52), in regressor form.

``tau = H(q) qdd + C(q) qd^2 + G(q)`` with ``qd^2 = (qd1 qd1, qd1 qd2, ..., qdN qdN)``. Every
entry of H, C and G is linear in the standard inertial parameters ``pi`` (see
:mod:`hapticdesign.model.inertia`) and an exact finite sum of basis functions of ``q``
(:mod:`.basis`), so the whole model is one coefficient tensor ``A[basis, entry, parameter]``:

    entry(q; pi) = sum_b phi_b(q) sum_p A[b, entry, p] pi_p

H and G come from the compiled kernel (:mod:`.kernel`) interpolated on an exact grid; C from
the Christoffel symbols ``Gamma_ijk = (dH_ij/dq_k + dH_ik/dq_j - dH_jk/dq_i) / 2``, obtained by
differentiating the basis (the column of pair (j, k) holds ``Gamma_ijj`` or ``2 Gamma_ijk``,
as in Appendix A.2). ``C_cvt`` is eq. 2.52: ``C_cvt_ij = sum_k Gamma_ijk qd_k``.
"""

from __future__ import annotations

import copy
from functools import cached_property
from typing import Protocol, runtime_checkable

import numpy as np
from numba import njit

from hapticdesign.analysis.dynamics.basis import (
    KIND_CODES,
    CoordinateBasis,
    CoordinateKind,
    apply_along,
    basis_kernel,
    grid,
    tensor_values,
)
from hapticdesign.analysis.dynamics.kernel import regressor_kernel
from hapticdesign.errors import UserError
from hapticdesign.model.mechanism import CompiledMechanism, Mechanism


def pair_index(n: int) -> list[tuple[int, int]]:
    """Ordered pairs (j, k), j <= k, of eq. 2.50's ``thetadot^2``: (1,1), (1,2), ..., (N,N)."""
    return [(j, k) for j in range(n) for k in range(j, n)]


@njit(cache=True, error_model="numpy", inline="always")
def velocity_products_into(qd, out):
    """``thetadot^2`` of eq. 2.50 for one velocity vector (N,) into ``out``: (1,1), (1,2), ..., (N,N)."""
    n = qd.shape[0]
    u = 0
    for j in range(n):
        for k in range(j, n):
            out[u] = qd[j] * qd[k]
            u += 1


@njit(cache=True)
def _velocity_products_rows(qd, out):
    for p in range(qd.shape[0]):
        velocity_products_into(qd[p], out[p])


def velocity_products(qd: np.ndarray) -> np.ndarray:
    """``thetadot^2`` of eq. 2.50 for velocities (..., N) -> (..., N(N+1)/2)."""
    qd = np.asarray(qd, dtype=float)
    n = qd.shape[-1]
    flat = np.ascontiguousarray(qd.reshape(-1, n))
    out = np.empty((flat.shape[0], n * (n + 1) // 2))
    _velocity_products_rows(flat, out)
    return out.reshape(qd.shape[:-1] + (out.shape[1],))


def _float_array(value, what: str, n: int) -> np.ndarray:
    """``value`` as a float array of shape (n,) or (P, n); anything else is a :class:`UserError`."""
    if value is None:
        raise UserError(f"{what} must be numbers: a vector of {n} or an array (P, {n}), got None")
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise UserError(f"{what} must be numbers: a vector of {n} or an array (P, {n}), got {type(value).__name__}") from None
    if array.ndim not in (1, 2):
        raise UserError(f"{what} must be a vector of {n} or an array (P, {n}), got an array of shape {array.shape}")
    return array


def _require_basis_memory(bases: list[CoordinateBasis], n_dof: int, n_params: int) -> None:
    """Refuse, before building it, an exact basis this machine should not or cannot hold."""
    from hapticdesign.workload import basis_bytes, require_memory

    points = int(np.prod([b.size for b in bases], dtype=float))
    kinds = ", ".join(f"{sum(b.kind is k for b in bases)} {k.value}" for k in CoordinateKind
                      if any(b.kind is k for b in bases))
    degree = max((b.degree for b in bases), default=0)
    require_memory(f"the exact equations of motion of a {n_dof}-joint device ({kinds}; degree {degree}, "
                   f"{points:,} grid poses)", basis_bytes(points, n_dof, n_params))


class EquationsOfMotion:
    """H, C, C_cvt, G, inverse and forward dynamics from the entries (unique H, C, G; eq. 2.50-2.52) of a subclass.

    A subclass sets ``mechanism``, ``n_dof``, ``n_params``, ``pairs`` and the slices ``slice_h``, ``slice_c``,
    ``slice_g`` of its entries, and gives ``entries`` (P, E) or (S, P, E) and ``entry_regressor``:
    :class:`DynamicsModel` from its exact basis, :class:`~.closed_loop.ClosedLoopModel` pose by pose.
    Arrays of poses ``q`` have shape (P, N) or (N,); parameters have shape (n_params,) or (S, n_params) for
    S parameter sets at once (results then lead with S). ``constant`` (None, or one value per entry) is added
    to every evaluation: the reflected rotor inertia of actuators.
    """

    constant: np.ndarray | None = None

    def _poses(self, q: np.ndarray) -> np.ndarray:
        q = _float_array(q, "joint coordinates", self.n_dof)
        if q.shape[-1] != self.n_dof:
            raise UserError(f"expected {self.n_dof} joint coordinates, got {q.shape[-1]}")
        if not np.all(np.isfinite(q)):
            raise UserError("joint coordinates must be finite numbers (got NaN or infinity)")
        return np.atleast_2d(q)

    def _params(self, pi: np.ndarray) -> np.ndarray:
        pi = _float_array(pi, "standard inertial parameters", self.n_params)
        if pi.shape[-1] != self.n_params:
            raise UserError(f"expected {self.n_params} standard inertial parameters, got {pi.shape[-1]}")
        if not np.all(np.isfinite(pi)):
            raise UserError("standard inertial parameters must be finite numbers (got NaN or infinity)")
        return pi

    def _squeeze(self, q: np.ndarray, out: np.ndarray) -> np.ndarray:
        return out[..., 0, :] if np.asarray(q).ndim == 1 else out

    def _h_from(self, e: np.ndarray) -> np.ndarray:
        n = self.n_dof
        iu, ju = np.triu_indices(n)
        h = np.empty(e.shape[:-1] + (n, n))
        h[..., iu, ju] = e[..., self.slice_h]
        h[..., ju, iu] = e[..., self.slice_h]
        return h

    def H(self, q: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """Mass matrix (eq. 2.50)."""
        h = self._h_from(self.entries(q, pi))
        return h[..., 0, :, :] if np.asarray(q).ndim == 1 else h

    def C(self, q: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """Coriolis and centrifugal matrix, N x N(N+1)/2 (eq. 2.50)."""
        e = self.entries(q, pi)[..., self.slice_c]
        c = e.reshape(e.shape[:-1] + (self.n_dof, len(self.pairs)))
        return c[..., 0, :, :] if np.asarray(q).ndim == 1 else c

    def G(self, q: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """Gravity torques (eq. 2.50)."""
        return self._squeeze(q, self.entries(q, pi)[..., self.slice_g])

    def christoffel(self, q: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """``Gamma_ijk`` (..., N, N, N) recovered from C."""
        c = self.C(q, pi)
        n = self.n_dof
        gamma = np.empty(c.shape[:-1] + (n, n))
        for col, (j, k) in enumerate(self.pairs):
            if j == k:
                gamma[..., j, j] = c[..., col]
            else:
                gamma[..., j, k] = gamma[..., k, j] = 0.5 * c[..., col]
        return gamma

    def C_cvt(self, q: np.ndarray, qd: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """N x N Coriolis matrix of eq. 2.51-2.52, ``C_cvt_ij = sum_k Gamma_ijk qd_k``."""
        qd = self._velocities(qd, q)
        return np.einsum("...ijk,...k->...ij", self.christoffel(q, pi), qd)

    def _velocities(self, v: np.ndarray, q: np.ndarray) -> np.ndarray:
        v = _float_array(v, "joint rates", self.n_dof)
        if v.shape[-1] != self.n_dof:
            raise UserError(f"expected {self.n_dof} joint rates, got {v.shape[-1]}")
        if not np.all(np.isfinite(v)):
            raise UserError("joint rates must be finite numbers (got NaN or infinity)")
        return v

    def inverse(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """Inverse dynamics ``tau = H qdd + C qd^2 + G`` (eq. 2.50)."""
        e = self.entries(q, pi)
        qd = self._velocities(qd, q)
        qdd = self._velocities(qdd, q)
        h = self._h_from(e)
        c = e[..., self.slice_c].reshape(e.shape[:-1] + (self.n_dof, len(self.pairs)))
        qd2 = velocity_products(np.atleast_2d(qd))
        tau = (
            np.einsum("...ij,...j->...i", h, np.atleast_2d(qdd))
            + np.einsum("...ic,...c->...i", c, qd2)
            + e[..., self.slice_g]
        )
        return self._squeeze(q, tau)

    def forward(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """Forward dynamics ``qdd = H^-1 (tau - C qd^2 - G)``."""
        e = self.entries(q, pi)
        qd = self._velocities(qd, q)
        tau = self._velocities(tau, q)
        h = self._h_from(e)
        c = e[..., self.slice_c].reshape(e.shape[:-1] + (self.n_dof, len(self.pairs)))
        rhs = np.atleast_2d(tau) - np.einsum("...ic,...c->...i", c, velocity_products(np.atleast_2d(qd))) - e[..., self.slice_g]
        try:
            qdd = np.linalg.solve(h, rhs[..., None])[..., 0]
        except np.linalg.LinAlgError:
            raise UserError("the mass matrix is singular at this pose (check the inertial parameters)") from None
        return self._squeeze(q, qdd)

    def regressor(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """Joint-torque regressor ``Y`` with ``tau = Y pi``: (P, N, n_params) or (N, n_params).

        ``Y pi`` leaves out a :attr:`constant` (reflected rotor inertia ``h``: add ``h qdd``).
        """
        e = self.entry_regressor(q)  # (P, E, n_params)
        n, m = self.n_dof, len(self.pairs)
        h = self._h_from(np.moveaxis(e, -1, 1)).transpose(0, 2, 3, 1)  # (P, N, N, n_params)
        c = e[:, self.slice_c].reshape(e.shape[0], n, m, self.n_params)
        qd2 = velocity_products(np.atleast_2d(self._velocities(qd, q)))
        y = (
            np.einsum("pijn,pj->pin", h, np.atleast_2d(self._velocities(qdd, q)))
            + np.einsum("picn,pc->pin", c, qd2)
            + e[:, self.slice_g]
        )
        return y[0] if np.asarray(q).ndim == 1 else y


@runtime_checkable
class ExactBasis(Protocol):
    """What a model with an exact basis of H, C, G offers (a tree's :class:`DynamicsModel`): the basis functions,
    their tables for compiled evaluation, the coefficients for a parameter set and the coordinates that enter
    nothing. The Linearity Number's exact moments and the simulation's tables need it; a closed-loop model
    has none (its LN uses quadrature, its simulation the compiled plant)."""

    cyclic: tuple[bool, ...]

    def basis(self, q: np.ndarray) -> np.ndarray: ...

    @property
    def basis_tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...

    def coefficients_for(self, pi: np.ndarray) -> np.ndarray: ...


def has_trigonometric_basis(mechanism: Mechanism) -> bool:
    """Whether the mechanism's H, C and G have an exact trigonometric basis (:class:`ExactBasis`), which the LN = 0
    conditions (seed 000 eq. 3.12-3.27), the symbolic engine and the simulation's tables need: a tree's have (no
    closures, an empty constraint list); a closed loop's entries, reduced to the actuated coordinates pose by pose,
    are no trigonometric polynomials of them."""
    return mechanism.loops.empty


class DynamicsModel(EquationsOfMotion):
    """Regressor model of one tree geometry on its exact basis (:class:`ExactBasis`); parameters ``pi`` are
    inputs of every call.

    ``constant`` (:meth:`with_constant_inertia`: the reflected rotor inertia) enters the constant basis
    function; ``coefficients`` and :meth:`regressor` stay purely linear in the inertial parameters.
    """

    def __init__(self, mechanism: Mechanism, max_degree: int = 4, tol: float = 1e-10, seed: int = 0):
        self.mechanism = mechanism
        self.compiled: CompiledMechanism = mechanism.compiled
        self.n_dof = mechanism.n_dof
        self.n_params = 10 * len(mechanism.bodies)
        self.pairs = pair_index(self.n_dof)
        rng = np.random.default_rng(seed)
        kinds = self._coordinate_kinds(rng)
        degree = 2
        while True:
            bases = [
                CoordinateBasis(kind, 0 if kind is CoordinateKind.CYCLIC else degree) for kind in kinds
            ]
            coef_hg = self._fit(bases)
            if self._fit_error(bases, coef_hg, rng) <= tol:
                break
            degree += 1
            if degree > max_degree:
                raise UserError(
                    "the equations of motion are not a trigonometric polynomial of degree "
                    f"<= {max_degree} in the joint angles (check the joint couplings)"
                )
        self.bases = bases
        self._build_tables(coef_hg)

    # -- construction -----------------------------------------------------------------------
    def _regressors(self, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        tree = self.compiled.tree
        return regressor_kernel(np.ascontiguousarray(qs, dtype=float), *tree.arrays, tree.body_node, self.compiled.gravity)

    def _coordinate_kinds(self, rng: np.random.Generator) -> list[CoordinateKind]:
        from hapticdesign.workload import require_memory

        n = self.n_dof
        require_memory(f"probing the equations of motion of a {n}-joint device with {len(self.mechanism.bodies)} "
                       "bodies", 4 * 3 * 8.0 * (n * n + n) * self.n_params)
        q0 = rng.uniform(-np.pi, np.pi, (3, self.n_dof))
        yh0, yg0 = self._regressors(q0)
        scale = max(np.abs(yh0).max(), np.abs(yg0).max(), 1e-300)
        kinds = []
        for k in range(self.n_dof):
            if self.compiled.prismatic[k]:
                kinds.append(CoordinateKind.PRISMATIC)
                continue
            q1 = q0.copy()
            q1[:, k] += rng.uniform(0.5, 2.5, 3)
            yh1, yg1 = self._regressors(q1)
            moved = max(np.abs(yh1 - yh0).max(), np.abs(yg1 - yg0).max())
            kinds.append(CoordinateKind.CYCLIC if moved <= 1e-13 * scale else CoordinateKind.REVOLUTE)
        return kinds

    def _fit(self, bases: list[CoordinateBasis]) -> np.ndarray:
        """Basis coefficients of the unique H entries and G: (prod sizes, N(N+1)/2 + N, n_params)."""
        n = self.n_dof
        _require_basis_memory(bases, n, self.n_params)
        yh, yg = self._regressors(grid(bases))
        iu, ju = np.triu_indices(n)
        values = np.concatenate([yh[:, iu, ju, :], yg], axis=1)
        shape = tuple(b.size for b in bases)
        tensor = values.reshape(shape + values.shape[1:])
        for axis, b in enumerate(bases):
            if b.size > 1:
                tensor = apply_along(tensor, b.interpolation(), axis)
        return tensor.reshape((-1,) + values.shape[1:])

    def _full_index(self, bases: list[CoordinateBasis]) -> np.ndarray:
        mesh = np.meshgrid(*[np.arange(b.size) for b in bases], indexing="ij")
        return np.stack([m.ravel() for m in mesh], axis=-1)

    def _fit_error(self, bases, coef_hg, rng) -> float:
        qs = rng.uniform(-np.pi, np.pi, (6, self.n_dof))
        for k, b in enumerate(bases):
            if b.kind is CoordinateKind.PRISMATIC:
                qs[:, k] = rng.uniform(-b.scale, b.scale, 6)
        yh, yg = self._regressors(qs)
        iu, ju = np.triu_indices(self.n_dof)
        exact = np.concatenate([yh[:, iu, ju, :], yg], axis=1)
        phi = tensor_values(bases, qs, self._full_index(bases))
        approx = np.tensordot(phi, coef_hg, axes=(1, 0))
        scale = max(np.abs(exact).max(), 1e-300)
        return float(np.abs(approx - exact).max() / scale)

    def _build_tables(self, coef_hg: np.ndarray) -> None:
        n = self.n_dof
        m = len(self.pairs)
        shape = tuple(b.size for b in self.bases)
        h_unique = coef_hg[:, :m, :].reshape(shape + (m, self.n_params))
        g = coef_hg[:, m:, :]
        upper = {pair: u for u, pair in enumerate(self.pairs)}

        def h_col(i: int, j: int) -> int:
            return upper[(min(i, j), max(i, j))]

        dh = []
        for axis, b in enumerate(self.bases):
            dh.append(apply_along(h_unique, b.derivative().T, axis).reshape((-1, m, self.n_params)))
        c = np.zeros((coef_hg.shape[0], n * m, self.n_params))
        for i in range(n):
            for col, (j, k) in enumerate(self.pairs):
                gamma = 0.5 * (dh[k][:, h_col(i, j)] + dh[j][:, h_col(i, k)] - dh[i][:, h_col(j, k)])
                c[:, i * m + col] = gamma if j == k else 2.0 * gamma
        table = np.concatenate([coef_hg[:, :m, :], c, g], axis=1)
        keep = np.abs(table).max(axis=(1, 2)) > 1e-13 * max(np.abs(table).max(), 1e-300)
        keep[0] = True
        self.index = self._full_index(self.bases)[keep]
        self.coefficients = np.ascontiguousarray(table[keep])
        self.slice_h = slice(0, m)
        self.slice_c = slice(m, m + n * m)
        self.slice_g = slice(m + n * m, m + n * m + n)

    # -- evaluation -------------------------------------------------------------------------
    @property
    def n_basis(self) -> int:
        return self.index.shape[0]

    def basis(self, q: np.ndarray) -> np.ndarray:
        """Basis functions at poses (P, N) -> (P, n_basis), compiled (:func:`.basis.basis_kernel`)."""
        return basis_kernel(np.ascontiguousarray(self._poses(q)), *self.basis_tables)

    @cached_property
    def basis_tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(kinds, degrees, index)`` of the basis as int64 arrays: kind codes (:data:`.basis.KIND_CODES`)
        and degree per coordinate, multi-index per basis function; what the compiled evaluations take."""
        kinds = np.array([KIND_CODES[b.kind] for b in self.bases], dtype=np.int64)
        degrees = np.array([b.degree for b in self.bases], dtype=np.int64)
        return kinds, degrees, np.ascontiguousarray(self.index, dtype=np.int64)

    def with_constant_inertia(self, h: np.ndarray) -> "DynamicsModel":
        """This model with the constant matrix ``h`` (N, N) added to H: ``H(q) = H_pi(q) + h``.

        For reflected rotor inertia ``h = diag(n^2 J_r)`` (:mod:`hapticdesign.model.actuators`). A
        constant changes neither C (its derivatives vanish, eq. 2.51-2.52) nor G; it enters the
        constant basis function (index 0), so the tables are shared with this model.
        """
        h = np.asarray(h, dtype=float)
        if h.shape != (self.n_dof, self.n_dof) or not np.allclose(h, h.T) or not np.all(np.isfinite(h)):
            raise UserError(f"a constant inertia must be a finite symmetric {self.n_dof} x {self.n_dof} matrix")
        out = copy.copy(self)
        constant = np.zeros(self.coefficients.shape[1])
        iu, ju = np.triu_indices(self.n_dof)
        constant[self.slice_h] = h[iu, ju]
        out.constant = constant + (0.0 if self.constant is None else self.constant)
        return out

    def coefficients_for(self, pi: np.ndarray) -> np.ndarray:
        """Basis coefficients of every entry for parameters (n_params,) -> (n_basis, n_entries)."""
        coef = self.coefficients @ self._params(pi)
        if self.constant is not None:
            coef[0] += self.constant
        return coef

    def entries(self, q: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """All entries (unique H, C, G) at poses: (P, E) or (S, P, E) for parameter sets (S, n)."""
        phi = self.basis(q)
        coef = np.tensordot(self.coefficients, self._params(pi), axes=([2], [-1]))
        if self.constant is not None:
            coef[0] += self.constant if coef.ndim == 2 else self.constant[:, None]
        if coef.ndim == 2:
            return phi @ coef
        return np.einsum("pb,bes->spe", phi, coef)

    def entry_regressor(self, q: np.ndarray) -> np.ndarray:
        """Every entry (unique H, C, G) as a row of the standard parameters: (P, E, n_params)."""
        return np.tensordot(self.basis(q), self.coefficients, axes=(1, 0))

    @cached_property
    def cyclic(self) -> tuple[bool, ...]:
        """Coordinates that do not enter H, C, G (theta1 of the Phantom)."""
        return tuple(b.kind is CoordinateKind.CYCLIC for b in self.bases)
