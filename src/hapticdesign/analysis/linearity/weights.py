"""Weighting coefficients of the Linearity Number (seed 000 eq. 3.1).

One weight per entry of H (N x N), C (N x N(N+1)/2, eq. 2.50's form) and G (N). The seed
uses unit weights throughout. Every (i, j) entry of H is counted, so an off-diagonal entry of
the symmetric H contributes with ``W_H[i, j] + W_H[j, i]`` (the reading under which Appendix B's printed coefficients reproduce).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.params_io import read_mapping


@dataclass(frozen=True)
class Weights:
    """Weights of the H, C and G entries; arrays of shape (N, N), (N, N(N+1)/2), (N,)."""

    H: np.ndarray
    C: np.ndarray
    G: np.ndarray

    @classmethod
    def unit(cls, n_dof: int) -> "Weights":
        m = n_dof * (n_dof + 1) // 2
        return cls(np.ones((n_dof, n_dof)), np.ones((n_dof, m)), np.ones(n_dof))

    def per_entry(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Weights in the model's entry order: unique H (i <= j, row-major), C rows, G."""
        iu, ju = np.triu_indices(self.H.shape[0])
        h = np.where(iu == ju, self.H[iu, ju], self.H[iu, ju] + self.H[ju, iu])
        return h, self.C.ravel(), self.G.copy()


def read_weights(path: Path, n_dof: int) -> Weights:
    """Weights from a JSON/YAML/TOML mapping with optional keys ``H``, ``C``, ``G`` (unit if absent).

    ``H`` is an N x N nested list, ``C`` an N x N(N+1)/2 nested list, ``G`` a list of N numbers;
    a scalar applies to every entry of its part. Weights must be finite and non-negative.
    """
    data = read_mapping(Path(path))
    unit = Weights.unit(n_dof)
    unknown = set(data) - {"H", "C", "G"}
    if unknown:
        raise UserError(f"{path}: unknown weight keys {sorted(unknown)} (use H, C, G)")
    parts = {}
    for key in ("H", "C", "G"):
        default = getattr(unit, key)
        if key not in data:
            parts[key] = default
            continue
        try:
            value = np.array(data[key], dtype=float)
        except (TypeError, ValueError):
            raise UserError(f"{path}: weights {key} must be numbers") from None
        if value.ndim == 0:
            value = np.full(default.shape, float(value))
        if value.shape != default.shape:
            raise UserError(f"{path}: weights {key} must have shape {default.shape}, got {value.shape}")
        if not np.all(np.isfinite(value)) or np.any(value < 0):
            raise UserError(f"{path}: weights {key} must be finite and non-negative")
        parts[key] = value
    return Weights(**parts)
