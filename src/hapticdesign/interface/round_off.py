"""Round-off is not data: entries below a relative ``1e-12`` of an array's largest are printed as 0."""

from __future__ import annotations

import numpy as np

RELATIVE = 1e-12


def without_round_off(values, relative: float = RELATIVE) -> np.ndarray:
    """``values`` with every entry whose magnitude is below ``relative`` times the largest set to 0 (the
    floating-point residue of cancelling terms, e.g. 1e-30 beside 1e+4, is not a result)."""
    array = np.array(values, dtype=float)
    largest = float(np.max(np.abs(array), initial=0.0))
    array[np.abs(array) < relative * largest] = 0.0
    return array
