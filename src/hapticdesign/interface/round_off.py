"""Round-off is not data: entries below a relative ``1e-12`` of an array's largest are printed as 0."""

from __future__ import annotations

import numpy as np

RELATIVE = 1e-12


def without_round_off(values, relative: float = RELATIVE, scale: float | None = None) -> np.ndarray:
    """``values`` with every entry whose magnitude is below ``relative`` times ``scale`` (default: the largest
    entry) set to 0: the floating-point residue of cancelling terms, e.g. 1e-30 beside 1e+4, is not a result.
    A quantity that can be zero as a whole (the Coriolis terms of a linear design) takes the scale of the one it
    derives from (the mass matrix's largest entry)."""
    array = np.array(values, dtype=float)
    largest = float(np.max(np.abs(array), initial=0.0)) if scale is None else float(scale)
    array[np.abs(array) < relative * largest] = 0.0
    return array
