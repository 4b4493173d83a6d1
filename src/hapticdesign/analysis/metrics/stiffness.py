"""Stiffness metrics of a Cartesian stiffness matrix (seed 001 §4.2.5, §6.2)."""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.metrics import names
from hapticdesign.errors import UserError


def _matrix(K) -> np.ndarray:
    K = np.asarray(K, dtype=float)
    if K.ndim < 2 or K.shape[-1] != K.shape[-2]:
        raise UserError(f"expected square matrices, got shape {K.shape}")
    return K


def euclidean_condition(K, pseudo: bool = False) -> np.ndarray:
    """``||K|| ||K^-1||`` (eq. 4.72, 6.53); ``pseudo=True`` uses the pseudo-inverse (eq. 6.58-6.59)."""
    s = np.linalg.svd(_matrix(K), compute_uv=False)
    if pseudo:
        tol = s[..., :1] * max(K.shape[-2:]) * np.finfo(float).eps
        smallest = np.min(np.where(s > tol, s, np.inf), axis=-1)
        return s[..., 0] / smallest
    with np.errstate(divide="ignore"):
        return s[..., 0] / s[..., -1]


def stiffness_uniformity(K) -> np.ndarray:
    """``S_e = ||K_C|| ||K_C^-1||`` (eq. 4.72)."""
    return euclidean_condition(K)


def frobenius(K) -> np.ndarray:
    """``S_f = sqrt(tr(K K^T))`` (eq. 4.73); the same operation gives ``I_f`` (eq. 4.98)."""
    return np.linalg.norm(_matrix(K), axis=(-2, -1))


def determinant(K) -> np.ndarray:
    """``S_d = det K_C`` (eq. 4.74, 6.71)."""
    return np.linalg.det(_matrix(K))


def translational_block(K) -> np.ndarray:
    """``K_CA``, the upper-left 3 x 3 block in N/m (eq. 6.54)."""
    return _matrix(K)[..., :3, :3]


def rotational_block(K) -> np.ndarray:
    """``K_CD``, the lower-right 3 x 3 block in N m/rad (eq. 6.54)."""
    return _matrix(K)[..., 3:, 3:]


def translational_condition(K) -> np.ndarray:
    """``S_et = ||K_CA|| ||K_CA^-1||`` (eq. 6.55)."""
    return euclidean_condition(translational_block(K))


def rotational_condition(K) -> np.ndarray:
    """``S_er = ||K_CD|| ||K_CD^-1||`` (eq. 6.56)."""
    return euclidean_condition(rotational_block(K))


def translational_volume(K) -> np.ndarray:
    """``S_da = det K_CA`` (eq. 6.74)."""
    return np.linalg.det(translational_block(K))


def rotational_volume(K) -> np.ndarray:
    """``S_dd = det K_CD`` (eq. 6.75)."""
    return np.linalg.det(rotational_block(K))


def all_stiffness_metrics(K) -> dict[str, np.ndarray]:
    """Every stiffness metric of a 6 x 6 ``K_C`` (or only the 3 x 3 ones for a translational matrix)."""
    K = _matrix(K)
    out = {names.STIFFNESS_UNIFORMITY: stiffness_uniformity(K), names.STIFFNESS_FROBENIUS: frobenius(K),
           names.STIFFNESS_VOLUME: determinant(K)}
    if K.shape[-1] == 6:
        out |= {
            names.TRANSLATIONAL_UNIFORMITY: translational_condition(K),
            names.ROTATIONAL_UNIFORMITY: rotational_condition(K),
            names.TRANSLATIONAL_VOLUME: translational_volume(K),
            names.ROTATIONAL_VOLUME: rotational_volume(K),
        }
    return out
