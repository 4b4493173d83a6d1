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

from functools import lru_cache

import numpy as np

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.dynamics.model import DynamicsModel, EquationsOfMotion, ExactBasis
from hapticdesign.analysis.linearity.quadratic import PARTS, LinearityForm
from hapticdesign.analysis.linearity.quadrature import quadrature_form
from hapticdesign.analysis.linearity.region import Region, limits_region
from hapticdesign.analysis.linearity.weights import Weights
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device

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


def linearity_form(model: EquationsOfMotion, region: Region | None = None, weights: Weights | None = None) -> LinearityForm:
    """Precompute ``Q_H, Q_C, Q_G`` for one device geometry (seed 000 eq. 3.1-3.4).

    Trees use the exact basis moments below; closed-loop devices (no exact basis) use converged
    quadrature over the region (:func:`.quadrature.quadrature_form`).
    """
    if not isinstance(model, ExactBasis):
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
