"""The Linearity Number as a quadratic form in the standard inertial parameters.

Seed 000 eq. 3.1-3.3: ``LN = sum_ij w_ij E[H_ij] + sum w E'[C] + sum_i w_i E[G_i]`` where ``E`` is
the variance over the region R (eq. 3.2-3.3 divided by the region's volume V) and, as in the
seed's Appendix B (whose printed coefficients, e.g. ``Ixy3^2: 5``, reproduce so), the C part is the mean square (C should vanish, not only
be constant). Every entry is ``sum_b phi_b(q) (A[b, e, :] @ pi)`` (the dynamics model's exact
basis expansion), so with the basis covariance ``K_ab = Cov[phi_a, phi_b]`` and mean ``mu``:

    Var[entry_e] = pi^T A_e^T K A_e pi,   Mean[entry_e^2] = pi^T A_e^T (K + mu mu^T) A_e pi.

LN is therefore ``pi^T (Q_H + Q_C + Q_G) pi`` with positive semi-definite matrices computed once
per device geometry, region and weights; designs are then evaluated in batches.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.dynamics.model import DynamicsModel
from hapticdesign.analysis.linearity.region import Region, limits_region
from hapticdesign.analysis.linearity.weights import Weights
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.model.inertia import standard_from_seed

PARTS = ("H", "C", "G")


@dataclass(frozen=True)
class LinearityForm:
    """``LN(pi) = pi^T Q pi`` split into the H, C and G parts; ``Q`` has shape (3, P, P)."""

    Q: np.ndarray
    region: Region
    weights: Weights
    accuracy: float = 0.0
    """Estimated relative error of Q: 0 for the exact basis of a tree, the last change of converged
    quadrature for a closed-loop device (:mod:`.quadrature`)."""

    @property
    def n_params(self) -> int:
        return self.Q.shape[-1]

    @property
    def total(self) -> np.ndarray:
        return self.Q.sum(axis=0)

    def parts(self, pi: np.ndarray) -> np.ndarray:
        """H, C, G parts for standard parameters (P,) -> (3,) or (S, P) -> (S, 3)."""
        pi = np.asarray(pi, dtype=float)
        if pi.shape[-1] != self.n_params:
            raise UserError(f"expected {self.n_params} standard inertial parameters, got {pi.shape[-1]}")
        if not np.all(np.isfinite(pi)):
            raise UserError("standard inertial parameters must be finite numbers (got NaN or infinity; m r or "
                            "m r^2 may overflow)")
        flat = np.atleast_2d(pi)
        n = self.n_params
        products = flat @ self.Q.transpose(1, 0, 2).reshape(n, 3 * n)  # one BLAS call for the batch
        out = np.einsum("skq,sq->sk", products.reshape(-1, 3, n), flat)
        if not np.all(np.isfinite(out)):
            raise UserError("the Linearity Number overflows for these inertial parameters (not a finite number)")
        out = np.maximum(out, 0.0)
        return out[0] if pi.ndim == 1 else out

    def ln(self, pi: np.ndarray) -> np.ndarray:
        """LN for standard parameters (P,) or (S, P)."""
        return self.parts(pi).sum(axis=-1)

    def parts_seed(self, seed: np.ndarray) -> np.ndarray:
        """Parts for designs in the seed's variables, (S, bodies * 10) in ``device.inertial_names()`` order."""
        seed = np.asarray(seed, dtype=float)
        if seed.shape[-1] != self.n_params:
            raise UserError(f"expected {self.n_params} inertial parameters, got {seed.shape[-1]}")
        pi = standard_from_seed(seed.reshape(seed.shape[:-1] + (-1, 10))).reshape(seed.shape)
        return self.parts(pi)

    def ln_seed(self, seed: np.ndarray) -> np.ndarray:
        return self.parts_seed(seed).sum(axis=-1)

    def null_space(self, rel_tol: float = 1e-10) -> np.ndarray:
        """Orthonormal basis (P, k) of the designs with LN = 0 (``Q pi = 0``)."""
        values, vectors = np.linalg.eigh(self.total)
        return vectors[:, values <= rel_tol * max(values.max(), 1e-300)]

    def factor(self, rel_tol: float = 1e-14) -> np.ndarray:
        """``L`` with ``L^T L = Q`` (rows for the non-zero eigenvalues): LN = |L pi|^2."""
        values, vectors = np.linalg.eigh(self.total)
        keep = values > rel_tol * max(values.max(), 1e-300)
        return np.sqrt(values[keep])[:, None] * vectors[:, keep].T


