"""Sets of designs at prescribed LN levels (seed 000 §3.2.2, eq. 3.35-3.39, Table 3.3).

The seed minimizes LN subject to ``LN >= LN_desired`` (eq. 3.39) with differential evolution, so
every design it keeps has LN equal to its level. Two methods:

- ``fast`` (default) exploits the structure: LN is a quadratic form in the standard parameters
  and both realizability conditions and the box bounds are convex in the seed's variables
  (mass, mass centre, inertia about the mass centre). Level 0: fully linear realizable designs
  from the convex program of :mod:`.linear_designs`. Level L > 0: a random realizable design in
  the box (principal moments meeting the triangle inequality, products zero as in the seed's
  Appendix C), pushed to larger LN by moving masses and mass centres uphill if needed; on the
  segment from a level-0 design to it every point is realizable and within bounds, LN runs
  continuously from 0 past L, and a root-finder (Brent) puts LN in ``[L, L (1 + 1e-6)]``.
- ``de``: the seed's method, SciPy's differential evolution (rand/1/bin, scale factor 1,
  crossover 0.5, population 50) on the 7 variables ``m, r, Ixx, Iyy, Izz`` of every bounded link
  (products zero, as in Appendix C), minimizing ``LN`` with a penalty for ``LN < L`` and for
  unrealizable links. It stops at DE's tolerance, so its result is then finished with the same
  exact level step (level 0: orthogonal projection onto the linear subspace, checked).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np
from scipy.optimize import brentq, differential_evolution, minimize

from hapticdesign.analysis.linearity.bounds import BodyBounds, within_bounds
from hapticdesign.analysis.linearity.conditions import LinearConditions
from hapticdesign.analysis.linearity.quadratic import LinearityForm
from hapticdesign.analysis.linearity.linear_designs import find_linear_designs, realizable
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.model.inertia import Realizability, seed_from_standard, standard_from_seed

DEFAULT_LEVELS = (0.0, 0.001, 0.01, 0.1, 1.0, 2.0)
LEVEL_TOLERANCE = 1e-6
ZERO_TOLERANCE = 1e-12
SEED_VARIABLES = (0, 1, 2, 3, 4, 5, 6)  # m, rx, ry, rz, Ixx, Iyy, Izz of each bounded link


class Method(str, Enum):
    FAST = "fast"
    DE = "de"


@dataclass(frozen=True)
class DESettings:
    """Differential evolution settings; the defaults are the seed's (population 50, §3.2.2)."""

    population: int = 50
    generations: int = 300

    def __post_init__(self) -> None:
        if self.population < 5 or self.generations < 1:
            raise UserError("differential evolution needs a population of at least 5 and at least 1 generation")


@dataclass(frozen=True)
class DesignSet:
    levels: np.ndarray  # (S,)
    parts: np.ndarray  # (S, 3)
    designs: np.ndarray  # (S, bodies * 10) in the seed's variables

    @property
    def ln(self) -> np.ndarray:
        return self.parts.sum(axis=1)

    def to_csv(self, names: list[str]) -> str:
        header = ["level", "ln", "ln_H", "ln_C", "ln_G", *names]
        lines = [",".join(header)]
        for level, parts, design in zip(self.levels, self.parts, self.designs):
            values = [level, parts.sum(), *parts, *design]
            lines.append(",".join(repr(float(v)) for v in values))
        return "\n".join(lines) + "\n"


class _Sampler:
    """Random realizable designs in the box, with products of inertia zero."""

    def __init__(self, device: Device, bounds: dict[str, BodyBounds], form: LinearityForm):
        self.device, self.bounds, self.form = device, bounds, form
        self.base = device.seed_parameters()
        self.bodies = [k for k, b in enumerate(device.body_names) if b in bounds]

    def ln(self, flat: np.ndarray) -> float:
        return float(self.form.ln_seed(flat))

    def random(self, rng: np.random.Generator) -> np.ndarray:
        x = self.base.copy()
        for k in self.bodies:
            b = self.bounds[self.device.body_names[k]]
            x[k, 0] = rng.uniform(*b.mass)
            x[k, 1:4] = rng.uniform(*b.centre, 3)
            while True:
                moments = rng.uniform(*b.moments, 3)
                if 2 * moments.max() <= moments.sum():
                    break
            x[k, 4:7] = moments
            x[k, 7:10] = 0.0
        return x.ravel()

    def push_up(self, x: np.ndarray, level: float) -> np.ndarray:
        """Move masses and mass centres uphill in LN (box-bounded) until LN reaches the level."""
        index = [10 * k + j for k in self.bodies for j in range(4)]
        box = []
        for k in self.bodies:
            b = self.bounds[self.device.body_names[k]]
            box += [b.mass] + [b.centre] * 3

        def negative(v: np.ndarray) -> float:
            y = x.copy()
            y[index] = v
            return -self.ln(y)

        def reached(v: np.ndarray) -> None:
            if -negative(v) >= 1.05 * level:
                raise StopIteration

        v = x[index].copy()
        try:
            v = minimize(negative, v, method="L-BFGS-B", bounds=box, callback=reached).x
        except StopIteration:
            pass
        y = x.copy()
        y[index] = v
        return y


