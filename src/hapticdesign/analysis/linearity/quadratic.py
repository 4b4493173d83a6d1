"""The Linearity Number as a quadratic form ``LN(pi) = pi^T Q pi`` in the standard inertial parameters (seed 000
eq. 3.1-3.4): the type both ways of computing ``Q`` produce, the exact basis moments of a tree
(:mod:`.form`) and converged quadrature for a closed-loop device (:mod:`.quadrature`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hapticdesign.analysis.linearity.region import Region
from hapticdesign.analysis.linearity.weights import Weights
from hapticdesign.errors import UserError
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
