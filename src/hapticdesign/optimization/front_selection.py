"""Choosing one design of a Pareto front by the least (weighted) RMS of its normalized objectives (seed 001 §7.2,
eq. 7.1-7.4, Figures 7.2-7.3): the rule of the R-CUBE selection, for any study's front."""

from __future__ import annotations

import numpy as np

from hapticdesign.errors import UserError


def normalize(values) -> np.ndarray:
    """``p_n = (p - p_min) / (p_max - p_min)`` over the solutions (eq. 7.1); constant columns give 0."""
    p = np.asarray(values, dtype=float)
    if p.size == 0:
        raise UserError("nothing to normalize: the front is empty")
    span = p.max() - p.min()
    return np.zeros_like(p) if span == 0.0 else (p - p.min()) / span


def weighted_rms(primary, secondary, weight: float = 1.0) -> np.ndarray:
    """``sqrt((a^2 + w b^2) / 2)`` (Figures 7.2-7.3): ``w = 1`` is the plain RMS of ``a`` and ``b``.

    With ``a = omega_nn*`` and ``b = mu_vn*`` this reproduces the seed's choices from Table 7.3:
    Sol. 29 at ``w = 1`` and Sol. 1, 2, 6, 16 at ``w = 0, 0.25, 0.5, 0.75`` (Table 7.5).
    """
    if not 0.0 <= weight:
        raise UserError(f"a weight must be non-negative, got {weight!r}")
    a, b = np.asarray(primary, dtype=float), np.asarray(secondary, dtype=float)
    return np.sqrt((a**2 + weight * b**2) / 2.0)


def least_rms(normalized: np.ndarray, weights=None) -> int:
    """Row of the least weighted RMS ``sqrt(sum_i w_i a_i^2 / k)`` of ``normalized (n, k)`` (0 best in
    every column, eq. 7.1-7.4): Figures 7.2-7.3's rule over any number of indices (all weights 1: the
    plain RMS of Figure 7.2; ``k = 2`` with weights ``(1, w)`` is :func:`weighted_rms`). Ties go to the
    first row."""
    a = np.atleast_2d(np.asarray(normalized, dtype=float))
    w = np.ones(a.shape[1]) if weights is None else np.asarray(weights, dtype=float)
    if w.shape != (a.shape[1],) or not np.all(w >= 0.0) or not np.any(w > 0.0):
        raise UserError(f"give one non-negative weight per index, not all 0 (indices: {a.shape[1]})")
    return int(np.argmin(np.sqrt((a**2 @ w) / a.shape[1])))