def _hit_level(sampler: _Sampler, start: np.ndarray, end: np.ndarray, level: float) -> np.ndarray:
    """The point on the segment start -> end (LN(start) = 0 <= level < LN(end)) with LN at the level."""
    target = level * (1 + 1e-3 * LEVEL_TOLERANCE)

    def gap(t: float) -> float:
        return sampler.ln(start + t * (end - start)) - target

    t = brentq(gap, 0.0, 1.0, xtol=1e-16, rtol=4 * np.finfo(float).eps, maxiter=200)
    return start + t * (end - start)


def _on_level(ln: float, level: float) -> bool:
    if level == 0:
        return ln < ZERO_TOLERANCE
    return level <= ln <= level * (1 + LEVEL_TOLERANCE)


def _de_design(
    sampler: _Sampler, level: float, rng: np.random.Generator, kind: Realizability, settings: DESettings
) -> np.ndarray:
    """The seed's differential evolution (rand/1/bin, F = 1, CR = 0.5, population 50 by default)."""
    names = sampler.device.body_names
    box = []
    for k in sampler.bodies:
        b = sampler.bounds[names[k]]
        box += [b.mass, b.centre, b.centre, b.centre, b.moments, b.moments, b.moments]
    index = [10 * k + j for k in sampler.bodies for j in SEED_VARIABLES]
    base = sampler.random(rng)

    def design(v: np.ndarray) -> np.ndarray:
        x = base.copy()
        x[index] = v
        return x

    def objective(v: np.ndarray) -> float:
        ln = sampler.ln(design(v))
        moments = v.reshape(-1, 7)[:, 4:7]
        broken = np.maximum(moments.max(axis=1) * 2 - moments.sum(axis=1), 0).sum() if kind is Realizability.RIGID_BODY else 0.0
        return ln + 1e3 * max(level - ln, 0.0) + 1e3 * broken

    lo, hi = np.array(box).T
    init = lo + (hi - lo) * rng.random((settings.population, len(box)))
    result = differential_evolution(
        objective, box, strategy="rand1bin", mutation=1.0, recombination=0.5, init=init,
        maxiter=settings.generations, tol=1e-10, polish=False, rng=rng,
    )
    return design(result.x)


def design_set(
    device: Device,
    form: LinearityForm,
    conditions: LinearConditions,
    bounds: dict[str, BodyBounds],
    levels: tuple[float, ...] = DEFAULT_LEVELS,
    count: int = 100,
    seed: int = 1,
    method: Method = Method.FAST,
    kind: Realizability = Realizability.RIGID_BODY,
    de: DESettings = DESettings(),
) -> DesignSet:
    """``count`` designs at each LN level, every one realizable, within bounds and on its level."""
    if count < 1:
        raise UserError("the number of designs per level must be at least 1")
    if any(level < 0 or not np.isfinite(level) for level in levels):
        raise UserError("LN levels must be finite and non-negative")
    rng = np.random.default_rng(seed)
    sampler = _Sampler(device, bounds, form)
    zero = find_linear_designs(device, form, conditions, bounds, count, int(rng.integers(2**32)), kind)
    bodies = device.body_names
    rows_level, rows_design = [], []
    for level in levels:
        for i in range(count):
            x = _design(sampler, conditions, zero[i], level, rng, method, kind, de)
            rows_level.append(level)
            rows_design.append(x)
    designs = np.array(rows_design)
    parts = form.parts_seed(designs)
    for x, p, level in zip(designs, parts, rows_level):
        seed_values = x.reshape(len(bodies), 10)
        if not (_on_level(p.sum(), level) and within_bounds(seed_values, bodies, bounds)):
            raise RuntimeError(f"design set check failed at level {level:g} (LN {p.sum():.17g})")
    return DesignSet(np.array(rows_level), parts, designs)


def _design(sampler, conditions, linear, level, rng, method, kind, de) -> np.ndarray:
    bodies = sampler.device.body_names
    for _ in range(50):
        if method is Method.DE:
            candidate = _de_design(sampler, level, rng, kind, de)
            if level == 0:
                standard = conditions.project(standard_from_seed(candidate.reshape(-1, 10)).ravel())
                candidate = seed_from_standard(standard.reshape(-1, 10)).ravel()
            elif not _on_level(sampler.ln(candidate), level) and sampler.ln(candidate) > level:
                candidate = _hit_level(sampler, linear, candidate, level)
        elif level == 0:
            return linear
        else:
            end = sampler.random(rng)
            if sampler.ln(end) <= level:
                end = sampler.push_up(end, level)
            if sampler.ln(end) <= level:
                continue
            candidate = _hit_level(sampler, linear, end, level)
        seed_values = candidate.reshape(len(bodies), 10)
        standard = standard_from_seed(seed_values)
        if (
            _on_level(sampler.ln(candidate), level)
            and within_bounds(seed_values, bodies, sampler.bounds)
            and realizable(seed_values, standard, kind)
        ):
            return candidate
    raise UserError(f"no realizable design reaches LN = {level:g} within the bounds")
