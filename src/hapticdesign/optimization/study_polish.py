"""Polishing a study's front: each end (or every front design) refined by a local search under the constraints.

A population search stops near the optima, not on them: the best design it finds for an objective is as good as
the designs it happened to draw. After the search, ``algorithm.polish`` refines front designs by SciPy's SLSQP
(:func:`~hapticdesign.optimization.local_search.minimize_in_boxes`) over the continuous variables, the discrete
choices held at the design's values, within the box holding every run's bounds, under the study's constraints
(scaled ``g <= 0``, a design without values counting as violating each):

- ``ends``: each objective's best front design minimizes that objective alone (a maximized one negated), so the
  front's ends reach the objectives' (local) optima;
- ``all``: every front design minimizes the sum of the objectives, each scaled by its range over the front,
  without letting any objective get worse than the design's own, so the polished design dominates it.

Variables are scaled to the unit box. Derivatives are forward differences of step :data:`STEP` (of each variable's
range), the neighbours of a design evaluated in one batch by the study's evaluator (a loop or a Dask cluster).
The search stops after :data:`BATCHES` batches; the best admissible design it evaluated is the
polished one. SLSQP is deterministic, so the same front asks for the same batches: each batch is checkpointed as
``checkpoint/polish-generation-NNNN.json`` like a generation, and a rerun replays them. A polished design is kept
(a record marked ``polished``) only when it is feasible and better: a smaller objective for an end, dominating the
design for ``all``; the front is then chosen again among the same records and the kept polished designs.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from hapticdesign.optimization.local_search import Gradients, minimize_in_boxes
from hapticdesign.optimization.study_run import (CHECKPOINT, Checkpoint, Encoding, Evaluator, Record, StudyRun,
                                                 constraint_columns, front_of, minimized, record_of, violations)
from hapticdesign.optimization.study_file import Choice, Study, StudySpec

STEP = 1e-6
"""Forward-difference step, as a fraction of each continuous variable's range."""

ITERATIONS = 100
"""Most SLSQP iterations per polished design."""

BATCHES = 100
"""Most batches of designs the evaluator is asked for per polished design: SLSQP on a reduction that is not smooth
(the least isotropy over the workspace points) may take many short line-search steps; the search then stops, and the
best design it evaluated stands."""


def most_designs(spec: StudySpec) -> int:
    """At most how many designs the polishing evaluates: :data:`BATCHES` batches of at most one design and its
    neighbours per polished design (each objective's end, or at most a population of front designs for ``all``)."""
    if spec.algorithm.polish == "none":
        return 0
    continuous = sum(not isinstance(v, Choice) for v in spec.variables.values())
    designs = len(spec.objectives) if spec.algorithm.polish == "ends" else spec.algorithm.population
    return designs * BATCHES * (continuous + 1)


class _Spent(Exception):
    """The local search used its batches."""


class _Designs:
    """The study's designs at given design vectors, evaluated in checkpointed batches and kept (each asked once)."""

    def __init__(self, study: Study, evaluate: Evaluator, checkpoint: Checkpoint, encoding: Encoding):
        self.spec = study.spec
        self.evaluate = evaluate
        self.checkpoint = checkpoint
        self.encoding = encoding
        self.known: dict[tuple[float, ...], Record] = {}
        self.batches = 0

    def __call__(self, X: np.ndarray) -> list[Record]:
        """The records of the rows of ``X``; the rows not yet known are evaluated as one batch."""
        keys = [tuple(float(v) for v in x) for x in X]
        new = np.array([k for k in dict.fromkeys(keys) if k not in self.known], dtype=float)
        if len(new):
            self.batches += 1
            values = [self.encoding.decode(x) for x in new]
            answers = self.checkpoint.load(self.batches, new)
            if answers is None:
                answers = self.evaluate(values)
                self.checkpoint.save(self.batches, new, answers)
            for x, v, a in zip(new, values, answers):
                self.known[tuple(float(c) for c in x)] = record_of(self.spec, 0, x, v, a)
        return [self.known[k] for k in keys]


