"""The sampled haptic loop: one record of its settings, one construction of its exact limit (seed 000 ch. 4, §5).

- :class:`SampledLoop`: the settings of every command and index (rate, delay, velocity estimate, compensation and
  its modelling error, the wall's damper, the hand, the joints held); practice's by default, the seed's one call
  away (:meth:`SampledLoop.seed`).
- :func:`handle_loops` / :func:`handle_limits`: the loop of an n-joint plant ``H``, ``B`` (with the hand and
  gravity's gradient) under a wall ``K w w^T``, discretized exactly under a zero-order hold, as one linear map of the
  sampled state; the limit is the smallest ``K`` at which its spectral radius reaches 1 (:func:`loop_limits`).
  :func:`joint_limits` is its one-joint case, the 1-DOF mass-damper ``J qdd + b qd = u`` of ``stability-boundary``
  and ``zwidth`` (about ``2 b / T`` without compensation, ``b^2 / J`` with the seed's).
- :func:`compensated_boundary`: the closed form of the 1-DOF limit with the seed's inertial compensator, no delay
  and no virtual damper (derived below), the oracle of the simulation tests.
- :func:`hapticdesign.simulation.boundary.simulated_boundary` (the simulation layer): the numba loop itself, ``K``
  bisected on the growth of the oscillation.

The 1-DOF law with the compensator (model inertia ``J_m = c J``, ``c = 1 - E/100`` for a modelling error of E
percent) is ``u = J_m a - K q - B qd``, ``a`` the acceleration sampled under the previous held torque.

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
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from hapticdesign.errors import InputError, RenamedWarning, UserError
from hapticdesign.model.actuators import Transmission
from hapticdesign.workload import EIGEN_ORDER_LIMIT, require_memory, require_within


def _taylor(first: int, term) -> np.ndarray:
    """The coefficients of ``sum_(n >= first) term(n) x^n / n!`` up to ``x^(first + 39)`` (zeros below ``first``):
    double precision for ``0 <= x < 1``."""
    return np.array([term(n) / math.factorial(n) if n >= first else 0.0 for n in range(first + 40)])


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


class SpringLoops:
    """The one-sample maps of S sampled loops in which the wall's spring ``K`` enters as a rank-one term,
    ``m(K) = m(0) - K g h^T`` (``base`` (S, N, N), ``g`` and ``h`` (S, N)), so a search builds the spring-free maps
    once (the loops of :func:`handle_loops`); ``law`` (S, n, N) and ``wall`` (S, n) give the torque the controller
    holds over the next period, ``law s - K wall (h^T s)`` (:meth:`torques`)."""

    def __init__(self, base: np.ndarray, g: np.ndarray, h: np.ndarray, law: np.ndarray, wall: np.ndarray):
        self.base, self.g, self.h, self.law, self.wall = base, g, h, law, wall

    def __len__(self) -> int:
        return len(self.base)

    def matrices(self, stiffness: np.ndarray, index: np.ndarray | slice = slice(None)) -> np.ndarray:
        """The maps (S', N, N) of the systems ``index`` under the springs ``stiffness`` (S',)."""
        k = np.asarray(stiffness, dtype=float)[:, None, None]
        return self.base[index] - k * self.g[index][:, :, None] * self.h[index][:, None, :]

    def torques(self, stiffness: float, states: np.ndarray, index: int = 0) -> np.ndarray:
        """The torques (..., n) loop ``index`` holds after the sampled states (..., N) under the spring
        ``stiffness``."""
        return states @ self.law[index].T - stiffness * np.multiply.outer(states @ self.h[index], self.wall[index])

    def radii(self, stiffness: np.ndarray, index: np.ndarray | slice = slice(None)) -> np.ndarray:
        """Spectral radii (S',) of :meth:`matrices` (the loop is stable below 1)."""
        return np.abs(np.linalg.eigvals(self.matrices(stiffness, index))).max(axis=-1)


FLOOR = 1e-9
"""The smallest spring of the search: a loop unstable already there has the limit 0."""
STEP = 1.1
"""The first step of the limit's bracket from its guess (down by it, or up), squared at each further step."""
RTOL, XTOL = 1e-10, 1e-12
"""The search stops when the stable and unstable springs are within ``XTOL + RTOL K`` of each other."""


def loop_limits(loops: SpringLoops, guess: np.ndarray, groups: np.ndarray | None = None,
                k_max: float = 1e9) -> np.ndarray:
    """The upper ends of :func:`loop_intervals`: the spring at which each loop (S,) stops being stable, or the
    smallest in each group (G,)."""
    return loop_intervals(loops, guess, groups, k_max)[1]


def loop_intervals(loops: SpringLoops, guess: np.ndarray, groups: np.ndarray | None = None,
                   k_max: float = 1e9) -> tuple[np.ndarray, np.ndarray]:
    """The springs ``[low, high]`` for which each loop (S,) is stable, or each group's (``groups``: S labels 0 ...
    G - 1; (G,) each: the largest ``low`` and the smallest ``high`` of its loops, the springs all of them hold).

    A loop stable at :data:`FLOOR` has ``low`` 0. One unstable there (gravity pulling the handle away from the wall
    faster than anything else holds it: over-compensation, an inverted pose) is tried at its guess and then at
    every decade up to ``k_max``; with no stable spring among them both ends are 0, else ``low`` is the crossing
    below the first stable spring found (:func:`_crossing`). ``high``: from ``guess`` (or that stable spring) a
    stable ``lo`` and an unstable ``hi`` are bracketed by steps down or up that start at :data:`STEP` and square
    each time (``hi > k_max``: stable up to ``k_max``, inf), then the crossing is found to ``XTOL + RTOL K``. All
    loops move at once (one batched eigenvalue call per step). In a group, a loop whose stable ``lo`` reaches the
    smallest unstable ``hi`` of another cannot hold the group's smallest ``high`` and leaves the search, so a bracket
    as tight as the guess allows lets most of a group leave after the first step of regula falsi (halving from a
    guess a few per cent above the limit left ``lo`` far below it and kept them searching: 3.4 times the steps once
    gravity's gradient put half the limits just below their guess).
    """
    count = len(loops)
    group = np.arange(count) if groups is None else np.asarray(groups, dtype=np.int64)
    n_group = int(group.max()) + 1 if count else 0
    f_floor = loops.radii(np.full(count, FLOOR)) - 1.0
    limit, low = np.full(count, np.nan), np.zeros(count)
    lo = np.minimum(np.maximum(guess, FLOOR), k_max)
    hi, f_lo, f_hi = lo * STEP, np.where(lo == FLOOR, f_floor, np.nan), np.full(count, np.nan)
    floor_unstable = np.flatnonzero(f_floor >= 0.0)
    if floor_unstable.size:
        found, f_found, below, f_below = _stable_spring(loops, floor_unstable, lo[floor_unstable], k_max)
        held = ~np.isnan(found)
        limit[floor_unstable[~held]] = 0.0
        kept = floor_unstable[held]
        low[kept] = _crossing(lambda x, idx: 1.0 - loops.radii(x, kept[idx]), below[held], found[held],
                              -f_below[held], -f_found[held])
        lo[kept], f_lo[kept], hi[kept] = found[held], f_found[held], found[held] * STEP
    step = np.full(count, STEP)
    search = _Search(group, n_group, limit)
    todo = np.flatnonzero(search.open() & (lo > FLOOR) & np.isnan(f_lo))
    while todo.size:  # step lo down until it is stable
        f = loops.radii(lo[todo], todo) - 1.0
        stable, unstable = todo[f < 0.0], todo[f >= 0.0]
        f_lo[stable] = f[f < 0.0]
        lower = np.maximum(lo[unstable] / step[unstable], FLOOR)
        hi[unstable], f_hi[unstable], lo[unstable] = lo[unstable], f[f >= 0.0], lower
        step[unstable] **= 2
        floored = unstable[lower == FLOOR]
        f_lo[floored] = f_floor[floored]
        todo = unstable[lower > FLOOR]
    while True:  # step hi up until it is unstable
        todo = np.flatnonzero(search.open() & np.isnan(f_hi))
        beyond = todo[hi[todo] > k_max]
        limit[beyond] = np.inf
        todo = todo[hi[todo] <= k_max]
        if not todo.size:
            break
        f = loops.radii(hi[todo], todo) - 1.0
        stable, unstable = todo[f < 0.0], todo[f >= 0.0]
        f_hi[unstable] = f[f >= 0.0]
        step[stable] **= 2
        lo[stable], f_lo[stable], hi[stable] = hi[stable], f[f < 0.0], hi[stable] * step[stable]
        if groups is not None:
            search.prune(lo, hi, f_hi)
    todo = np.flatnonzero(search.open())
    prune = None if groups is None else (lambda idx, a, b: search.left_behind(todo, idx, a, b))
    limit[todo] = _crossing(lambda x, idx: loops.radii(x, todo[idx]) - 1.0, lo[todo], hi[todo], f_lo[todo],
                            f_hi[todo], prune)
    if groups is None:
        return low, limit
    low, high = search.largest(low), search.smallest(limit)
    apart = low > high  # no spring holds every loop of the group
    low[apart] = high[apart] = 0.0
    return low, high


def _stable_spring(loops: SpringLoops, index: np.ndarray, guess: np.ndarray,
                   k_max: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For the loops ``index``, unstable at :data:`FLOOR`: a stable spring (their guess, else the first decade from
    ``10 FLOOR`` to ``k_max`` that is; NaN where none is), its ``f = radius - 1``, and the unstable spring below it
    with its ``f`` (the last one tried, or the floor)."""
    found, f_found = np.full(len(index), np.nan), np.full(len(index), np.nan)
    below, f_below = np.full(len(index), FLOOR), loops.radii(np.full(len(index), FLOOR), index) - 1.0
    decades = FLOOR * 10.0 ** np.arange(1, int(np.floor(np.log10(k_max / FLOOR))) + 1)
    for level in range(len(decades) + 1):
        todo = np.flatnonzero(np.isnan(found))
        if not todo.size:
            break
        trial = guess[todo] if level == 0 else np.full(todo.size, decades[level - 1])
        f = loops.radii(trial, index[todo]) - 1.0
        stable = f < 0.0
        found[todo[stable]], f_found[todo[stable]] = trial[stable], f[stable]
        if level:  # the decades rise: an unstable one is the highest unstable spring below a stable one found later
            below[todo[~stable]], f_below[todo[~stable]] = trial[~stable], f[~stable]
    return found, f_found, below, f_below


def _crossing(evaluate, lo: np.ndarray, hi: np.ndarray, f_lo: np.ndarray, f_hi: np.ndarray,
              prune=None) -> np.ndarray:
    """Where ``evaluate(x, idx)`` (the sign of ``radius - 1`` or its opposite, of the systems ``idx`` of these arrays)
    crosses 0 between ``lo`` (``f < 0``) and ``hi`` (``f >= 0``), by the Illinois variant of regula falsi to
    ``XTOL + RTOL K``: the bracket's middle. A step that would land within half the tolerance of an end (the secant
    through an end at f = 0 lands on it) lands that far from it, so an end that has converged closes the bracket at
    the next step, as in Dekker's method; a bisection follows two stalls, a stall being a step that neither halved
    the bracket nor moved its end by less than half the move before (Brent's test): a secant converging on the
    crossing from one side, its moves shrinking fast, is not cut short by a bisection of the far end (which took
    about 30 steps to reach the tolerance where the radius is nearly linear). ``prune(idx, lo, hi)`` (a group
    search) returns a mask of the systems that no longer matter among the open ones ``idx`` (NaN for them)."""
    lo, hi, f_lo, f_hi = (np.array(v, dtype=float) for v in (lo, hi, f_lo, f_hi))
    out = np.full(len(lo), np.nan)
    open_ = np.ones(len(lo), dtype=bool)
    side, stall = np.zeros(len(lo), dtype=np.int8), np.zeros(len(lo), dtype=np.int8)
    moved = np.full(len(lo), np.inf)  # how far the end each step replaced moved
    while True:
        if prune is not None:
            open_ &= ~prune(np.flatnonzero(open_), lo, hi)
        todo = np.flatnonzero(open_)
        narrow = hi[todo] - lo[todo] <= XTOL + RTOL * hi[todo]
        done = todo[narrow]
        out[done] = 0.5 * (lo[done] + hi[done])
        open_[done] = False
        todo = todo[~narrow]
        if not todo.size:
            return out
        a, b, fa, fb = lo[todo], hi[todo], f_lo[todo], f_hi[todo]
        x = (a * fb - b * fa) / (fb - fa)
        x = np.where((stall[todo] >= 2) | ~(x >= a) | ~(x <= b), 0.5 * (a + b), x)
        half = 0.5 * (XTOL + RTOL * b)
        x = np.clip(x, a + half, b - half)
        f = evaluate(x, todo)
        up = f >= 0.0
        move = np.abs(x - np.where(up, b, a))
        halved = np.where(up, x - a, b - x) <= 0.5 * (b - a)
        stall[todo] = np.where(halved | (move < 0.5 * moved[todo]), 0, stall[todo] + 1)
        moved[todo] = move
        rise, fall = todo[up], todo[~up]
        f_lo[rise[side[rise] == 2]] *= 0.5
        f_hi[fall[side[fall] == 1]] *= 0.5
        hi[rise], f_hi[rise], side[rise] = x[up], f[up], 2
        lo[fall], f_lo[fall], side[fall] = x[~up], f[~up], 1


class _Search:
    """Which systems of :func:`loop_intervals` still search: not done (``limit`` NaN, 0 for those with no stable
    spring, set before), their group not settled at 0, and not left behind by another system of their group."""

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

    def left_behind(self, systems: np.ndarray, open_: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """:meth:`prune` in the regula-falsi phase (every bracket known): of ``systems`` (whose brackets ``lo``,
        ``hi`` these are), a mask of the open ones ``open_`` left behind, now out."""
        group = self.group[systems[open_]]
        unstable = np.full(self.n_group, np.inf)
        np.minimum.at(unstable, group, hi[open_])
        drop = np.zeros(len(systems), dtype=bool)
        drop[open_] = lo[open_] >= unstable[group]
        self.out[systems[drop]] = True
        return drop

    def largest(self, low: np.ndarray) -> np.ndarray:
        """Each group's largest lower end over all its systems (0 for a group settled at 0)."""
        out = np.zeros(self.n_group)
        np.maximum.at(out, self.group, low)
        out[self.zero] = 0.0
        return out

    def smallest(self, limit: np.ndarray) -> np.ndarray:
        """Each group's smallest limit over the systems that finished (the ones left behind hold larger ones)."""
        out = np.full(self.n_group, np.inf)
        np.minimum.at(out, self.group[~self.out & ~self.settled], limit[~self.out & ~self.settled])
        out[self.zero] = 0.0
        return out


SCALE_RANGE = (1e-12, 1e12)
"""The magnitudes (SI units) a loop's settings and plants are computed for: beyond them the loop's ratios (``J / T``,
``B / T``, the damper grid's ``4 J / T``) and the stiffness search (up to 1e12) lose their meaning in double
precision. A setting that may be off (a damper, a hand) may be 0."""
MIN_PERIOD = SCALE_RANGE[0]
"""The shortest sample period (s) of a loop (longer periods are checked where a plant meets them, as its ratios)."""
MAX_WALL_DAMPING = SCALE_RANGE[1]
"""The largest wall damper (N s/m, or N m s/rad on a joint)."""


@dataclass(frozen=True)
class Hand:
    """A linear hand at the handle: mass (kg), damping (N s/m) and stiffness (N/m) to ground, the same in every
    direction; mapped to the joints as ``x J_v^T J_v`` (a linearized grasp)."""

    mass: float = 0.0
    damping: float = 0.0
    stiffness: float = 0.0
    name: str | None = None
    """The preset's name (:data:`HANDS`), None for a hand of one's own."""

    def __post_init__(self) -> None:
        values = (self.mass, self.damping, self.stiffness)
        if not all(math.isfinite(v) and v >= 0 for v in values):
            raise InputError(f"the hand's mass, damping and stiffness must be finite and non-negative, got "
                             f"{', '.join(f'{v:g}' for v in values)}", "hand_mass", "hand_damping", "hand_stiffness")
        for name, value in zip(("mass", "damping", "stiffness"), values):
            if value > SCALE_RANGE[1]:
                raise InputError(f"the hand's {name} must be at most {SCALE_RANGE[1]:g} (SI units), got {value:g}",
                                 f"hand_{name}")

    @staticmethod
    def optional(mass: float = 0.0, damping: float = 0.0, stiffness: float = 0.0) -> "Hand | None":
        """A hand when any of its values is non-zero, else None (no hand)."""
        return Hand(mass, damping, stiffness) if (mass or damping or stiffness) else None

    @staticmethod
    def named(name: str) -> "Hand":
        """The preset ``name`` of :data:`HANDS` (``grasp``, its former name, is ``light`` with a deprecation line);
        a one-line error for another name."""
        if name == "grasp":
            warnings.warn("the hand 'grasp' is now called 'light' (the same 0.1 kg, 2 N s/m, 200 N/m); 'grasp' "
                          "will be removed", RenamedWarning, stacklevel=2)
            name = "light"
        if name not in HANDS:
            raise UserError(f"unknown hand {str(name)[:40]!r}; choose one of {', '.join(HANDS)} or give mass, damping "
                            "and stiffness")
        return HANDS[name]

    def as_dict(self) -> dict:
        return {"mass": self.mass, "damping": self.damping, "stiffness": self.stiffness,
                **({} if self.name is None else {"name": self.name})}

    def describe(self) -> str:
        """``light hand (0.1 kg, 2 N s/m, 200 N/m)``: what an output states of it."""
        return (f"{self.name or 'a'} hand ({self.mass:g} kg, {self.damping:g} N s/m, {self.stiffness:g} N/m)")


HANDS: dict[str, Hand] = {
    "light": Hand(mass=0.1, damping=2.0, stiffness=200.0, name="light"),
    "firm": Hand(mass=0.554, damping=6.45, stiffness=135.0, name="firm"),
}
"""The hands a wall is designed for, linear mass-damper-springs at the handle.

- ``light``: a light fingertip or pen grasp, 0.1 kg, 2 N s/m, 200 N/m, at the low (least stabilizing) end of the
  hand and fingertip impedances measured by Tsuji, Morasso, Goto & Ito (1995, "Human hand impedance characteristics
  during maintained posture", Biol. Cybern. 72) and Hajian & Howe (1997, "Identification of the mechanical impedance
  at the human finger tip", J. Biomech. Eng. 119): the hand that stabilizes least, so the wall to design for.
- ``firm``: a firm grasp of a stylus or knob, 0.554 kg, 6.45 N s/m, 135 N/m: figures quoted from a published
  second-order fit of a grasping hand whose source this project has not checked, so an assumption of the right
  order, not a measurement: stylus and knob grasps identified by Fu & Cavusoglu ("Three-dimensional human arm and
  hand dynamics and variability model for a stylus-based haptic interface", ICRA 2010) and Hasser & Cutkosky
  ("System identification of the human hand grasping a haptic knob", Haptics Symposium 2002) are of this kind, their
  damping and stiffness rising with the grip force.

Colgate & Brown (1994, "Factors affecting the Z-width of a haptic display", ICRA), Hulin, Preusche & Hirzinger (2008,
"Stability boundary for haptic rendering: influence of human operator", IROS) and Diaz & Gil (2010, "Influence of
vibration modes and human operator on the stability of haptic rendering", IEEE T-RO 26) show how the operator's
impedance enlarges the stable region: a firmer grasp renders stiffer walls, and a wall designed for the light hand
holds for the firm one. Without a hand, the limit is set by the device's own viscous damping alone (about
``2 b / T``), which rewards friction and damping rather than the design (docs/simulation.md)."""

GRASP = HANDS["light"]
"""The default hand of the "with the hand" limit (``light`` of :data:`HANDS`). A user changes it (``hand`` by name, or
``hand_mass``, ``hand_damping``, ``hand_stiffness``)."""

VELOCITIES = ("difference", "sampled")
"""How the virtual damper's velocity is formed: the backward difference of the sampled positions (practice), or the
sampled velocity itself (the seed's perfect sensor, seed 000 §4.1.3 ix)."""
COMPENSATIONS = ("none", "gravity", "full")
"""What the controller feeds forward: nothing, the gravity torque (practice), or the full inverse dynamics with the
sampled acceleration (the seed's, seed 000 §4.1.1.2)."""


@dataclass(frozen=True)
class SampledLoop:
    """The settings of a sampled haptic loop, one record for every command and index.

    ``period`` (s) the servo period, ``delay`` whole samples between reading the sensors and applying the torque,
    ``velocity`` of :data:`VELOCITIES`, ``compensation`` of :data:`COMPENSATIONS` with ``error_percent`` (percent
    E: a bare joint's compensator feeds ``(1 - E/100)`` times its inertia; a device's is its model device, every
    mass, mass centre and inertia off by E %, :mod:`hapticdesign.model.compensator_model`, whose ``H`` and ``G``
    the callers pass to :func:`handle_loops`), ``wall_damping`` the wall's damper
    (N s/m, or N m s/rad on a joint), ``hand`` a :class:`Hand` at the handle (None: none), ``held`` the joints held
    fixed (none by default: a Cartesian wall acts with every actuated joint free, as under a user's hand).
    The defaults are what practice uses: 1 kHz, one sample of delay, backward-difference velocity, gravity
    compensation only; :meth:`seed` gives the seed's settings (full compensation, no delay, sampled velocity).
    About a pose, gravity enters the linearized loop through its gradient: the plant's ``K_G = dG/dq`` and the
    compensator's ``s K_G`` on the sensed pose (:attr:`gravity_share`)."""

    period: float = 1e-3
    delay: int = 1
    velocity: str = "difference"
    compensation: str = "gravity"
    error_percent: float = 0.0
    wall_damping: float = 0.0
    hand: Hand | None = None
    held: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        if isinstance(self.period, bool) or not (isinstance(self.period, (int, float)) and math.isfinite(self.period)
                                                 and self.period > 0):
            raise InputError(f"the sample period must be a positive number of seconds, got {self.period!r}", "period")
        if self.period < MIN_PERIOD:
            raise InputError(f"the sample period must be at least {MIN_PERIOD:g} s, got {self.period:g}", "period")
        if isinstance(self.delay, bool) or not isinstance(self.delay, (int, np.integer)) or self.delay < 0:
            raise InputError(f"the sensor delay must be a non-negative number of samples, got {self.delay!r}", "delay")
        if self.velocity not in VELOCITIES:
            raise InputError(f"unknown velocity estimate {str(self.velocity)[:40]!r}; choose one of "
                             f"{', '.join(VELOCITIES)}", "velocity")
        if self.compensation not in COMPENSATIONS:
            raise InputError(f"unknown compensation {str(self.compensation)[:40]!r}; choose one of "
                             f"{', '.join(COMPENSATIONS)}", "compensation")
        if not (math.isfinite(self.error_percent) and -100 < self.error_percent < 100):
            raise InputError(f"the error percentage must be a finite number between -100 and 100 (exclusive), got "
                             f"{self.error_percent}", "error_percent")
        if not (math.isfinite(self.wall_damping) and self.wall_damping >= 0):
            raise InputError(f"the wall damping must be a finite number >= 0, got {self.wall_damping}",
                             "wall_damping")
        if self.wall_damping > MAX_WALL_DAMPING:
            raise InputError(f"the wall damping must be at most {MAX_WALL_DAMPING:g} (N s/m or N m s/rad), got "
                             f"{self.wall_damping:g}", "wall_damping")
        if self.hand is not None and not isinstance(self.hand, Hand):
            raise UserError(f"the hand must be a Hand, got {type(self.hand).__name__}")

    def order(self, joints: int = 1, motors: bool = False) -> int:
        """The order of the exact loop's one-sample map for ``joints`` free joints (:func:`handle_loops`): position
        and velocity of each coordinate (a joint's, and its motor's behind a compliant transmission when
        ``motors``) over the delay (one sample more for a differenced damper), the held torques with full
        compensation."""
        coordinates = 2 * joints if motors else joints
        differenced = self.velocity == "difference" and self.wall_damping > 0
        torques = joints * (self.delay + 1) if self.compensation == "full" else 0
        return 2 * coordinates * (self.delay + int(differenced) + 1) + torques

    def require_exact(self, joints: int, count: int, motors: bool = False) -> None:
        """Estimate the exact loops of ``count`` systems of ``joints`` free joints (with their motors' coordinates
        when ``motors``) before they are built: their order at most
        :data:`~hapticdesign.workload.EIGEN_ORDER_LIMIT` rows, their matrices within the memory limits (a delay of
        10^9 samples is refused here, not when its matrix is allocated)."""
        order = self.order(joints, motors)
        what = (f"the closed-loop matrices of {count:,} loop{'s' if count != 1 else ''} of order {order:,} (a delay "
                f"of {self.delay:,} samples)")
        require_within(what, order, EIGEN_ORDER_LIMIT, "rows")
        require_memory(what, 8.0 * order * order * count)

    @classmethod
    def seed(cls, **changes) -> "SampledLoop":
        """The seed's settings (seed 000 §4.1.1): full inverse-dynamics compensation, no delay, sampled velocity."""
        return cls(**{"delay": 0, "velocity": "sampled", "compensation": "full", **changes})

    @property
    def rate(self) -> float:
        return 1.0 / self.period

    @property
    def fraction(self) -> float:
        """The compensator's share ``c`` of the inertia it feeds forward: ``1 - E/100`` with full compensation, else
        0."""
        return 1.0 - self.error_percent / 100.0 if self.compensation == "full" else 0.0

    @property
    def gravity_share(self) -> float:
        """The share ``s`` of the gravity torque the compensator feeds forward: ``1 - E/100`` (its model's masses
        carry the modelling error, and gravity is linear in them) unless the compensation is none, 0 then."""
        return 0.0 if self.compensation == "none" else 1.0 - self.error_percent / 100.0

    def as_dict(self) -> dict:
        """The settings as an output states them."""
        return {"rate": self.rate, "period": self.period, "delay": self.delay, "velocity": self.velocity,
                "compensation": self.compensation, "error_percent": self.error_percent,
                "wall_damping": self.wall_damping, "hand": None if self.hand is None else self.hand.as_dict(),
                "held_joints": [j + 1 for j in self.held]}

    def describe(self) -> str:
        """One line for a text output."""
        hand = "no hand" if self.hand is None else self.hand.describe()
        held = f", joints {', '.join(str(j + 1) for j in self.held)} held" if self.held else ", every joint free"
        comp = self.compensation + (f" (model error {self.error_percent:g} %)" if self.compensation == "full"
                                    and self.error_percent else "")
        return (f"{self.rate:g} Hz, delay {self.delay} sample{'s' if self.delay != 1 else ''}, {self.velocity} "
                f"velocity, {comp} compensation, wall damper {self.wall_damping:g}, {hand}{held}")


def handle_loops(jacobian: np.ndarray, mass: np.ndarray, damping: np.ndarray, spring: np.ndarray,
                 loop: SampledLoop, poses: np.ndarray | None = None, gravity: np.ndarray | None = None,
                 model: tuple[np.ndarray, np.ndarray] | None = None,
                 transmission: Transmission | None = None) -> tuple[SpringLoops, np.ndarray]:
    """The sampled loops of S handles under a wall whose spring acts on the joints as ``K w w^T`` (``spring``: the
    rows ``w`` (S, n); ``J_v^T u`` for a Cartesian wall along a unit ``u``, ``e_j`` for a wall on joint j), every
    joint free but ``loop.held``, and a starting guess of their limits (S,).

    ``jacobian`` ``J_v`` (P, 3, n), ``mass`` ``H`` (P, n, n) and ``damping`` ``B`` (n, n) or (P, n, n) of the
    actuated coordinates at the P poses the walls hold, ``poses`` (S,) the pose of each loop (default: loop s at
    pose s, P = S), so that the plant of a pose walled along many directions is discretized once; ``gravity``
    ``K_G = dG/dq`` (n, n) or (P, n, n) at those poses (None: 0); ``model`` the compensator's own inertia ``H_m`` and
    gravity gradient ``K_Gm`` there (each (n, n) or (P, n, n): a device's are its model device's, whose modelling
    error need not scale ``H`` and ``G`` alike), None for the loop's uniform shares ``H_m = c H`` and ``K_Gm = s
    K_G`` (:attr:`SampledLoop.fraction`, :attr:`SampledLoop.gravity_share`); the compensation setting switches them
    (``none``: neither, ``gravity``: ``K_Gm`` only). The plant ``H_h qdd + B_h qd + (K_h + K_G) q =
    u`` (the hand's mass, damping and stiffness added as ``x J_v^T J_v``) is discretized exactly under a zero-order
    hold (:func:`held_plant`). With a ``transmission`` (:class:`~hapticdesign.model.actuators.Transmission`, each
    (n, n) or (P, n, n)) the motors sit behind springs: the plant's coordinates are the motors' ``phi`` and the
    links' ``q``, ``M_r phi'' + B_m phi' + K_t (phi - q) = u`` and ``(H_h - M_r) q'' + (B_h - B_m) q' + (K_h + K_G)
    q + K_t (q - phi) = 0`` (the rotors and the motors' damping on the motor side, the links, the hand and gravity on
    the other), and the controller senses ``phi`` (the encoders are on the motors); ``K_t`` is the drive's full
    symmetric stiffness, the transmissions' and the links' compliance in series
    (:mod:`hapticdesign.analysis.stiffness.drive`), and motors of no rotor inertia make a massless motor side
    (:func:`_massless_plant`: the encoders read ``q + K_t^-1 u``). Every period the controller
    holds, ``d`` samples late, ``u_k = H_m a_(k-d) + K_Gm q_(k-d) - K w w^T q_(k-d) - B_w w w^T v^_(k-d)``, ``q``,
    ``a`` the sensed position and the acceleration sampled under the previous torque, ``K_Gm q`` the linearized
    gravity compensation, ``v^`` the sampled velocity or the backward difference of positions. The state is ``[x_k,
    ..., x_(k-L), u_(k-1), ..., u_(k-d-1)]`` (``x`` the plant's coordinates and rates; the torques only with the
    compensator), and ``K`` enters as the rank-one term of :class:`SpringLoops`. The pose changes along the wall
    (``w^T q = 0``) that no static stiffness resists are fixed points (eigenvalue 1) whatever ``K``, a neutral
    drift of the handle along the wall, not an instability; they are deflated (:func:`_deflated`).
    """
    if any(not 0 <= j < jacobian.shape[-1] for j in loop.held):
        raise UserError(f"the held joints {[j + 1 for j in loop.held]} are not all joints of the device (1 to "
                        f"{jacobian.shape[-1]})")
    free = [j for j in range(jacobian.shape[-1]) if j not in set(loop.held)]
    if not free:
        raise UserError("every joint is held: nothing moves under the wall")
    jv = np.asarray(jacobian, dtype=float)[:, :, free]
    h = np.asarray(mass, dtype=float)[:, free][:, :, free]

    def joints(x) -> np.ndarray:  # the free joints' block of an (n, n) or (P, n, n) matrix, one per pose
        return np.broadcast_to(np.asarray(x, dtype=float)[..., free, :][..., free], h.shape)

    b = joints(damping)
    n = len(free)
    jtj = np.swapaxes(jv, 1, 2) @ jv
    hand = loop.hand or Hand()
    hh, bh, kp = h + hand.mass * jtj, b + hand.damping * jtj, hand.stiffness * jtj
    grad = np.zeros_like(kp) if gravity is None else joints(gravity)
    kp = kp + grad
    if model is None:  # held: the compensator's gravity gradient, on the sensed pose
        h_model, held = loop.fraction * h, loop.gravity_share * grad
    else:
        h_model, held = (joints(x) for x in model)
    if loop.compensation != "full":
        h_model = np.zeros_like(h)
    if loop.compensation == "none":
        held = np.zeros_like(h)
    plant, massless = ((hh, bh, kp), None) if transmission is None else _compliant_plant(
        hh, bh, kp, *(joints(x) for x in transmission), period=loop.period)
    phi, gamma = held_plant(*plant, loop.period, inputs=n) if massless is None else massless[:2]
    if poses is not None:  # each loop takes its pose's plant
        pick = np.asarray(poses, dtype=np.int64)
        phi, gamma, h_model, bh, held = (x[pick] for x in (phi, gamma, h_model, bh, held))
        plant = tuple(x[pick] for x in plant)
        massless = None if massless is None else tuple(x[pick] for x in massless)
    w = np.asarray(spring, dtype=float)[:, free]
    count, coords = len(w), plant[0].shape[-1]  # coords: n, or 2 n with the motors' own coordinates
    d = loop.delay
    differenced = loop.velocity == "difference" and loop.wall_damping > 0
    depth = d + int(differenced)
    compensated = bool(np.any(h_model))
    nx, size = 2 * coords, 2 * coords * (depth + 1) + (n * (d + 1) if compensated else 0)
    u0 = nx * (depth + 1)  # first column of the torque buffer
    at, rate = nx * d, nx * d + coords  # the sensed sample's positions and rates
    law = np.zeros((count, n, size))  # u_k from the state, spring left out
    ww = w[:, :, None] * w[:, None, :]
    if compensated and massless is not None:  # H_m a, a the links' acceleration (the motors' between torque steps)
        law[:, :, u0 + n * d:u0 + n * (d + 1)] += h_model @ massless[3]
        law[:, :, at:at + 2 * coords] += h_model @ massless[2]
    elif compensated:  # H_m a, a the sensed coordinates' rows of M^-1 (u_prev - D v - K q)
        feed = h_model @ np.linalg.inv(plant[0])[:, :n, :]
        law[:, :, u0 + n * d:u0 + n * (d + 1)] += feed[:, :, :n]
        law[:, :, at:at + coords] -= feed @ plant[2]
        law[:, :, rate:rate + coords] -= feed @ plant[1]
    law[:, :, at:at + n] += held
    if differenced:
        law[:, :, at:at + n] -= loop.wall_damping / loop.period * ww
        law[:, :, at + nx:at + nx + n] += loop.wall_damping / loop.period * ww
    else:
        law[:, :, rate:rate + n] -= loop.wall_damping * ww
    m = np.zeros((count, size, size))
    m[:, :nx, :nx] = phi
    m[:, :nx] += gamma @ law
    for k in range(1, depth + 1):
        m[:, nx * k:nx * (k + 1), nx * (k - 1):nx * k] = np.eye(nx)
    if compensated:
        m[:, u0:u0 + n] = law
        for k in range(1, d + 1):
            m[:, u0 + n * k:u0 + n * (k + 1), u0 + n * (k - 1):u0 + n * k] = np.eye(n)
    g = np.zeros((count, size))
    g[:, :nx] = np.einsum("sij,sj->si", gamma, w)
    if compensated:
        g[:, u0:u0 + n] = w
    hvec = np.zeros((count, size))
    hvec[:, at:at + n] = w
    if n > 1:
        net = plant[2].copy()
        net[:, :n, :n] -= held
        net *= loop.period ** 2 / np.linalg.norm(plant[0], axis=(1, 2))[:, None, None]
        if massless is not None:  # in compliance form (K may be huge): phi - q = C K_Gm phi, K_p q = K_Gm phi
            scale = loop.period ** 2 / np.linalg.norm(plant[0], axis=(1, 2))[:, None, None]
            eye = np.broadcast_to(np.eye(n), held.shape)
            net = np.concatenate([np.concatenate([eye - massless[4] @ held, -eye], axis=2),
                                  np.concatenate([-held, massless[5]], axis=2) * scale], axis=1)
        m, g, hvec, law = _deflated(m, g, hvec, law, w, net, held, depth, u0 if compensated else None)
    reach = np.einsum("sn,sn->s", w, w)
    viscous = np.einsum("sn,snm,sm->s", w, bh, w) / np.maximum(reach, 1e-300) ** 2 + loop.wall_damping
    guess = np.maximum(2.0 * viscous / (loop.period * (1 + 2 * d)), FLOOR)
    return SpringLoops(m, g, hvec, law, w), guess


def _compliant_plant(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray, rotor: np.ndarray,
                     motor_damping: np.ndarray, spring: np.ndarray,
                     period: float) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], tuple | None]:
    """The plant of :func:`handle_loops` with a compliant drive over ``(phi, q)`` (P, 2n, 2n each): the rotors
    ``M_r`` and the motors' damping ``B_m`` moved from the rigid ``H_h`` and ``B_h`` to the motor side, the drive's
    ``K`` (a full symmetric matrix: the transmissions' and the links' compliance in series,
    :mod:`hapticdesign.analysis.stiffness.drive`) between the sides, and None; a one-line error when the link side
    keeps no positive definite inertia (a link of no mass but the rotor's), or when a motor resonates on its drive
    more than :data:`RESONANCE_LIMIT` radians per period (the exact discretization loses its precision there, and
    the rigid model, which the compliant one tends to, is the answer). Motors with no rotor inertia and no damping
    of their own make a massless motor side (:func:`_massless_plant`), the second item then."""
    if not np.any(rotor):
        if np.any(motor_damping):
            raise UserError("a motor with damping of its own needs a rotor inertia behind a compliant drive (the "
                            "transmission's or the links'): give rotor_inertia, or the damping on the joint")
        return _massless_plant(mass, damping, stiffness, spring, period)
    link = mass - rotor
    if not np.all(np.linalg.eigvalsh(link)[..., 0] > 0) or not np.all(np.linalg.eigvalsh(rotor)[..., 0] > 0):
        raise UserError("a compliant transmission needs a rotor inertia on every motor and a link side of positive "
                        "definite inertia (H minus the rotors' n^2 J_r)")
    with np.errstate(over="ignore", invalid="ignore"):
        ratio = np.linalg.solve(rotor, spring)
    fastest = float(np.sqrt(np.max(np.linalg.eigvals(ratio).real))) if np.all(np.isfinite(ratio)) else math.inf
    if not fastest * period <= RESONANCE_LIMIT:
        raise UserError(f"the motors resonate on their transmissions at {fastest / (2 * math.pi):.3g} Hz, more than "
                        f"{RESONANCE_LIMIT / (2 * math.pi):.3g} times the loop's rate: the transmission is rigid for "
                        "this loop (leave out transmission_stiffness)")
    zero = np.zeros_like(mass)
    return (np.block([[rotor, zero], [zero, link]]), np.block([[motor_damping, zero], [zero, damping - motor_damping]]),
            np.block([[spring, -spring], [-spring, spring + stiffness]])), None


