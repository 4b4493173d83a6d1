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
``a = exp(-x)``, ``x = b T / J``. The acceleration sampled just before instant k is
``(u_(k-1) - b v_k) / J``, so the law is ``u_k = c (u_(k-1) - b v_k) - K q_k``: a three-state
linear map of ``(q, v, u_prev)`` whose characteristic polynomial ``z^3 + a2 z^2 + a1 z + a0`` has
coefficients affine in K, ``a0 = -a c``. The Schur-Cohn (Jury) conditions are then each linear in K:

- ``p(1) > 0``: ``K T (1 - a) / b > 0``, i.e. ``K > 0`` (the pole at z = 1 of the running sum);
- ``|a0| < 1``: ``a c < 1``. A compensator that over-estimates the inertia (``c > 1``) by more than
  ``exp(x) - 1`` (about x) makes the loop unstable for every spring: the limit is 0;
- ``1 - a0^2 > a1 - a0 a2`` (a complex pair reaches ``|z| = 1``)::

      K < K* = b^2 (1 - a)(1 - a c) / [J (1 - a)(1 - a c) - T a b (1 - c)]
             = b^2 (1 - a)(1 - a c) / (J [(1 - c) g(x) + c (1 - a)^2]),   g(x) = 1 - (1 + x) e^-x

  (the denominator is positive for every c >= 0 since ``g(x) <= (1 - a)^2``);
- ``p(-1) < 0`` (a real pole leaves through z = -1)::

      K < K_-1 = 2 b^2 (1 + a + 2 a c) / (J f(x)),   f(x) = x (1 + e^-x) - 2 (1 - e^-x);

- the remaining Schur-Cohn inequality holds whenever ``a c < 1``.

So the exact limit is ``0`` when ``a c >= 1`` and ``min(K*, K_-1)`` otherwise. ``K*`` binds for
``x`` up to 4 at ``c = 1`` exactly (``f(4) = 2 (1 + 3 e^-4)``), up to 3.977 at ``c = 0.9`` and 4.023 at
``c = 1.1``; beyond, the real pole binds (J = 0.01, b = 5, T = 0.01, c = 1: 1674.04, not b^2/J = 2500).
Within that domain ``K* = b^2 / J`` at ``c = 1`` (the compensated loop's torque is a running sum
``u_k = u_(k-1) - b v_k - K q_k``), about ``b^2 / J + (1 - c) b / T`` for ``c`` near 1 (a 1 %
modelling error adds ``b / (100 T)``: 5 N m/rad at b = 0.5, T = 1 ms) and about ``2 b / T`` at
``c = 0``. ``1 - a``, ``g`` and ``f`` are evaluated without cancellation (``expm1`` and their
series below x = 1), so the limit keeps full precision down to x = 1e-9. The tests check it
against the spectral radius of the exactly discretized loop and the simulated loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from hapticdesign.errors import InputError, UserError
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
            raise InputError(f"the sensor delay must be a non-negative number of samples, got {self.delay_samples}",
                             "delay")
        if not (self.virtual_damping >= 0 and math.isfinite(self.virtual_damping)):
            raise InputError(f"the wall damping must be a finite number >= 0, got {self.virtual_damping}",
                             "wall_damping")
        if not (self.plant_stiffness >= 0 and math.isfinite(self.plant_stiffness)):
            raise UserError(f"the plant stiffness must be non-negative, got {self.plant_stiffness}")
        if self.model_inertia is not None and not (self.model_inertia >= 0 and math.isfinite(self.model_inertia)):
            raise UserError(f"the model inertia must be non-negative, got {self.model_inertia}")

    @property
    def j_model(self) -> float:
        return self.inertia if self.model_inertia is None else self.model_inertia


