"""Stability boundary of a 1-DOF mass-damper under a sampled virtual spring (CONVENTIONS.md).

Plant ``J qdd + b qd = u``; every ``T`` the digital side reads ``q, qd`` (and the acceleration
under the previous held torque), optionally ``delay`` samples late, and holds
``u = c J_m a - K q - B qd`` (``c = 1`` with the inertial compensator, model inertia ``J_m``).

- :func:`exact_boundary`: the plant discretized exactly (``scipy.linalg.expm`` of the augmented
  matrix), the closed loop written as one linear map of the sampled state, and the smallest
  ``K`` at which its spectral radius reaches 1 (about ``2 b / T`` without compensation).
- :func:`simulated_boundary`: the numba loop itself, ``K`` bisected on the growth of the
  oscillation (the envelope of the last quarter of the run against the second quarter).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from hapticdesign.errors import UserError
from hapticdesign.simulation.loop import Compensator, LoopConfig, Sensors, Wall, simulate_tables
from hapticdesign.simulation.tables import DynamicsTables


@dataclass(frozen=True)
class MassDamper:
    """A 1-DOF inertia ``J`` (kg m^2) with viscous damping ``b`` (N m s/rad), sampled every ``T``."""

    inertia: float
    damping: float
    period: float
    delay_samples: int = 0
    virtual_damping: float = 0.0
    compensate_inertia: bool = False
    model_inertia: float | None = None

    def __post_init__(self) -> None:
        for name in ("inertia", "period"):
            value = getattr(self, name)
            if not (value > 0 and math.isfinite(value)):
                raise UserError(f"the {name} must be positive, got {value}")
        if not (self.damping >= 0 and math.isfinite(self.damping)):
            raise UserError(f"the damping must be non-negative, got {self.damping}")
        if self.delay_samples < 0:
            raise UserError("the delay must be a non-negative number of samples")

    @property
    def j_model(self) -> float:
        return self.inertia if self.model_inertia is None else self.model_inertia


@lru_cache(maxsize=64)
def _discretize(j: float, b: float, t: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretization of ``J qdd + b qd = u`` over one period."""
    a = np.array([[0.0, 1.0, 0.0], [0.0, -b / j, 1.0 / j], [0.0, 0.0, 0.0]])
    e = expm(a * t)
    return e[:2, :2], e[:2, 2]


def closed_loop_matrix(system: MassDamper, stiffness: float) -> np.ndarray:
    """One-sample map of ``[q, qd, u_prev, s_(k-1), ..., s_(k-d)]`` with ``s = (q, qd, a)``."""
    j, b, d = system.inertia, system.damping, system.delay_samples
    phi, gamma = _discretize(j, b, system.period)
    size = 3 + 3 * d
    sense = np.zeros((3, size))  # s_k from z_k
    sense[0, 0] = 1.0
    sense[1, 1] = 1.0
    sense[2, 1] = -b / j
    sense[2, 2] = 1.0 / j
    gains = np.array([-stiffness, -system.virtual_damping, float(system.compensate_inertia) * system.j_model])
    law = gains @ sense if d == 0 else np.concatenate([np.zeros(3 + 3 * (d - 1)), gains])
    m = np.zeros((size, size))
    m[:2, :2] = phi
    m[:2] += np.outer(gamma, law)
    m[2] = law
    if d > 0:
        m[3:6] = sense
        m[6:] = np.eye(size)[3:size - 3]
    return m


def spectral_radius(system: MassDamper, stiffness: float) -> float:
    return float(np.max(np.abs(np.linalg.eigvals(closed_loop_matrix(system, stiffness)))))


def exact_boundary(system: MassDamper, k_max: float = 1e9) -> float:
    """Smallest spring stiffness at which the exactly discretized loop loses stability."""
    lo = 1e-9
    if spectral_radius(system, lo) >= 1.0:
        return 0.0
    hi = lo
    while spectral_radius(system, hi) < 1.0:
        lo, hi = hi, hi * 1.25
        if hi > k_max:
            return math.inf
    return brentq(lambda k: spectral_radius(system, k) - 1.0, lo, hi, xtol=1e-12, rtol=1e-10)


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
    trace = simulate_tables(plant, model, cfg, (system.damping,))
    if trace.diverged or len(trace.t) < samples + 1:
        return True
    return envelope_grows(trace.q[:, 0] - 0.01)


def envelope_grows(error: np.ndarray, margin: float = 0.0) -> bool:
    """Oscillation growth: the peak of the last quarter exceeds the second quarter's by ``margin``."""
    err = np.abs(np.asarray(error))
    quarter = len(err) // 4
    return bool(err[3 * quarter:].max() > (1.0 + margin) * err[quarter:2 * quarter].max())


def simulated_boundary(system: MassDamper, rel_tol: float = 1e-3, samples: int = 4000, substeps: int = 10) -> float:
    """Bisect the simulated loop for the stiffness at which oscillations start to grow."""
    lo, hi = 0.0, system.damping / system.period + 1e-9
    while not grows(system, hi, samples, substeps):
        lo, hi = hi, 2.0 * hi
        if hi > 1e12:
            return math.inf
    while hi - lo > rel_tol * hi:
        mid = 0.5 * (lo + hi)
        if grows(system, mid, samples, substeps):
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)
