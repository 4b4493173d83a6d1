"""Global performance indices (seed 001 §4.4): the average of a pose-dependent metric, eq. 4.108."""

from __future__ import annotations

import numpy as np

from hapticdesign.errors import UserError


def global_index(values, weights=None) -> float:
    """``k = sum_i k_i / W_n`` over the finite samples (eq. 4.108); optional weights for denser regions."""
    v = np.asarray(values, dtype=float).ravel()
    if weights is None:
        mask = np.isfinite(v)
        if not mask.any():
            raise UserError("no finite metric values to globalize")
        return float(v[mask].mean())
    w = np.asarray(weights, dtype=float).ravel()
    mask = np.isfinite(v) & (w > 0)
    if not mask.any():
        raise UserError("no finite metric values to globalize")
    return float(np.sum(v[mask] * w[mask]) / np.sum(w[mask]))


def global_indices(metric_maps: dict[str, np.ndarray]) -> dict[str, float]:
    """Eq. 4.108 for each named map."""
    return {name: global_index(values) for name, values in metric_maps.items()}