def basis_moments(model: DynamicsModel, region: Region) -> tuple[np.ndarray, np.ndarray]:
    """Covariance ``K`` (B, B) and mean ``mu`` (B,) of the model's tensor basis functions on R.

    Built one coordinate at a time without forming ``E[phi_a phi_b] - mu_a mu_b`` (which would
    cancel): with ``R = prod w w^T`` so far, ``K <- K (C_k + w_k w_k^T) + R C_k``.
    """
    n_basis = model.index.shape[0]
    cov = np.zeros((n_basis, n_basis))
    outer = np.ones((n_basis, n_basis))
    mean = np.ones(n_basis)
    for k, basis in enumerate(model.bases):
        w, c = region.moments(k, basis)
        idx = model.index[:, k]
        ck = c[np.ix_(idx, idx)]
        wk = np.outer(w[idx], w[idx])
        cov = cov * (ck + wk) + outer * ck
        outer = outer * wk
        mean = mean * w[idx]
    return cov, mean


def _weighted_form(coef: np.ndarray, weights: np.ndarray, gram: np.ndarray) -> np.ndarray:
    """``sum_e w_e A_e^T gram A_e`` for coefficients (B, E, P)."""
    diagonal = np.count_nonzero(gram - np.diag(np.diag(gram))) == 0
    if diagonal:
        transformed = np.diag(gram)[:, None, None] * coef
    else:
        transformed = np.tensordot(gram, coef, axes=(1, 0))
    q = np.tensordot(coef * weights[None, :, None], transformed, axes=([0, 1], [0, 1]))
    return 0.5 * (q + q.T)


def linearity_form(model: DynamicsModel, region: Region | None = None, weights: Weights | None = None) -> LinearityForm:
    """Precompute ``Q_H, Q_C, Q_G`` for one device geometry (seed 000 eq. 3.1-3.4).

    Trees use the exact basis moments below; closed-loop devices (no exact basis) use converged
    quadrature over the region (:func:`.quadrature.quadrature_form`).
    """
    if not getattr(model, "exact_basis", True):
        from hapticdesign.analysis.linearity.quadrature import quadrature_form

        return quadrature_form(model, region, weights)
    region = region or Region()
    weights = weights or Weights.unit(model.n_dof)
    expected = Weights.unit(model.n_dof)
    for key in PARTS:
        if getattr(weights, key).shape != getattr(expected, key).shape:
            raise UserError(f"weights {key} must have shape {getattr(expected, key).shape}")
    cov, mean = basis_moments(model, region)
    w_h, w_c, w_g = weights.per_entry()
    a = model.coefficients
    q_h = _weighted_form(a[:, model.slice_h], w_h, cov)
    q_c = _weighted_form(a[:, model.slice_c], w_c, cov + np.outer(mean, mean))
    q_g = _weighted_form(a[:, model.slice_g], w_g, cov)
    return LinearityForm(np.stack([q_h, q_c, q_g]), region, weights)


def device_form(device: Device, region: Region | None = None, weights: Weights | None = None) -> LinearityForm:
    """The LN form of a device (cached per geometry and region when the weights are the defaults).

    The default region is the box of the device's joint limits, full turns where it has none.
    """
    region = limits_region(device.joint_limits()) if region is None else region
    if weights is None:
        return _default_form(dynamics_of(device), tuple(sorted(region.ranges.items())))
    return linearity_form(dynamics_of(device), region, weights)


@lru_cache(maxsize=8)
def _default_form(model, ranges: tuple) -> LinearityForm:
    return linearity_form(model, Region(dict(ranges)) if ranges else None)
