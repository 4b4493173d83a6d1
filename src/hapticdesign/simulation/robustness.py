"""Does a linear device keep its stable range under modelling error? (seed 000 ch. 5, first future-work item)

Seed 000 asks how the results change "under conditions closer to the physical world", modelling
error first. For every design of a set and every error level E the compensator's model gets
masses and inertias wrong by E percent, each parameter with a seeded random sign (the model over-
and underestimates, as an identification would), and the stable impedance range of type 1 is
searched again. Type 1 with the other joints held is exactly linear for the Phantom's joint 1, so
the analytic method (:mod:`.analytic`) gives the simulation's answer (tested) in a fraction of the
time; ``method="fast"`` runs the simulation instead.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.config import Compensator, LoopConfig
from hapticdesign.simulation.impedance import impedance_range


@dataclass(frozen=True)
class ErrorCase:
    """One design at one error level: the stable range found."""

    design: str
    level: float
    error_percent: float
    k_max: float


def error_cases(devices: list[tuple[str, float, Device]], errors: list[float], seed: int,
                groups: tuple[str, ...] = ("mass", "inertia"), method: str = "analytic", k_limit: int = 400,
                progress: Callable[[int, int], None] | None = None) -> list[ErrorCase]:
    """``k_max`` of type 1 for every ``(name, LN level, device)`` and error level (percent).

    Design i at error E uses the sign seed ``seed + i`` for every E, so the levels differ only in
    size, not in direction.
    """
    if not errors or any(not (math.isfinite(e) and 0 <= e < 100) for e in errors):
        raise UserError(f"error levels must be percentages in [0, 100), got {errors}")
    cases, total = [], len(devices) * len(errors)
    for i, (name, level, device) in enumerate(devices):
        for error in errors:
            compensator = Compensator(group_errors=tuple((g, float(error)) for g in groups), error_seed=seed + i)
            found = impedance_range(device, 1, method=method, k_limit=k_limit,
                                    config=LoopConfig(compensator=compensator))
            cases.append(ErrorCase(name, level, float(error), float(found.k_max)))
            if progress is not None:
                progress(len(cases), total)
    return cases


def summarize_errors(cases: list[ErrorCase]) -> list[dict]:
    """Per LN level and error level: mean and spread of k_max and its absolute (N m/rad) and relative
    change from E = 0 (designs whose k_max is 0 at E = 0 enter the absolute change only)."""
    base = {c.design: c.k_max for c in cases if c.error_percent == 0}
    rows = []
    for level in sorted({c.level for c in cases}):
        for error in sorted({c.error_percent for c in cases}):
            chosen = [c for c in cases if c.level == level and c.error_percent == error]
            k = np.array([c.k_max for c in chosen])
            change = np.array([abs(c.k_max - base[c.design]) / base[c.design] for c in chosen
                               if base.get(c.design)])
            absolute = np.array([abs(c.k_max - base[c.design]) for c in chosen if c.design in base])
            rows.append({"level": level, "error_percent": error, "n": len(chosen), "mean": float(k.mean()),
                         "std": float(k.std(ddof=1)) if len(k) > 1 else 0.0,
                         "mean_absolute_change": float(absolute.mean()) if absolute.size else None,
                         "mean_relative_change": float(change.mean()) if change.size else None,
                         "changed_share": float(np.mean(change > 0)) if change.size else None})
    return rows
