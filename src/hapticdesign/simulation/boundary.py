"""Stability boundary of a 1-DOF mass-damper under a sampled virtual spring (seed 000 ch. 4, §5).

Plant ``J qdd + b qd + k_p q = u`` (``k_p``: a physical spring such as a hand's, 0 by default);
every ``T`` the digital side reads ``q, qd`` (and the acceleration under the previous held
torque), optionally ``delay`` samples late, and holds ``u = J_m a - K q - B qd`` with the
inertial compensator (model inertia ``J_m``, ``J_m = c J`` for a modelling error of
``E = 100 (1 - c)`` percent), ``u = - K q - B qd`` without it.

- :func:`exact_boundary`: the plant discretized exactly (``scipy.linalg.expm`` of the augmented
  matrix), the closed loop written as one linear map of the sampled state, and the smallest
  ``K`` at which its spectral radius reaches 1 (about ``2 b / T`` without compensation).
- :func:`compensated_boundary`: the closed form of that limit with the inertial compensator,
  no delay and no virtual damper (derived below), the oracle of the simulation tests.
- :func:`simulated_boundary`: the numba loop itself, ``K`` bisected on the growth of the
  oscillation (the envelope of the last quarter of the run against the second quarter).

The closed form. Over one period the held torque moves the plant (``k_p = 0``) by
``v+ = a v + (1 - a) u / b`` and ``q+ = q + J (1 - a) v / b + (T/b - J (1 - a)/b^2) u`` with
``a = exp(-b T / J)``. The acceleration sampled just before instant k is
``(u_(k-1) - b v_k) / J``, so the law is ``u_k = c (u_(k-1) - b v_k) - K q_k``: a three-state
linear map of ``(q, v, u_prev)``. Its cubic characteristic polynomial keeps a real root inside
the unit circle and loses stability when its complex pair reaches ``|z| = 1``; the Schur-Cohn
(Jury) condition for that crossing is linear in K and gives

    K* = b^2 (1 - a)(1 - a c) / [J (1 - a)(1 - a c) - T a b (1 - c)],

which is ``b^2 / J`` at ``c = 1`` (the compensated loop's torque is a running sum
``u_k = u_(k-1) - b v_k - K q_k``), about ``b^2 / J + (1 - c) b / T`` for ``c`` near 1 (a 1 %
modelling error adds ``b / (100 T)``: 5 N m/rad at b = 0.5, T = 1 ms) and about ``2 b / T`` at
``c = 0``. The tests check it against the spectral radius of :func:`closed_loop_matrix` and the
simulated loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from hapticdesign.errors import UserError
from hapticdesign.simulation.config import Compensator, LoopConfig, Sensors, Wall
from hapticdesign.simulation.loop import simulate_tables
from hapticdesign.simulation.tables import DynamicsTables
from hapticdesign.workload import EIGEN_ORDER_LIMIT, require_memory, require_plant_steps, require_within

BOUNDARY_RUNS = 42  # doublings from b / T to the 1e12 cap of :func:`simulated_boundary`


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
    plant_stiffness: float = 0.0

    def __post_init__(self) -> None:
        for name in ("inertia", "period"):
            value = getattr(self, name)
            if not (value > 0 and math.isfinite(value)):
                raise UserError(f"the {name} must be positive, got {value}")
        if not (self.damping >= 0 and math.isfinite(self.damping)):
            raise UserError(f"the damping must be non-negative, got {self.damping}")
        if self.delay_samples < 0:
            raise UserError("the delay must be a non-negative number of samples")
        if not (self.plant_stiffness >= 0 and math.isfinite(self.plant_stiffness)):
            raise UserError(f"the plant stiffness must be non-negative, got {self.plant_stiffness}")
        if self.model_inertia is not None and not (self.model_inertia >= 0 and math.isfinite(self.model_inertia)):
            raise UserError(f"the model inertia must be non-negative, got {self.model_inertia}")

    @property
    def j_model(self) -> float:
        return self.inertia if self.model_inertia is None else self.model_inertia


@lru_cache(maxsize=64)
def _discretize(j: float, b: float, t: float, k_p: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretization of ``J qdd + b qd + k_p q = u`` over one period."""
    a = np.array([[0.0, 1.0, 0.0], [-k_p / j, -b / j, 1.0 / j], [0.0, 0.0, 0.0]])
    e = expm(a * t)
    return e[:2, :2], e[:2, 2]


def compensated_boundary(inertia: float, damping: float, period: float, fraction: float = 1.0) -> float:
    """Closed-form ``K*`` of a 1-DOF inertia with a compensator feeding ``fraction * J * a`` forward.

    ``fraction = c = 1 - E/100`` for a modelling error of E percent; see the module docstring.
    ``inf`` when the denominator is not positive (no spring destabilizes the loop).
    """
    a = math.exp(-damping * period / inertia)
    num = damping ** 2 * (1 - a) * (1 - a * fraction)
    den = inertia * (1 - a) * (1 - a * fraction) - period * a * damping * (1 - fraction)
    return num / den if den > 0 else math.inf


def closed_loop_matrix(system: MassDamper, stiffness: float) -> np.ndarray:
    """One-sample map of ``[q, qd, u_prev, s_(k-1), ..., s_(k-d)]`` with ``s = (q, qd, a)``."""
    j, b, d = system.inertia, system.damping, system.delay_samples
    phi, gamma = _discretize(j, b, system.period, system.plant_stiffness)
    size = 3 + 3 * d
    sense = np.zeros((3, size))  # s_k from z_k
    sense[0, 0] = 1.0
    sense[1, 1] = 1.0
    sense[2, 0] = -system.plant_stiffness / j
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
    order = 3 + 3 * system.delay_samples
    what = f"the closed-loop matrix of a {system.delay_samples:,}-sample delay"
    require_memory(what, 8.0 * order * order)
    require_within(what, order, EIGEN_ORDER_LIMIT, "rows")
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
