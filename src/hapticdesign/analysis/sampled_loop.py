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
- :func:`hapticdesign.simulation.boundary.simulated_boundary` (the simulation layer): the numba
  loop itself, ``K`` bisected on the growth of the oscillation.

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
against the spectral radius of the exactly discretized loop and the simulated loop
(:mod:`hapticdesign.simulation.boundary`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from hapticdesign.errors import InputError, UserError
from hapticdesign.workload import EIGEN_ORDER_LIMIT, require_memory, require_within


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
        _check(self)

    @property
    def j_model(self) -> float:
        return self.inertia if self.model_inertia is None else self.model_inertia


@dataclass(frozen=True)
class MassDampers:
    """Many :class:`MassDamper` s at once (each numeric field a number or an array of S values) that share the delay
    and the use of the compensator: the systems of one batched boundary search."""

    inertia: np.ndarray
    damping: np.ndarray
    period: np.ndarray | float
    delay_samples: int = 0
    virtual_damping: np.ndarray | float = 0.0
    compensate_inertia: bool = False
    model_inertia: np.ndarray | None = None
    plant_stiffness: np.ndarray | float = 0.0

    def __post_init__(self) -> None:
        size = np.broadcast_shapes(*(np.shape(getattr(self, name)) for name in _NUMERIC
                                     if getattr(self, name) is not None))
        for name in _NUMERIC:
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, np.broadcast_to(np.asarray(value, dtype=float), size).ravel())
        _check(self)

    @classmethod
    def of(cls, systems: Sequence[MassDamper]) -> "MassDampers":
        """The systems ``systems`` (one delay, compensated all or none) as one batch."""
        if len({(s.delay_samples, s.compensate_inertia) for s in systems}) > 1:
            raise UserError("a batch of mass-dampers shares the delay and the use of the compensator")
        first = systems[0]
        return cls(*(np.array([getattr(s, name) for s in systems], dtype=float) for name in _NUMERIC[:3]),
                   first.delay_samples, np.array([s.virtual_damping for s in systems], dtype=float),
                   first.compensate_inertia, np.array([s.j_model for s in systems], dtype=float),
                   np.array([s.plant_stiffness for s in systems], dtype=float))

    def __len__(self) -> int:
        return len(self.inertia)

    @property
    def j_model(self) -> np.ndarray:
        return self.inertia if self.model_inertia is None else self.model_inertia


_NUMERIC = ("inertia", "damping", "period", "virtual_damping", "model_inertia", "plant_stiffness")


def _check(system: MassDamper | MassDampers) -> None:
    """The one-line refusals of a mass-damper's (or a batch's) values."""
    for name in ("inertia", "period"):
        value = getattr(system, name)
        if not np.all((np.asarray(value) > 0) & np.isfinite(value)):
            raise UserError(f"the {name} must be positive, got {_worst(value)}")
    if not np.all((np.asarray(system.damping) >= 0) & np.isfinite(system.damping)):
        raise UserError(f"the damping must be non-negative, got {_worst(system.damping)}")
    if system.delay_samples < 0:
        raise InputError(f"the sensor delay must be a non-negative number of samples, got {system.delay_samples}",
                         "delay")
    if not np.all((np.asarray(system.virtual_damping) >= 0) & np.isfinite(system.virtual_damping)):
        raise InputError(f"the wall damping must be a finite number >= 0, got {_worst(system.virtual_damping)}",
                         "wall_damping")
    if not np.all((np.asarray(system.plant_stiffness) >= 0) & np.isfinite(system.plant_stiffness)):
        raise UserError(f"the plant stiffness must be non-negative, got {_worst(system.plant_stiffness)}")
    if system.model_inertia is not None and not np.all((np.asarray(system.model_inertia) >= 0)
                                                       & np.isfinite(system.model_inertia)):
        raise UserError(f"the model inertia must be non-negative, got {_worst(system.model_inertia)}")


def _worst(value) -> float:
    """The value a refusal names: the number itself, or a batch's smallest (or first non-finite) value."""
    values = np.ravel(np.asarray(value, dtype=float))
    bad = values[~np.isfinite(values)]
    return float(bad[0] if bad.size else values.min())