class _Target:
    """One local search: from the front design ``start``, minimize ``weights @ minimized objectives`` (scaled), with
    the objectives kept at most the start's when ``bounded``; ``u`` are the continuous variables in the unit box."""

    def __init__(self, designs: _Designs, start: Record, weights: np.ndarray, bounded: bool,
                 lower: np.ndarray, upper: np.ndarray, columns: list[int]):
        self.designs, self.start, self.weights, self.bounded = designs, start, weights, bounded
        self.lower, self.span, self.columns = lower, upper - lower, columns
        self.spec = designs.spec
        self.m0 = minimized(self.spec, start)
        self.f0 = float(weights @ self.m0)
        self.n_g = constraint_columns(self.spec)
        self.first_batch = designs.batches
        self.best: Record | None = None

    def _evaluated(self, X: np.ndarray) -> list[Record]:
        """The records of ``X`` (see :class:`_Designs`), the best feasible one kept; :class:`_Spent` past
        :data:`BATCHES`."""
        if self.designs.batches - self.first_batch >= BATCHES:
            raise _Spent
        records = self.designs(X)
        for r in records:
            if self.admissible(r) and (self.best is None or self.value(r) < self.value(self.best)):
                self.best = r
        return records

    def admissible(self, record: Record) -> bool:
        """Feasible, and no objective worse than the start's when bounded."""
        return record.feasible and bool(np.all(self.g(record) <= 0.0))

    def x(self, u: np.ndarray) -> np.ndarray:
        x = np.array(self.start.x, dtype=float)
        x[self.columns] = self.lower + np.clip(u, 0.0, 1.0) * self.span
        return x

    def _rows(self, u: np.ndarray) -> np.ndarray:
        """The design at ``u`` and its forward neighbours (a backward one at the upper bound)."""
        steps = np.where(u + STEP <= 1.0, STEP, -STEP)
        return np.vstack([u, u + np.diag(steps)]), steps

    def value(self, record: Record) -> float:
        """The scaled objective; a design without values keeps the start's (it is refused by the constraints)."""
        return self.f0 if record.invalid else float(self.weights @ minimized(self.spec, record))

    def g(self, record: Record) -> np.ndarray:
        """Scaled ``g <= 0``: the study's constraints (all 1 for a design without values), then the objectives
        against the start's when bounded."""
        if record.invalid:
            g = np.ones(self.n_g)
        else:
            g = violations(self.spec, record.constraints)[0]
        if not self.bounded:
            return g
        scale = np.where(self.weights > 0, self.weights, 1.0)
        worse = 1.0 if record.invalid else (minimized(self.spec, record) - self.m0) * scale
        return np.concatenate([g, np.broadcast_to(worse, self.m0.shape)])

    def record(self, u: np.ndarray) -> Record:
        return self._evaluated(self.x(u)[None])[0]

    def gradients(self) -> Gradients:
        def both(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            rows, steps = self._rows(np.asarray(u, dtype=float))
            records = self._evaluated(np.array([self.x(r) for r in rows]))
            f = np.array([self.value(r) for r in records])
            g = np.array([self.g(r) for r in records])
            return (f[1:] - f[0]) / steps, ((g[1:] - g[0]) / steps[:, None]).T

        return Gradients(lambda u: both(u)[0], lambda u: both(u)[1])

    def search(self) -> Record | None:
        """The polished design: the best admissible design the local search evaluated, when it is better than the
        start (dominating it when bounded)."""
        u0 = (np.array(self.start.x)[self.columns] - self.lower) / self.span
        try:
            minimize_in_boxes([(np.zeros(len(u0)), np.ones(len(u0)))], lambda u: self.value(self.record(u)),
                              lambda u: self.g(self.record(u)), 0, 0, lambda u: self.admissible(self.record(u)),
                              u0[None], self.gradients(), ITERATIONS)
        except _Spent:
            pass
        if self.best is None:
            return None
        m, m0 = minimized(self.spec, self.best), self.m0
        better = np.all(m <= m0) and np.any(m < m0) if self.bounded else float(self.weights @ m) < self.f0
        return self.best if better else None


def _targets(run: StudyRun) -> list[tuple[int, np.ndarray, bool]]:
    """The front designs to polish: (record, weights of the minimized objectives, bounded) per search."""
    spec = run.spec
    F = np.array([minimized(spec, run.records[k]) for k in run.front])
    if spec.algorithm.polish == "ends":
        out = []
        for j in range(F.shape[1]):
            weights = np.zeros(F.shape[1])
            size = abs(F[:, j]).max()
            weights[j] = 1.0 / size if size > 0.0 else 1.0
            out.append((run.front[int(np.argmin(F[:, j]))], weights, False))
        return out
    span = np.ptp(F, axis=0)
    size = np.where(span > 0.0, span, abs(F).max(axis=0))
    weights = 1.0 / np.where(size > 0.0, size, 1.0)
    return [(k, weights, True) for k in run.front]


def polish(run: StudyRun, study: Study, evaluate: Evaluator, out: Path | None = None) -> StudyRun:
    """``run`` with its front polished as ``algorithm.polish`` asks (see the module); ``out`` keeps the checkpoint."""
    spec = run.spec
    encodings = [Encoding.of(spec, bounds) for bounds in (spec.algorithm.runs or [{}])]
    columns = [k for k in range(len(encodings[0].names)) if k not in encodings[0].discrete]
    if spec.algorithm.polish == "none" or not run.front or not columns:
        return run
    lower = np.min([e.xl[columns] for e in encodings], axis=0)
    upper = np.max([e.xu[columns] for e in encodings], axis=0)
    folder = None if out is None else Path(out) / CHECKPOINT
    designs = _Designs(study, evaluate, Checkpoint(folder, study, run.seed, "polish-"), encodings[0])
    generation = max(r.generation for r in run.records) + 1
    kept: list[Record] = []
    for k, weights, bounded in _targets(run):
        found = _Target(designs, run.records[k], weights, bounded, lower, upper, columns).search()
        if found is not None and found.x not in {r.x for r in kept}:
            kept.append(replace(found, generation=generation, polished=True))
    records = run.records + kept
    added = list(range(len(run.records), len(records)))
    among = None if run.among is None else run.among + added
    return replace(run, records=records, front=front_of(spec, records, among), among=among,
                   probes=run.probes + len(designs.known) - len(kept))