@lru_cache(maxsize=64)
def _discretize(j: float, b: float, t: float, k_p: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretization of ``J qdd + b qd + k_p q = u`` over one period.

    Without a plant spring, in closed form (``x = b T / J``, ``a = e^-x``)::

        Phi = [[1, T h1], [0, a]],   Gamma = [T^2 h2 / J, T h1 / J],
        h1 = (1 - e^-x) / x,   h2 = (x - 1 + e^-x) / x^2

    (series below x = 1, 1 and 1/2 at x = 0); with one, ``scipy.linalg.expm`` of the augmented matrix.
    """
    if k_p != 0.0:
        e = expm(np.array([[0.0, 1.0, 0.0], [-k_p / j, -b / j, 1.0 / j], [0.0, 0.0, 0.0]]) * t)
        return e[:2, :2], e[:2, 2]
    x = b * t / j
    if x < 1.0:
        h1 = _series(x, 0, lambda n: (-1) ** n / (n + 1))
        h2 = _series(x, 0, lambda n: (-1) ** n / ((n + 1) * (n + 2)))
    else:
        h1 = -math.expm1(-x) / x
        h2 = (x + math.expm1(-x)) / x ** 2
    return np.array([[1.0, t * h1], [0.0, math.exp(-x)]]), np.array([t * t * h2 / j, t * h1 / j])


def _series(x: float, first: int, term) -> float:
    """``sum_(n >= first) term(n) x^n / n!`` to double precision (for ``0 <= x < 1``)."""
    total, power = 0.0, x ** first / math.factorial(first)
    for n in range(first, first + 40):
        total += term(n) * power
        power *= x / (n + 1)
    return total


def _g(x: float) -> float:
    """``1 - (1 + x) e^-x`` (series ``sum (-1)^n (n - 1) x^n / n!`` from n = 2 below x = 1)."""
    return _series(x, 2, lambda n: (-1) ** n * (n - 1)) if x < 1.0 else 1.0 - (1.0 + x) * math.exp(-x)


def _f(x: float) -> float:
    """``x (1 + e^-x) - 2 (1 - e^-x)`` (series ``sum (-1)^(n-1) (n - 2) x^n / n!`` from n = 3 below x = 1)."""
    if x < 1.0:
        return _series(x, 3, lambda n: (-1) ** (n - 1) * (n - 2))
    return x * (1.0 + math.exp(-x)) + 2.0 * math.expm1(-x)


@dataclass(frozen=True)
class CompensatedLimit:
    """The exact limit with the inertial compensator and the Schur-Cohn condition that sets it:
    ``"complex pair"`` (``K*``), ``"real pole at z = -1"`` (``K_-1``) or ``"no stable spring"``
    (``a c >= 1``, limit 0)."""

    stiffness: float
    bound: str


def compensated_limit(inertia: float, damping: float, period: float, fraction: float = 1.0) -> CompensatedLimit:
    """The closed-form limit of a 1-DOF inertia with a compensator feeding ``fraction * J * a`` forward,
    exact for every ``x = b T / J`` and ``fraction = c = 1 - E/100 >= 0`` (see the module docstring)."""
    if not fraction >= 0:
        raise UserError(f"the compensator fraction must be non-negative, got {fraction}")
    x = damping * period / inertia
    one_minus_a = -math.expm1(-x)
    one_minus_ac = (1.0 - fraction) + fraction * one_minus_a
    if x == 0 or one_minus_ac <= 0:
        return CompensatedLimit(0.0, "no stable spring")
    a = math.exp(-x)
    k_star = damping ** 2 * one_minus_a * one_minus_ac / (
        inertia * ((1.0 - fraction) * _g(x) + fraction * one_minus_a ** 2))
    k_real = 2.0 * damping ** 2 * (1.0 + a + 2.0 * a * fraction) / (inertia * _f(x))
    if k_star <= k_real:
        return CompensatedLimit(k_star, "complex pair")
    return CompensatedLimit(k_real, "real pole at z = -1")


def compensated_boundary(inertia: float, damping: float, period: float, fraction: float = 1.0) -> float:
    """The limit of :func:`compensated_limit` (N m/rad): ``min(K*, K_-1)``, or 0 when ``a c >= 1``."""
    return compensated_limit(inertia, damping, period, fraction).stiffness


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
    floor = 1e-9
    if spectral_radius(system, floor) >= 1.0:
        return 0.0
    lo, hi = _bracket(system, floor, k_max)
    if hi > k_max:
        return math.inf
    return brentq(lambda k: spectral_radius(system, k) - 1.0, lo, hi, xtol=1e-12, rtol=1e-10)


def _bracket(system: MassDamper, floor: float, k_max: float) -> tuple[float, float]:
    """A stable ``lo`` and an unstable ``hi = 2 lo`` (``hi > k_max``: stable up to ``k_max``), searched by doubling
    or halving from the passivity scale ``2 (b + B) / (T (1 + 2 d))`` (Colgate's bound with a delay of ``d``
    samples), so that a few spectral radii place the limit instead of a sweep up from ``floor``."""
    guess = 2.0 * (system.damping + system.virtual_damping) / (system.period * (1 + 2 * system.delay_samples))
    lo = min(max(guess, floor), k_max)
    while lo > floor and spectral_radius(system, lo) >= 1.0:
        lo = max(lo / 2.0, floor)
    hi = 2.0 * lo
    while hi <= k_max and spectral_radius(system, hi) < 1.0:
        lo, hi = hi, 2.0 * hi
    return lo, hi


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
