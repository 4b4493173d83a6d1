"""The simulated stability boundary of a 1-DOF mass-damper under a sampled virtual spring (seed 000 ch. 4, §5):
the numba loop itself, ``K`` bisected on the growth of the oscillation (the envelope of the last quarter of the run
against the second quarter). The exact limit of the same loop, its oracle, is
:mod:`hapticdesign.analysis.sampled_loop`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from hapticdesign.analysis.sampled_loop import MassDamper
from hapticdesign.errors import UserError
from hapticdesign.simulation.config import Compensator, LoopConfig, Sensors, Wall
from hapticdesign.simulation.loop import simulate_tables
from hapticdesign.simulation.tables import DynamicsTables
from hapticdesign.workload import require_plant_steps

BOUNDARY_RUNS = 42  # doublings from b / T to the 1e12 cap of :func:`simulated_boundary`


def _config(system: MassDamper, stiffness: float, duration: float, step: float) -> LoopConfig:
    return LoopConfig(
        duration=duration,
        step=step,
        sensors=Sensors(period=system.period, delay_samples=system.delay_samples),
        compensator=Compensator(inertial=system.compensate_inertia, coriolis=False, gravity=False),
        wall=Wall(0, stiffness, system.virtual_damping, 0.01),
        damping=(system.damping,),
        safety_limit=None,
        stop_excursion=1e6,
    )


def grows(system: MassDamper, stiffness: float, samples: int = 4000, substeps: int = 10) -> bool:
    """True when the simulated oscillation about the equilibrium grows (last vs second quarter)."""
    plant = DynamicsTables.constant_inertia(system.inertia)
    model = DynamicsTables.constant_inertia(system.j_model)
    cfg = _config(system, stiffness, samples * system.period, system.period / substeps)
    spring = np.array([[system.plant_stiffness]])
    trace = simulate_tables(plant, model, cfg, (system.damping,), hand=(np.zeros((1, 1)), np.zeros((1, 1)), spring))
    if trace.diverged or len(trace.t) < samples + 1:
        return True
    rest = stiffness * cfg.wall.equilibrium / (stiffness + system.plant_stiffness)
    return envelope_grows(trace.q[:, 0] - rest)


def envelope_grows(error: np.ndarray, margin: float = 0.0) -> bool:
    """Oscillation growth: the peak of the last quarter exceeds the second quarter's by ``margin``."""
    err = np.abs(np.asarray(error))
    quarter = len(err) // 4
    return bool(err[3 * quarter:].max() > (1.0 + margin) * err[quarter:2 * quarter].max())


def simulated_boundary(system: MassDamper, rel_tol: float = 1e-3, samples: int = 4000, substeps: int = 10) -> float:
    """Bisect the simulated loop for the stiffness at which oscillations start to grow."""
    if samples < 40 or substeps < 1:
        raise UserError("the growth test needs at least 40 samples and 1 plant step per sample")
    runs = BOUNDARY_RUNS + math.ceil(math.log2(1.0 / rel_tol))
    require_plant_steps(f"{runs} simulations of {samples:,} samples x {substeps:,} plant steps", runs * samples * substeps)
    return growth_onset(lambda k: grows(system, k, samples, substeps), 0.0, system.damping / system.period + 1e-9,
                        rel_tol, 1e12)


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