def _massless_plant(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray, spring: np.ndarray,
                    period: float) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], tuple]:
    """A drive ``K`` whose motor side has no inertia and no damping: the spring passes the held torque ``u`` to the
    links unchanged, ``H_h q'' + B_h q' + K_h q = u``, and stretches by ``C u`` (``C = K^-1``), so an encoder
    sampled at instant k reads ``phi_k = q_k + C u_(k-1)`` and the motors turn at ``phi' = q'`` between torque steps.
    Over the state ``(phi, q, phi', q')`` of the compliant plant the held map is the links' exact one
    (:func:`held_plant`), each of ``phi``, ``phi'`` following its link's row, and ``C`` added to ``phi``'s input
    (the motors' own columns are zero: eigenvalues 0). Returns the static plant ``(0 (+) H_h, 0 (+) B_h,
    [[K, -K], [-K, K + K_h]])`` (the fixed points' stiffness and the inertia's scale) and ``(Phi, Gamma, A_x, A_u,
    C, K_h)``: the held map, the links' acceleration ``A_x x + A_u u_prev`` (the compensator's sampled one) and what
    :func:`_deflated` needs in compliance form."""
    n = mass.shape[-1]
    phi_links, gamma_links = held_plant(mass, damping, stiffness, period)
    phi, gamma = np.zeros((len(mass), 4 * n, 4 * n)), np.zeros((len(mass), 4 * n, n))
    columns = np.r_[n:2 * n, 3 * n:4 * n]  # q and q'
    for block, rows in enumerate((slice(0, n), slice(0, n), slice(n, 2 * n), slice(n, 2 * n))):
        phi[:, block * n:(block + 1) * n, columns] = phi_links[:, rows]
        gamma[:, block * n:(block + 1) * n] = gamma_links[:, rows]
    compliance = np.linalg.inv(spring)
    gamma[:, :n] += compliance
    inverse = np.linalg.inv(mass)
    zero = np.zeros_like(mass)
    accel = -np.concatenate([zero, inverse @ stiffness, zero, inverse @ damping], axis=2)
    return ((np.block([[zero, zero], [zero, mass]]), np.block([[zero, zero], [zero, damping]]),
             np.block([[spring, -spring], [-spring, spring + stiffness]])),
            (phi, gamma, accel, inverse, compliance, stiffness))


