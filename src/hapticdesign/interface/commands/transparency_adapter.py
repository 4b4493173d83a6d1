"""What ``transparency`` says about its stiffness: the wall joint's stable limit and why a bandwidth is null.

The limit is the stiffness at which the wall joint's sampled loop, linearized where the wall holds the joint (the
spring's rest, :data:`STEP` from the start pose), starts to grow (:meth:`~hapticdesign.simulation.analytic.AnalyticProblem.grows`: its one-sample map's spectral radius
reaches 1; with full inertial compensation and no delay the seed's 1-DOF closed form ``b^2 / H_ww``,
seed 000 §4.1.2). Imported when the command runs, so ``hapticdesign --help`` loads no engine.
"""

from __future__ import annotations

import math

from hapticdesign.simulation.analytic import AnalyticProblem, linear_loop
from hapticdesign.simulation.boundary import growth_onset
from hapticdesign.simulation.criteria import Criteria

REL_TOL = 1e-9
DOUBLINGS = 60
STEP = 0.01  # the spring's rest from the start (Table 4.2), where the loop is linearized


def stable_limit(device, sim_type: int, wall_joint: int, config) -> float | None:
    """The growth boundary of the wall joint's linearized loop (``inf`` when no stiffness makes it grow), or
    None where the linearization does not decide it (encoder counts, Coulomb friction, a type 2 motion
    coupled to the wall joint)."""
    if not linear_loop(device, config):
        return None
    problem = AnalyticProblem(device, sim_type, wall_joint, STEP, Criteria(), config)
    if not problem.growth_is_exact:
        return None
    first = problem.estimate()
    return growth_onset(problem.grows, 0.0, first, REL_TOL, first * 2.0 ** DOUBLINGS)


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
