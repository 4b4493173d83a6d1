"""Local constrained minimization by SciPy's SLSQP from several starts, over the union of boxes.

One generic search serves every local refinement of the package: the shortest R-CUBE design
(:mod:`.rcube.shortest`), a study's ``algorithm.start`` and the polishing of a study's front (:mod:`.study_polish`).
``objective(x)`` is minimized under ``constraints(x) <= 0`` (a vector) within box bounds; the answer is kept
only when it is ``feasible``. Gradients are SciPy's finite differences unless the caller gives them (a study's
polishing evaluates a design and its neighbours in one batch).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from hapticdesign.errors import UserError

FEASIBILITY_MARGIN = 1e-10
"""The local solver keeps ``g <= -margin`` so that its answer meets ``g <= 0`` exactly (constraint units)."""

SAME_POINT = 1e-6
"""Starts whose answers differ from the best by less than this (objective units) found the same minimum."""

Function = Callable[[np.ndarray], float]
Constraints = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Gradients:
    """The caller's derivatives: ``objective(x) -> (n,)`` and ``constraints(x) -> (m, n)``."""

    objective: Callable[[np.ndarray], np.ndarray]
    constraints: Callable[[np.ndarray], np.ndarray]


def _hull(boxes: Sequence[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """The smallest box holding every box ``(lower, upper)``."""
    return (np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0))


def _local_minimum(x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, objective: Function,
                   constraints: Constraints, feasible: Callable[[np.ndarray], bool] | None,
                   gradients: Gradients | None, iterations: int) -> np.ndarray | None:
    """SLSQP from ``x0``; the answer if it is ``feasible`` (by default: meets ``g(x) <= 0``), else None."""
    constraint = {"type": "ineq", "fun": lambda x: -constraints(x) - FEASIBILITY_MARGIN}
    options = {}
    if gradients is not None:
        constraint["jac"] = lambda x: -gradients.constraints(x)
        options["jac"] = gradients.objective
    result = minimize(objective, x0, method="SLSQP", constraints=[constraint], bounds=list(zip(lower, upper)),
                      options={"ftol": 1e-14, "maxiter": iterations}, **options)
    x = np.clip(result.x, lower, upper)
    ok = feasible(x) if feasible is not None else bool(np.all(constraints(x) <= 0.0))
    return x if ok else None


def _minimize_in_box(lower: np.ndarray, upper: np.ndarray, starts: int, seed: int, objective: Function,
                     constraints: Constraints, feasible, initial: np.ndarray, gradients: Gradients | None,
                     iterations: int) -> tuple[np.ndarray, int] | None:
    """Best feasible local minimum from the ``initial`` rows and ``starts`` uniform starts drawn with ``seed``,
    and how many starts reached it."""
    rng = np.random.default_rng(seed)
    rows = np.vstack([initial, rng.uniform(lower, upper, (starts, len(lower)))])
    found = [x for x in (_local_minimum(x0, lower, upper, objective, constraints, feasible, gradients, iterations)
                         for x0 in rows) if x is not None]
    if not found:
        return None
    values = np.array([objective(x) for x in found])
    best = int(np.argmin(values))
    return found[best], int(np.sum(values - values[best] < SAME_POINT))


def held_by(x: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
    """Whether ``x`` lies within the box ``lower``, ``upper``."""
    return bool(np.all(lower <= x) and np.all(x <= upper))


def minimize_in_boxes(boxes: Sequence[tuple[np.ndarray, np.ndarray]], objective: Function, constraints: Constraints,
                      starts: int, seed: int, feasible: Callable[[np.ndarray], bool] | None = None,
                      initial: np.ndarray | None = None, gradients: Gradients | None = None,
                      iterations: int = 500) -> tuple[np.ndarray, int] | None:
    """The least ``objective(x)`` under ``constraints(x) <= 0`` over the union of ``boxes`` (``(lower, upper)``
    pairs) by SLSQP (at most ``iterations`` each) from the ``initial`` rows and ``starts`` uniform starts drawn
    with ``seed``, and how many starts reached it; None when no start reaches a ``feasible`` design (by default:
    one that meets the constraints). ``gradients``: the derivatives (SciPy's finite differences without them).

    The box holding every box is searched first; if its minimum lies outside every box (only possible for
    boxes that are not nested), each box is searched on its own.
    """
    boxes = [(np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)) for lo, hi in boxes]
    initial = np.zeros((0, len(boxes[0][0]))) if initial is None else np.atleast_2d(np.asarray(initial, dtype=float))
    if starts < 0 or starts + len(initial) < 1:
        raise UserError(f"the constrained minimization needs at least one start, got {starts}")
    found = _minimize_in_box(*_hull(boxes), starts, seed, objective, constraints, feasible, initial, gradients,
                             iterations)
    if found is None and len(boxes) == 1:
        return None

    def held(x) -> bool:
        return any(held_by(x, lo, hi) for lo, hi in boxes)

    if found is None or not held(found[0]):
        per_box = [_minimize_in_box(lo, hi, starts, seed, objective, constraints, feasible,
                                    initial[[held_by(x, lo, hi) for x in initial]].reshape(-1, len(lo)),
                                    gradients, iterations) for lo, hi in boxes]
        per_box = [p for p in per_box if p is not None]
        if not per_box:
            return None
        found = min(per_box, key=lambda p: objective(p[0]))
    return found