RESONANCE_LIMIT = 1e4
"""The most radians a motor turns on its transmission's spring per sample period (``sqrt(K_t / M_r) T``) that the
compliant plant takes: the rigid limit is reached long before (1e-4 relative at ``1e7`` N m/rad on the Phantom's
joint, ``sqrt(K_t / M_r) T`` about 230)."""


def held_plant(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray,
               period: float, inputs: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The plants ``H qdd + B qd + K q = S u`` ((P, N, N) each) over ``period`` under a held ``u``, exactly: ``Phi``
    (P, 2N, 2N) and ``Gamma`` (P, 2N, m) of ``x = (q, qd)``, ``x+ = Phi x + Gamma u`` (``scipy.linalg.expm`` of the
    augmented matrix), the torques ``u`` acting on the first ``inputs`` = m coordinates (``S`` their columns of the
    identity; None: every coordinate)."""
    n = mass.shape[-1]
    m = n if inputs is None else inputs
    aug = np.zeros((len(mass), 2 * n + m, 2 * n + m))
    aug[:, :n, n:2 * n] = np.eye(n)
    aug[:, n:2 * n, :n] = -np.linalg.solve(mass, stiffness)
    aug[:, n:2 * n, n:2 * n] = -np.linalg.solve(mass, damping)
    aug[:, n:2 * n, 2 * n:] = np.linalg.inv(mass)[:, :, :m]
    e = expm(aug * period)
    return e[:, :2 * n, :2 * n], e[:, :2 * n, 2 * n:]


def _deflated(m: np.ndarray, g: np.ndarray, h: np.ndarray, law: np.ndarray, w: np.ndarray, net: np.ndarray,
              held: np.ndarray, depth: int,
              u0: int | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The maps with their spring-independent fixed points removed: a pose change ``q*`` of the plant's N
    coordinates (the first n sensed) along the wall (``w^T q*_sensed = 0``) that no static stiffness resists
    (``(K - S K_Gm S^T) q* = 0``, ``K`` the plant's stiffness with the hand's and gravity's, ``S`` the sensed
    coordinates; ``net`` that stiffness times ``T^2 / |M|``, the share of the inertia's scale it reaches over a
    period) is held still whatever ``K`` (the state ``[q*, 0, q*, 0, ..., 0]``, the torque buffer ``K_Gm q*_sensed``;
    ``held`` ``K_Gm``): eigenvalue 1, a neutral drift of the handle along the wall, not an instability. In an
    orthonormal basis ``[Q1 Q2]`` with ``Q1`` spanning them the map is block triangular, so the other eigenvalues
    are those of ``Q2^T m Q2`` (and the spring's term stays rank one, ``(Q2^T g)(Q2^T h)^T``); when the loops have
    different numbers of them, ``(I - P) m (I - P)`` with ``P`` the orthogonal projector on them has the same
    eigenvalues and zeros, at one size for all. The torque law is taken into the same coordinates."""
    count, size = m.shape[0], m.shape[1]
    n, coords = w.shape[1], net.shape[-1]
    wall = np.zeros((count, 1, coords))
    wall[:, 0, :n] = w / np.linalg.norm(w, axis=1, keepdims=True)
    rows = np.concatenate([wall, net], axis=1)
    _, sv, vt = np.linalg.svd(rows)
    free = sv <= NULL_TOL  # the last rows of vt (singular values descending)
    ranks = free.sum(axis=1)
    uniform = bool(np.all(ranks == ranks[0]))
    null = vt[:, coords - ranks[0]:, :] if uniform else vt * free[:, :, None]  # rows spanning the fixed pose changes
    r = null.shape[1]
    if r == 0:
        return m, g, h, law
    fixed = np.zeros((count, size, r))
    for k in range(depth + 1):
        fixed[:, 2 * coords * k:2 * coords * k + coords] = np.swapaxes(null, 1, 2)
    if u0 is not None:
        torque = held @ np.swapaxes(null[:, :, :n], 1, 2)
        for k in range((size - u0) // n):
            fixed[:, u0 + n * k:u0 + n * (k + 1)] = torque
    if uniform:
        q = np.linalg.qr(fixed, mode="complete")[0][:, :, r:]
        qt = np.swapaxes(q, 1, 2)
        return qt @ m @ q, np.einsum("sji,sj->si", q, g), np.einsum("sji,sj->si", q, h), law @ q
    keep = np.eye(size) - fixed @ np.linalg.pinv(fixed)
    return keep @ m @ keep, np.einsum("sij,sj->si", keep, g), np.einsum("sij,sj->si", keep, h), law @ keep


NULL_TOL = 1e-9
"""A pose change along the wall is free when the static stiffness resists it by less than this (singular values of
the wall's unit row stacked on the stiffness in units of ``|H_h| / T^2``): a balanced device's rounding-level
gravity gradient leaves the drift free."""


def handle_intervals(jacobian: np.ndarray, mass: np.ndarray, damping: np.ndarray, spring: np.ndarray,
                     loop: SampledLoop, groups: np.ndarray | None = None, k_max: float = 1e9,
                     poses: np.ndarray | None = None, gravity: np.ndarray | None = None,
                     model: tuple[np.ndarray, np.ndarray] | None = None,
                     transmission: Transmission | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The exact stable wall stiffnesses ``[low, high]`` (N/m) of each handle loop of :func:`handle_loops` (S,
    each), or of each group (:func:`loop_intervals`; ``low`` 0 unless gravity pulls the handle off the wall)."""
    loop.require_exact(np.shape(jacobian)[-1] - len(loop.held), len(spring), transmission is not None)
    loops, guess = handle_loops(jacobian, mass, damping, spring, loop, poses, gravity, model, transmission)
    return loop_intervals(loops, guess, groups, k_max)


def handle_limits(jacobian: np.ndarray, mass: np.ndarray, damping: np.ndarray, spring: np.ndarray,
                  loop: SampledLoop, groups: np.ndarray | None = None, k_max: float = 1e9,
                  poses: np.ndarray | None = None, gravity: np.ndarray | None = None,
                  model: tuple[np.ndarray, np.ndarray] | None = None,
                  transmission: Transmission | None = None) -> np.ndarray:
    """The upper ends of :func:`handle_intervals`: the exact stable wall stiffness (N/m) of each handle loop (S,),
    or the smallest in each group."""
    return handle_intervals(jacobian, mass, damping, spring, loop, groups, k_max, poses, gravity, model,
                            transmission)[1]


def _joint(inertia, damping, model_inertia=None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                                           tuple[np.ndarray, np.ndarray] | None]:
    """The handle arrays of S one-joint plants (``J_v`` the unit x axis, ``H = J``, ``B = b``, the wall's row 1) and
    the compensator's model (its inertia ``model_inertia``, no gravity; None: the loop's share of ``J``)."""
    j, b = np.broadcast_arrays(np.asarray(inertia, dtype=float), np.asarray(damping, dtype=float))
    j, b = j.ravel(), b.ravel()
    if not np.all((j > 0) & np.isfinite(j)):
        raise UserError(f"the inertia must be positive, got {_worst(j)}")
    if not np.all((b >= 0) & np.isfinite(b)):
        raise UserError(f"the damping must be non-negative, got {_worst(b)}")
    model = None
    if model_inertia is not None:
        m = np.broadcast_to(np.asarray(model_inertia, dtype=float), j.shape)
        if not np.all((m >= 0) & np.isfinite(m)):
            raise UserError(f"the compensator's inertia must be non-negative, got {_worst(m)}")
        model = (m[:, None, None], np.zeros((len(j), 1, 1)))
    axis = np.broadcast_to(np.array([[1.0], [0.0], [0.0]]), (len(j), 3, 1))
    return axis, j[:, None, None], b[:, None, None], np.ones((len(j), 1)), model


def joint_loops(inertia, damping, loop: SampledLoop, model_inertia=None) -> SpringLoops:
    """The sampled loops of 1-DOF plants, a joint of inertia ``J`` (kg m^2, or kg) and damping ``b`` (N m s/rad, or
    N s/m) each (numbers or S values) under the wall on it and the settings ``loop`` (a hand adds its mass, damping
    and stiffness to the joint's), the full compensator feeding ``model_inertia`` times the acceleration (default
    ``c J``): the one-joint case of :func:`handle_loops`."""
    axis, h, b, w, model = _joint(inertia, damping, model_inertia)
    loop.require_exact(1, len(w))
    return handle_loops(axis, h, b, w, loop, model=model)[0]


def joint_limits(inertia, damping, loop: SampledLoop, groups: np.ndarray | None = None,
                 k_max: float = 1e9, model_inertia=None) -> np.ndarray:
    """The exact limits (S,) of the loops of :func:`joint_loops`, or the smallest in each group
    (:func:`handle_limits`)."""
    axis, h, b, w, model = _joint(inertia, damping, model_inertia)
    return handle_limits(axis, h, b, w, loop, groups, k_max, model=model)


def joint_limit(inertia: float, damping: float, loop: SampledLoop, k_max: float = 1e9,
                model_inertia: float | None = None) -> float:
    """:func:`joint_limits` of one joint."""
    return float(joint_limits(inertia, damping, loop, k_max=k_max, model_inertia=model_inertia)[0])


def _worst(values: np.ndarray) -> float:
    """The value a refusal names: the first non-finite value, else the smallest."""
    bad = values[~np.isfinite(values)]
    return float(bad[0] if bad.size else values.min())