def _discretize(j: np.ndarray, b: np.ndarray, t: np.ndarray, k_p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretization of ``J qdd + b qd + k_p q = u`` over one period, for S systems at once
    (arrays of S values): ``Phi`` (S, 2, 2) and ``Gamma`` (S, 2).

    Without a plant spring, in closed form (``x = b T / J``, ``a = e^-x``)::

        Phi = [[1, T h1], [0, a]],   Gamma = [T^2 h2 / J, T h1 / J],
        h1 = (1 - e^-x) / x,   h2 = (x - 1 + e^-x) / x^2

    (series below x = 1, 1 and 1/2 at x = 0); with one, ``scipy.linalg.expm`` of the augmented matrix.
    """
    x = b * t / j
    small = x < 1.0
    xs, xl = np.where(small, x, 0.0), np.where(small, 1.0, x)
    h1 = np.where(small, _series(xs, _H1), -np.expm1(-xl) / xl)
    h2 = np.where(small, _series(xs, _H2), (xl + np.expm1(-xl)) / xl ** 2)
    phi = np.zeros((len(x), 2, 2))
    phi[:, 0, 0] = 1.0
    phi[:, 0, 1] = t * h1
    phi[:, 1, 1] = np.exp(-x)
    gamma = np.stack([t * t * h2 / j, t * h1 / j], axis=1)
    spring = np.flatnonzero(k_p != 0.0)
    if spring.size:
        aug = np.zeros((spring.size, 3, 3))
        aug[:, 0, 1] = 1.0
        aug[:, 1, 0] = -k_p[spring] / j[spring]
        aug[:, 1, 1] = -b[spring] / j[spring]
        aug[:, 1, 2] = 1.0 / j[spring]
        e = expm(aug * t[spring, None, None])
        phi[spring], gamma[spring] = e[:, :2, :2], e[:, :2, 2]
    return phi, gamma


def _taylor(first: int, term) -> np.ndarray:
    """The coefficients of ``sum_(n >= first) term(n) x^n / n!`` up to ``x^(first + 39)`` (zeros below ``first``):
    double precision for ``0 <= x < 1``."""
    return np.array([term(n) / math.factorial(n) if n >= first else 0.0 for n in range(first + 40)])


_H1 = _taylor(0, lambda n: (-1) ** n / (n + 1))
_H2 = _taylor(0, lambda n: (-1) ** n / ((n + 1) * (n + 2)))
_G = _taylor(2, lambda n: (-1) ** n * (n - 1))
_F = _taylor(3, lambda n: (-1) ** (n - 1) * (n - 2))


def _series(x, coefficients: np.ndarray):
    """The power series ``coefficients`` at ``x`` (a number or an array), by Horner's rule."""
    return np.polynomial.polynomial.polyval(x, coefficients)


def _g(x: float) -> float:
    """``1 - (1 + x) e^-x`` (series ``sum (-1)^n (n - 1) x^n / n!`` from n = 2 below x = 1)."""
    return float(_series(x, _G)) if x < 1.0 else 1.0 - (1.0 + x) * math.exp(-x)


def _f(x: float) -> float:
    """``x (1 + e^-x) - 2 (1 - e^-x)`` (series ``sum (-1)^(n-1) (n - 2) x^n / n!`` from n = 3 below x = 1)."""
    if x < 1.0:
        return float(_series(x, _F))
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


class ClosedLoops:
    """The one-sample maps of S sampled loops, state ``[q, qd, u_prev, s_(k-1), ..., s_(k-d)]`` with ``s = (q, qd,
    a)``: ``m(K) = m(0) - K g e_c^T`` (the spring enters one column ``c``, that of ``q`` in the law, through
    ``g = (Gamma, 1)``), so a search builds the spring-free maps once."""

    def __init__(self, systems: MassDampers):
        j, b, d = systems.inertia, systems.damping, systems.delay_samples
        phi, gamma = _discretize(j, b, systems.period, systems.plant_stiffness)
        count, size = len(j), 3 + 3 * d
        sense = np.zeros((count, 3, 3))  # s_k from z_k
        sense[:, 0, 0] = 1.0
        sense[:, 1, 1] = 1.0
        sense[:, 2, 0] = -systems.plant_stiffness / j
        sense[:, 2, 1] = -b / j
        sense[:, 2, 2] = 1.0 / j
        gains = np.stack([np.zeros(count), -systems.virtual_damping,
                          float(systems.compensate_inertia) * systems.j_model], axis=1)
        law = np.einsum("si,sij->sj", gains, sense) if d == 0 else np.concatenate(
            [np.zeros((count, 3 + 3 * (d - 1))), gains], axis=1)
        m = np.zeros((count, size, size))
        m[:, :2, :2] = phi
        m[:, :2] += gamma[:, :, None] * law[:, None, :]
        m[:, 2] = law
        if d > 0:
            m[:, 3:6, :3] = sense
            m[:, 6:, 3:size - 3] = np.eye(size)[3:size - 3, 3:size - 3]
        self.base, self.column = m, 0 if d == 0 else size - 3
        self.spring = np.concatenate([gamma, np.ones((count, 1))], axis=1)

    def matrices(self, stiffness: np.ndarray, index: np.ndarray | slice = slice(None)) -> np.ndarray:
        """The maps (S', n, n) of the systems ``index`` under the springs ``stiffness`` (S',)."""
        m = self.base[index].copy()
        m[:, :3, self.column] -= np.asarray(stiffness, dtype=float)[:, None] * self.spring[index]
        return m

    def radii(self, stiffness: np.ndarray, index: np.ndarray | slice = slice(None)) -> np.ndarray:
        """Spectral radii (S',) of :meth:`matrices` (the loop is stable below 1)."""
        return np.abs(np.linalg.eigvals(self.matrices(stiffness, index))).max(axis=-1)


def closed_loop_matrix(system: MassDamper, stiffness: float) -> np.ndarray:
    """One-sample map of ``[q, qd, u_prev, s_(k-1), ..., s_(k-d)]`` with ``s = (q, qd, a)`` (:class:`ClosedLoops`)."""
    return ClosedLoops(MassDampers.of([system])).matrices(np.array([stiffness]))[0]


def spectral_radius(system: MassDamper, stiffness: float) -> float:
    return float(ClosedLoops(MassDampers.of([system])).radii(np.array([stiffness]))[0])


FLOOR = 1e-9
"""The smallest spring of the search: a loop unstable already there has the limit 0."""
RTOL, XTOL = 1e-10, 1e-12
"""The search stops when the stable and unstable springs are within ``XTOL + RTOL K`` of each other."""


def exact_boundary(system: MassDamper, k_max: float = 1e9) -> float:
    """Smallest spring stiffness at which the exactly discretized loop loses stability (:func:`exact_boundaries`)."""
    return float(exact_boundaries(MassDampers.of([system]), k_max=k_max)[0])


def exact_boundaries(systems: MassDampers, groups: np.ndarray | None = None, k_max: float = 1e9) -> np.ndarray:
    """The exact limit of each system (S,), or the smallest in each group (``groups``: S labels 0 ... G - 1; (G,)).

    A system unstable at :data:`FLOOR` has the limit 0; otherwise a stable ``lo`` and an unstable ``hi`` are
    bracketed by halving or doubling from the passivity scale ``2 (b + B) / (T (1 + 2 d))`` (Colgate's bound with a
    delay of ``d`` samples; ``hi > k_max``: stable up to ``k_max``, the limit is inf), and the crossing of the
    spectral radius through 1 is found by the Illinois variant of regula falsi (a bisection after two steps that
    did not halve the bracket) to ``XTOL + RTOL K``; the limit is the bracket's middle. All systems move at once
    (one batched eigenvalue call per step). In a group, a system whose stable ``lo`` reaches the smallest unstable
    ``hi`` of another cannot hold the group's smallest limit and leaves the search.
    """
    order = 3 + 3 * systems.delay_samples
    what = f"the closed-loop matrices of {len(systems):,} loops with a {systems.delay_samples:,}-sample delay"
    require_memory(what, 8.0 * order * order * len(systems))
    require_within(what, order, EIGEN_ORDER_LIMIT, "rows")
    count = len(systems)
    group = np.arange(count) if groups is None else np.asarray(groups, dtype=np.int64)
    n_group = int(group.max()) + 1 if count else 0
    loops = ClosedLoops(systems)
    f_floor = loops.radii(np.full(count, FLOOR)) - 1.0
    limit = np.full(count, np.nan)
    limit[f_floor >= 0.0] = 0.0
    guess = 2.0 * (systems.damping + systems.virtual_damping) / (systems.period * (1 + 2 * systems.delay_samples))
    lo = np.minimum(np.maximum(guess, FLOOR), k_max)
    hi, f_lo, f_hi = 2.0 * lo, np.where(lo == FLOOR, f_floor, np.nan), np.full(count, np.nan)
    search = _Search(group, n_group, limit)
    todo = np.flatnonzero(search.open() & (lo > FLOOR))
    while todo.size:  # halve lo until it is stable
        f = loops.radii(lo[todo], todo) - 1.0
        stable, unstable = todo[f < 0.0], todo[f >= 0.0]
        f_lo[stable] = f[f < 0.0]
        halved = np.maximum(lo[unstable] / 2.0, FLOOR)
        known = halved == lo[unstable] / 2.0
        f_hi[unstable[known]] = f[f >= 0.0][known]
        lo[unstable], hi[unstable] = halved, 2.0 * halved
        f_lo[unstable[halved == FLOOR]] = f_floor[unstable[halved == FLOOR]]
        todo = unstable[known & (halved > FLOOR)]
    while True:  # double hi until it is unstable
        todo = np.flatnonzero(search.open() & np.isnan(f_hi))
        beyond = todo[hi[todo] > k_max]
        limit[beyond] = np.inf
        todo = todo[hi[todo] <= k_max]
        if not todo.size:
            break
        f = loops.radii(hi[todo], todo) - 1.0
        stable, unstable = todo[f < 0.0], todo[f >= 0.0]
        f_hi[unstable] = f[f >= 0.0]
        lo[stable], f_lo[stable], hi[stable] = hi[stable], f[f < 0.0], 2.0 * hi[stable]
        if groups is not None:
            search.prune(lo, hi, f_hi)
    side, stall = np.zeros(count, dtype=np.int8), np.zeros(count, dtype=np.int8)
    while True:  # Illinois regula falsi
        if groups is not None:
            search.prune(lo, hi, f_hi)
        todo = np.flatnonzero(search.open())
        done = todo[hi[todo] - lo[todo] <= XTOL + RTOL * hi[todo]]
        limit[done] = 0.5 * (lo[done] + hi[done])
        todo = todo[hi[todo] - lo[todo] > XTOL + RTOL * hi[todo]]
        if not todo.size:
            break
        a, b, fa, fb = lo[todo], hi[todo], f_lo[todo], f_hi[todo]
        x = (a * fb - b * fa) / (fb - fa)
        x = np.where((stall[todo] >= 2) | ~(x > a) | ~(x < b), 0.5 * (a + b), x)
        f = loops.radii(x, todo) - 1.0
        up = f >= 0.0
        stall[todo] = np.where(np.maximum(np.where(up, x, b) - np.where(up, a, x), 0.0) > 0.5 * (b - a),
                               stall[todo] + 1, 0)
        rise, fall = todo[up], todo[~up]
        f_lo[rise[side[rise] == 2]] *= 0.5
        f_hi[fall[side[fall] == 1]] *= 0.5
        hi[rise], f_hi[rise], side[rise] = x[up], f[up], 2
        lo[fall], f_lo[fall], side[fall] = x[~up], f[~up], 1
    return limit if groups is None else search.smallest(limit)


class _Search:
    """Which systems of :func:`exact_boundaries` still search: not done (``limit`` NaN, 0 for those unstable at the
    floor, set before), their group not settled at 0, and not left behind by another system of their group."""

    def __init__(self, group: np.ndarray, n_group: int, limit: np.ndarray):
        self.group, self.n_group, self.limit = group, n_group, limit
        self.zero = np.zeros(n_group, dtype=bool)
        self.zero[group[limit == 0.0]] = True
        self.out = np.zeros(len(group), dtype=bool)
        self.settled = self.zero[group]

    def open(self) -> np.ndarray:
        return np.isnan(self.limit) & ~self.out & ~self.settled

    def prune(self, lo: np.ndarray, hi: np.ndarray, f_hi: np.ndarray) -> None:
        """Leave out the systems whose stable ``lo`` is at or above their group's smallest known unstable ``hi``."""
        unstable = np.full(self.n_group, np.inf)
        known = self.open() & ~np.isnan(f_hi)
        np.minimum.at(unstable, self.group[known], hi[known])
        self.out |= self.open() & (lo >= unstable[self.group])

    def smallest(self, limit: np.ndarray) -> np.ndarray:
        """Each group's smallest limit over the systems that finished (the ones left behind hold larger ones)."""
        out = np.full(self.n_group, np.inf)
        np.minimum.at(out, self.group[~self.out & ~self.settled], limit[~self.out & ~self.settled])
        out[self.zero] = 0.0
        return out
