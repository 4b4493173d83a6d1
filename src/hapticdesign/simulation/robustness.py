"""Does a linear device keep its stable range under modelling error? (seed 000 ch. 5, first future-work item)

Seed 000 asks how the results change "under conditions closer to the physical world", modelling
error first. For every design of a set, every error level E and several seeded draws the
compensator's model gets masses and inertias wrong by E percent, each parameter with a random sign
(the model over- and underestimates, as an identification would), and the stable impedance range
is searched again, in type 2 by default: with joints 2 and 3 driven the design's coupling (its LN)
can matter, while in type 1 every design is the same 1-DOF loop and only its inertia counts. The
analytic method (:mod:`.analytic`, :mod:`.analytic_driven`) gives the simulation's answer (tested);
``method="fast"`` runs the simulation instead.

Each case also records ``c = H_model,ww / H_ww`` at the start pose, the compensator's share of the
wall joint's inertia: for the 1-DOF loop the limit moves by about ``(1 - c) b / T`` (up for c < 1,
:mod:`.boundary`), and it collapses to 0 once ``c - 1`` exceeds about ``x = b T / H_ww`` (the loop
has no stable spring when ``c exp(-x) >= 1``): the effect is set by the error draw through
``1 - c`` and is one-sided. :func:`summarize_errors` gives, per LN level and error level, the
distributions with 95 % confidence intervals (Student t over the cases) and the rank correlation
of the change with ``|1 - c|``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import stats

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.config import Compensator, LoopConfig, compensator_device, rest_pose
from hapticdesign.simulation.impedance import impedance_range

MAX_DRAWS = 1000


@dataclass(frozen=True)
class ErrorCase:
    """One design at one error level and draw: the compensator's share ``c`` of H_ww and the range found."""

    design: str
    level: float
    error_percent: float
    draw: int
    fraction: float
    k_max: float


def inertia_share(device: Device, config: LoopConfig, joint: int = 0) -> float:
    """``c = H_model,ww / H_ww`` at the start pose under the run ``config``."""
    q0 = rest_pose(device)
    model = compensator_device(device, config)
    return float(mass_matrix(model, q0)[joint, joint] / mass_matrix(device, q0)[joint, joint])


def case_count(designs: int, errors: list[float], draws: int) -> int:
    """How many searches :func:`error_cases` runs: each design once at E = 0, ``draws`` times at every other E; a
    one-line error for error levels outside [0, 100) % or draws outside 1 to :data:`MAX_DRAWS` (checked here, before
    a command announces the work)."""
    if not errors or any(not (math.isfinite(e) and 0 <= e < 100) for e in errors):
        raise UserError(f"error levels must be percentages in [0, 100), got {errors}")
    if isinstance(draws, bool) or not (isinstance(draws, int) and 1 <= draws <= MAX_DRAWS):
        raise UserError(f"the number of error draws must be a whole number from 1 to {MAX_DRAWS}, got {draws}")
    return designs * sum(1 if e == 0 else draws for e in errors)


def error_cases(devices: list[tuple[str, float, Device]], errors: list[float], seed: int,
                groups: tuple[str, ...] = ("mass", "inertia"), method: str = "analytic", k_limit: int = 400,
                progress: Callable[[int, int], None] | None = None, sim_type: int = 2,
                draws: int = 1) -> list[ErrorCase]:
    """``k_max`` for every ``(name, LN level, device)``, error level (percent) and draw.

    Draw d of design i uses the sign seed ``seed + i draws + d`` at every E, so the levels differ
    only in size, not in direction; E = 0 has no error to draw and is searched once per design.
    """
    total = case_count(len(devices), errors, draws)
    cases, done = [], 0
    for i, (name, level, device) in enumerate(devices):
        for error in errors:
            for d in range(1 if error == 0 else draws):
                compensator = Compensator(group_errors=tuple((g, float(error)) for g in groups),
                                          error_seed=seed + i * draws + d)
                config = LoopConfig(compensator=compensator)
                found = impedance_range(device, sim_type, method=method, k_limit=k_limit, config=config)
                cases.append(ErrorCase(name, level, float(error), d, inertia_share(device, config),
                                       float(found.k_max)))
                done += 1
                if progress is not None:
                    progress(done, total)
    return cases


def _interval(values: np.ndarray) -> tuple[float | None, float | None, float | None]:
    """Mean and its 95 % Student-t confidence interval (None for fewer than two values)."""
    if values.size == 0:
        return None, None, None
    mean = float(values.mean())
    if values.size < 2:
        return mean, None, None
    half = float(stats.t.ppf(0.975, values.size - 1) * values.std(ddof=1) / math.sqrt(values.size))
    return mean, mean - half, mean + half


def summarize_errors(cases: list[ErrorCase]) -> list[dict]:
    """Per LN level and error level: the k_max distribution (mean, spread, 95 % CI of the mean), its absolute
    (N m/rad) and relative change from E = 0 with CIs (designs whose k_max is 0 at E = 0 enter the absolute
    change only), the signed change of under- (c < 1) and over-estimated (c > 1) inertia with CIs, the share
    of over-estimated cases driven to 0, and Spearman's rank correlation of |change| with |1 - c|."""
    base = {c.design: c.k_max for c in cases if c.error_percent == 0}
    rows = []
    for level in sorted({c.level for c in cases}):
        for error in sorted({c.error_percent for c in cases}):
            chosen = [c for c in cases if c.level == level and c.error_percent == error]
            k = np.array([c.k_max for c in chosen])
            known = [c for c in chosen if c.design in base]
            signed = np.array([c.k_max - base[c.design] for c in known])
            absolute = np.abs(signed)
            relative = np.array([abs(c.k_max - base[c.design]) / base[c.design] for c in known if base[c.design]])
            share = np.array([c.fraction for c in known])
            under, over = signed[share < 1.0], signed[share > 1.0]
            mean, lo, hi = _interval(k)
            abs_mean, abs_lo, abs_hi = _interval(absolute)
            rel_mean, rel_lo, rel_hi = _interval(relative)
            under_mean, under_lo, under_hi = _interval(under)
            over_mean, over_lo, over_hi = _interval(over)
            rho = None
            if absolute.size > 2 and np.ptp(absolute) > 0 and np.ptp(share) > 0:
                rho = float(stats.spearmanr(absolute, np.abs(1.0 - share)).statistic)
            rows.append({"level": level, "error_percent": error, "n": len(chosen), "mean": mean,
                         "std": float(k.std(ddof=1)) if len(k) > 1 else 0.0, "mean_ci_low": lo, "mean_ci_high": hi,
                         "mean_absolute_change": abs_mean, "absolute_change_ci_low": abs_lo,
                         "absolute_change_ci_high": abs_hi,
                         "mean_relative_change": rel_mean, "relative_change_ci_low": rel_lo,
                         "relative_change_ci_high": rel_hi,
                         "changed_share": float(np.mean(relative > 0)) if relative.size else None,
                         "under_n": int(under.size), "under_change": under_mean, "under_ci_low": under_lo,
                         "under_ci_high": under_hi,
                         "over_n": int(over.size), "over_change": over_mean, "over_ci_low": over_lo,
                         "over_ci_high": over_hi,
                         "over_to_zero_share": float(np.mean(np.array([c.k_max for c in known])[share > 1.0] == 0))
                         if over.size else None,
                         "spearman_abs_change_vs_abs_1_minus_c": rho})
    return rows
