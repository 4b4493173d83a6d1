"""Standard parameters back to the seed's variables (inverse of ``standard_from_seed``)."""

from __future__ import annotations

import numpy as np


def seed_from_standard(standard: np.ndarray) -> np.ndarray:
    """Map standard parameters ``(..., 10)`` to seed parameters ``(..., 10)`` (mass must be positive).

    ``r = h / m``; the inertia about the mass centre is ``J - m (r.r 1 - r r^T)`` and the seed's
    products are minus its off-diagonal entries (seed 000 Table 2.3).
    """
    standard = np.asarray(standard, dtype=float)
    m = standard[..., 0]
    r = standard[..., 1:4] / m[..., None]
    rx, ry, rz = r[..., 0], r[..., 1], r[..., 2]
    out = np.empty_like(standard)
    out[..., 0] = m
    out[..., 1:4] = r
    out[..., 4] = standard[..., 4] - m * (ry**2 + rz**2)
    out[..., 5] = standard[..., 5] - m * (rx**2 + rz**2)
    out[..., 6] = standard[..., 6] - m * (rx**2 + ry**2)
    out[..., 7] = -(standard[..., 7] + m * rx * ry)
    out[..., 8] = -(standard[..., 8] + m * rx * rz)
    out[..., 9] = -(standard[..., 9] + m * ry * rz)
    return out
