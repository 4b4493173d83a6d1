"""The simulated stability boundary of a 1-DOF mass-damper under a sampled virtual spring (seed 000 ch. 4, §5):
the numba loop itself under the settings of a :class:`~hapticdesign.analysis.sampled_loop.SampledLoop`, ``K``
bisected on the growth of the oscillation (the envelope of the last quarter of the run against the second quarter).
The exact limit of the same loop, its oracle, is :func:`hapticdesign.analysis.sampled_loop.joint_limits`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from hapticdesign.analysis.sampled_loop import SampledLoop
from hapticdesign.errors import UserError
from hapticdesign.simulation.config import LoopConfig, Wall
from hapticdesign.simulation.loop import simulate_tables
from hapticdesign.simulation.tables import DynamicsTables
from hapticdesign.workload import require_plant_steps

BOUNDARY_RUNS = 42  # doublings from b / T to the 1e12 cap of :func:`simulated_boundary`


def grows(inertia: float, damping: float, loop: SampledLoop, stiffness: float, samples: int = 4000,
          substeps: int = 10) -> bool:
    """True when the simulated oscillation of the 1-DOF loop (inertia, damping, the settings ``loop``; a hand adds
    its mass, damping and stiffness to the joint's) about the wall's rest grows (last vs second quarter)."""
    cfg = LoopConfig(duration=samples * loop.period, step=loop.period / substeps, loop=loop,
                     wall=Wall(0, stiffness, equilibrium=0.01), damping=(damping,), safety_limit=None,
                     stop_excursion=1e6)
    model = inertia * (1.0 - loop.error_percent / 100.0)
    plant = DynamicsTables.constant_inertia(inertia)
    hand = loop.hand
    spring = 0.0 if hand is None else hand.stiffness
    trace = simulate_tables(plant, DynamicsTables.constant_inertia(model), cfg, (damping,),
                            hand=None if hand is None else (np.array([[hand.mass]]), np.array([[hand.damping]]),
                                                            np.array([[spring]])))
    if trace.diverged or len(trace.t) < samples + 1:
        return True
    rest = stiffness * cfg.wall.equilibrium / (stiffness + spring)
    return envelope_grows(trace.q[:, 0] - rest)


def envelope_grows(error: np.ndarray, margin: float = 0.0) -> bool:
    """Oscillation growth: the peak of the last quarter exceeds the second quarter's by ``margin``."""
    err = np.abs(np.asarray(error))
    quarter = len(err) // 4
    return bool(err[3 * quarter:].max() > (1.0 + margin) * err[quarter:2 * quarter].max())


def simulated_boundary(inertia: float, damping: float, loop: SampledLoop, rel_tol: float = 1e-3, samples: int = 4000,
                       substeps: int = 10) -> float:
    """Bisect the simulated 1-DOF loop (:func:`grows`) for the stiffness at which oscillations start to grow."""
    if samples < 40 or substeps < 1:
        raise UserError("the growth test needs at least 40 samples and 1 plant step per sample")
    runs = BOUNDARY_RUNS + math.ceil(math.log2(1.0 / rel_tol))
    require_plant_steps(f"{runs} simulations of {samples:,} samples x {substeps:,} plant steps", runs * samples * substeps)
    return growth_onset(lambda k: grows(inertia, damping, loop, k, samples, substeps), 0.0,
                        damping / loop.period + 1e-9, rel_tol, 1e12)


def growth_onset(grows: Callable[[float], bool], lo: float, hi: float, rel_tol: float, k_limit: float,
                 hi_grows: bool = False) -> float:
    """The stiffness at which ``grows(k)`` turns true, the growth boundary of every simulated search (seed 000 §5):
    from ``lo`` (not growing), ``hi`` is doubled until the loop grows (inf once past ``k_limit``; skipped when
    ``hi_grows`` says it is known to grow), then the bracket is bisected to ``rel_tol`` of ``hi``; the midpoint."""
    if not hi_grows:
        while not grows(hi):
            lo, hi = hi, 2.0 * hi
            if hi > k_limit:
                return math.inf
    while hi - lo > rel_tol * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if grows(mid) else (mid, hi)
    return 0.5 * (lo + hi)
