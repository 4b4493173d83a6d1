"""What ``transparency`` says about its stiffness: the wall joint's stable limit
(:func:`hapticdesign.simulation.transparency.stable_limit`) for JSON, and why a bandwidth is null. Imported when the
command runs, so ``hapticdesign --help`` loads no engine.
"""

from __future__ import annotations

import math


def finite_or_none(limit: float | None) -> float | None:
    """The limit for JSON: null when no stiffness makes the loop grow or the linearization does not decide it."""
    return limit if limit is not None and math.isfinite(limit) else None


def bandwidth_note(bandwidth_hz: float | None, band_db: float, top_hz: float, stiffness: float,
                   limit: float | None, unit: str) -> str | None:
    """Why the bandwidth is null (None when it is a number)."""
    if bandwidth_hz is not None:
        return None
    note = f"|G_T| stays within +-{band_db:g} dB up to the chirp's top, {top_hz:g} Hz: the bandwidth is beyond it"
    if limit is not None and stiffness > limit:
        note += (f"; K = {stiffness:g} {unit} is above the wall joint's stable limit {limit:.4g} {unit}, so the "
                 "wall's oscillation grows and this response is not a stable wall's")
    return note
