"""Running a study: NSGA-II over the study's variables, each generation checkpointed (docs/optimization.md).

The study's variables become pymoo's design vector: a continuous variable its value, a discrete one the
index of its choice (a whole number, :class:`~hapticdesign.optimization.pymoo_run.RoundColumns`). Each
generation's designs go to an evaluator in one batch (a loop here, or a Dask cluster, :mod:`.study_dask`),
which answers every reduced index the study reads, or why the design has none (a workspace point out of
reach, an invalid device). Objectives enter pymoo as minimized values (a maximized one negated);
constraints as ``g <= 0`` scaled by their bound, plus one column that is 1 for a design without values
(0 otherwise), so that NSGA-II's constrained domination (Deb et al. 2002) ranks it behind every valid
design.

Checkpoint: with an output folder, each generation's answers are written to
``checkpoint/generation-NNNN.json`` as they arrive. A rerun replays the same seeded algorithm and takes
each generation's answers from its file when the file holds exactly the designs asked for, so an
interrupted run continues where it stopped and ends with the same front as an uninterrupted run (the
algorithm between evaluations is deterministic for a seed). The front is the feasible, non-dominated set
of every design evaluated (an archive), not only of the last population.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pymoo.core.problem import Problem

from hapticdesign.errors import UserError
from hapticdesign.files import read_text, write_atomically
from hapticdesign.optimization.pymoo_run import AlgorithmSpec, pareto_filter, run
from hapticdesign.optimization.study_file import Choice, ExpressionConstraint, Study, StudySpec

CHECKPOINT = "checkpoint"
RUN_FILE = "run.json"


@dataclass(frozen=True)
class Answer:
    """The evaluator's answer for one design: every reduced index of :func:`reduced_keys` in order (NaN
    when the design has none) and ``reason``, empty for a valid design, else why it has no values."""

    reduced: tuple[float, ...]
    reason: str = ""


Evaluator = Callable[[list[dict[str, float]]], list[Answer]]
"""Answers for a batch of designs (variable name -> value), in order."""


def reduced_keys(spec: StudySpec) -> tuple[tuple, ...]:
    """The reduced indices the study reads (index, options, reduction): objectives first, then index
    constraints, each once."""
    return tuple(dict.fromkeys(use.key for use in spec.index_uses))


@dataclass(frozen=True)
class Encoding:
    """The study's variables as pymoo's design vector: bounds and the whole-number columns."""

    names: tuple[str, ...]
    choices: dict[str, tuple[float, ...]]
    xl: np.ndarray
    xu: np.ndarray

    @classmethod
    def of(cls, spec: StudySpec) -> "Encoding":
        low, high, choices = [], [], {}
        for name, variable in spec.variables.items():
            if isinstance(variable, Choice):
                choices[name] = variable.values
                low.append(-0.5)  # rounded to 0 ... n - 1, each choice sampled alike
                high.append(len(variable.values) - 0.5)
            else:
                low.append(variable[0])
                high.append(variable[1])
        return cls(tuple(spec.variables), choices, np.array(low), np.array(high))

    @property
    def discrete(self) -> tuple[int, ...]:
        return tuple(k for k, name in enumerate(self.names) if name in self.choices)

    def decode(self, x: Sequence[float]) -> dict[str, float]:
        """Variable values of one design vector (a choice's index becomes its value)."""
        out = {}
        for name, v in zip(self.names, x):
            out[name] = self.choices[name][int(round(v))] if name in self.choices else float(v)
        return out


@dataclass(frozen=True)
class Record:
    """One evaluated design: its generation (1 = the initial population), design vector, variable values,
    objectives (the study's sense and units), constrained values, why it has no values (``invalid``) or
    which constraint it breaks first (``violated``), both empty when it is feasible, and its total scaled
    constraint violation."""

    generation: int
    x: tuple[float, ...]
    values: dict[str, float]
    objectives: tuple[float, ...]
    constraints: tuple[float, ...]
    invalid: str
    violated: str
    violation: float

    @property
    def feasible(self) -> bool:
        return not self.invalid and not self.violated

    @property
    def reason(self) -> str:
        return self.invalid or self.violated


def _violations(spec: StudySpec, constraints: Sequence[float]) -> tuple[np.ndarray, str]:
    """Scaled ``g <= 0`` columns of the constraints and the first violated one in words."""
    g, first = [], ""
    for c, value in zip(spec.constraints, constraints):
        for bound, sign, word in ((c.at_most, 1.0, "<="), (c.at_least, -1.0, ">=")):
            if bound is None:
                continue
            scale = abs(bound) if bound != 0.0 else 1.0
            g.append(sign * (value - bound) / scale)
            if g[-1] > 0.0 and not first:
                first = f"{c.label} = {value:.6g}, not {word} {bound:g}"
    return np.array(g), first


def constraint_labels(spec: StudySpec) -> tuple[str, ...]:
    """Column names of the constrained values (``min_isotropy``, ``l1 + l2``)."""
    return tuple(c.label for c in spec.constraints)


def record_of(spec: StudySpec, generation: int, x, values: dict[str, float], answer: Answer) -> Record:
    """One design's record from its answer: objectives, constrained values and whether it is feasible."""
    keys = reduced_keys(spec)
    reduced = dict(zip(keys, answer.reduced))
    objectives = tuple(reduced[o.key] for o in spec.objectives)
    constraints = tuple(c.value(values) if isinstance(c, ExpressionConstraint) else reduced[c.key]
                        for c in spec.constraints)
    invalid = answer.reason
    if not invalid:
        bad = [label for label, v in zip([o.name for o in spec.objectives] + list(constraint_labels(spec)),
                                         objectives + constraints) if not np.isfinite(v)]
        invalid = f"{bad[0]} is not a finite number" if bad else ""
    g, violated = _violations(spec, constraints) if not invalid else (np.zeros(0), "")
    return Record(generation, tuple(float(v) for v in x), values, objectives, constraints, invalid, violated,
                  float(np.sum(np.maximum(g, 0.0))))


def minimized(spec: StudySpec, record: Record) -> np.ndarray:
    """The record's objectives as pymoo minimizes them (a maximized objective negated; 0 without values)."""
    if record.invalid:
        return np.zeros(len(spec.objectives))
    return np.array([-v if o.sense == "max" else v for o, v in zip(spec.objectives, record.objectives)])


def _g(spec: StudySpec, record: Record) -> np.ndarray:
    """pymoo's ``g <= 0`` row: the validity column, then the scaled constraints (0 for a design without values)."""
    if record.invalid:
        return np.concatenate([[1.0], np.zeros(len(_violations(spec, [0.0] * len(spec.constraints))[0]))])
    return np.concatenate([[0.0], _violations(spec, record.constraints)[0]])


class Checkpoint:
    """Each generation's answers in ``folder`` (see the module); None folder: nothing kept."""

    def __init__(self, folder: Path | None, study: Study, seed: int):
        self.folder = folder
        if folder is None:
            return
        header = {"study": study.fingerprint, "seed": seed}
        path = folder / RUN_FILE
        if path.exists():
            try:
                found = json.loads(read_text(path, "checkpoint"))
            except ValueError:
                found = None
            if found != header:
                raise UserError(f"{folder.parent} holds a run of another study or seed; choose another output folder "
                                "or empty this one")
        else:
            write_atomically(path, json.dumps(header))

    def _path(self, generation: int) -> Path:
        return self.folder / f"generation-{generation:04d}.json"

    def load(self, generation: int, X: np.ndarray) -> list[Answer] | None:
        """The answers kept for ``generation`` if its file holds exactly the designs ``X``."""
        if self.folder is None or not self._path(generation).exists():
            return None
        try:
            kept = json.loads(read_text(self._path(generation), "checkpoint"))
            same = np.array_equal(np.array(kept["X"], dtype=float).reshape(X.shape), X)
            answers = zip(kept["reduced"], kept["reasons"], strict=True)
            return [Answer(tuple(r), s) for r, s in answers] if same else None
        except (ValueError, KeyError, TypeError, UserError):
            return None

    def save(self, generation: int, X: np.ndarray, answers: list[Answer]) -> None:
        if self.folder is None:
            return
        kept = {"X": X.tolist(), "reduced": [list(a.reduced) for a in answers], "reasons": [a.reason for a in answers]}
        write_atomically(self._path(generation), json.dumps(kept))


class StudyProblem(Problem):
    """The study as pymoo's Problem: each call evaluates one generation in one batch and keeps its records."""

    def __init__(self, spec: StudySpec, evaluate: Evaluator, checkpoint: Checkpoint):
        self.spec = spec
        self.encoding = Encoding.of(spec)
        self.evaluate_batch = evaluate
        self.checkpoint = checkpoint
        self.records: list[Record] = []
        self.generation = 0
        n_g = 1 + len(_violations(spec, [0.0] * len(spec.constraints))[0])
        super().__init__(n_var=len(self.encoding.names), n_obj=len(spec.objectives), n_ieq_constr=n_g,
                         xl=self.encoding.xl, xu=self.encoding.xu)

    def _evaluate(self, X, out, *args, **kwargs):
        self.generation += 1
        X = np.asarray(X, dtype=float)
        values = [self.encoding.decode(x) for x in X]
        answers = self.checkpoint.load(self.generation, X)
        if answers is None:
            answers = self.evaluate_batch(values)
            self.checkpoint.save(self.generation, X, answers)
        records = [record_of(self.spec, self.generation, x, v, a) for x, v, a in zip(X, values, answers)]
        self.records += records
        out["F"] = np.array([minimized(self.spec, r) for r in records])
        out["G"] = np.array([_g(self.spec, r) for r in records])


@dataclass(frozen=True)
class StudyRun:
    """Every evaluated design (``records``, in evaluation order) and the front (indices into them, feasible
    and non-dominated over all evaluations, sorted by the first objective); method convex adds ``bound``, a
    lower bound on the minimized objective (:mod:`.study_convex`)."""

    spec: StudySpec
    seed: int
    records: list[Record]
    front: list[int]
    bound: float | None = None

    @property
    def evaluations(self) -> int:
        return len(self.records)


def front_of(spec: StudySpec, records: list[Record]) -> list[int]:
    """Feasible, non-dominated records (designs with equal objectives once), by their first objective."""
    ok = [k for k, r in enumerate(records) if r.feasible]
    if not ok:
        return []
    X = np.array([records[k].x for k in ok])
    F = np.array([minimized(spec, records[k]) for k in ok])
    kept, seen = [], set()
    for i in pareto_filter(X, F):  # designs with the same objectives: the first evaluated stands for them
        if tuple(F[i]) not in seen:
            seen.add(tuple(F[i]))
            kept.append(ok[i])
    return sorted(kept, key=lambda k: (minimized(spec, records[k])[0], k))


def run_study(study: Study, seed: int, evaluate: Evaluator, out: Path | None = None,
              progress: Callable[[int, int], None] | None = None) -> StudyRun:
    """Run ``study`` with ``seed``; ``evaluate`` answers batches of designs; ``out`` keeps the checkpoint
    (``out/checkpoint``); ``progress(generation, generations)`` after each generation."""
    if seed < 0:
        raise UserError(f"the seed must be at least 0, got {seed}")
    spec = study.spec
    checkpoint = Checkpoint(None if out is None else Path(out) / CHECKPOINT, study, seed)
    problem = StudyProblem(spec, evaluate, checkpoint)
    encoding = problem.encoding
    algorithm = AlgorithmSpec("nsga2", spec.algorithm.population, spec.algorithm.generations,
                              discrete=encoding.discrete)
    total = spec.algorithm.generations
    run(problem, algorithm, seed, (lambda generation: progress(generation, total)) if progress else None)
    return StudyRun(spec, seed, problem.records, front_of(spec, problem.records))
