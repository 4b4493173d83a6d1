"""Running a study: a population search over the study's variables, each generation checkpointed (docs/optimization.md).

The study's variables become pymoo's design vector: a continuous variable its value, a discrete one the
index of its choice (a whole number, :class:`~hapticdesign.optimization.pymoo_run.RoundColumns`). Each
generation's designs go to an evaluator in one batch (in this process or on a Dask cluster, :mod:`.study_evaluation`),
which answers every reduced index the study reads, or why the design has none (a workspace point out of
reach, an invalid device). Objectives enter pymoo as minimized values (a maximized one negated);
constraints as ``g <= 0`` scaled by their bound, plus one column that is 1 for a design without values
(0 otherwise), so that constrained domination (Deb et al. 2002; NSGA-II and NSGA-III) ranks it behind every valid
design.

Checkpoint: with an output folder, each generation's answers are written to
``checkpoint/generation-NNNN.json`` as they arrive. A rerun replays the same seeded algorithm and takes
each generation's answers from its file when the file passes verification (a checksum over its content, the study
and the seed) and holds exactly the designs asked for, so an
interrupted run continues where it stopped and ends with the same front as an uninterrupted run (the
algorithm between evaluations is deterministic for a seed). The front is the feasible, non-dominated set
of every design evaluated (an archive), not only of the last population.
"""

from __future__ import annotations

import hashlib
import json
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pymoo.core.problem import Problem

from hapticdesign.errors import RunWarning, UserError
from hapticdesign.files import output_folder, read_text, write_atomically
from hapticdesign.optimization.pymoo_run import AlgorithmSpec, PymooAlgorithm, initial_population, pareto_filter, run
from hapticdesign.optimization.local_search import minimize_in_boxes
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
    def of(cls, spec: StudySpec, bounds: dict | None = None) -> "Encoding":
        """The study's variables, with ``bounds`` (name -> (low, high)) in place of some continuous ones' (a run's)."""
        low, high, choices = [], [], {}
        for name, variable in {**spec.variables, **(bounds or {})}.items():
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

    def encode(self, values: dict[str, float]) -> tuple[float, ...]:
        """The design vector of variable ``values`` (a choice's value becomes its index, NaN for a value not among
        the choices)."""
        return tuple(float(self.choices[name].index(values[name]) if values[name] in self.choices[name] else math.nan)
                     if name in self.choices else float(values[name]) for name in self.names)

    def decode(self, x: Sequence[float]) -> dict[str, float]:
        """Variable values of one design vector (a choice's index becomes its value)."""
        out = {}
        for name, v in zip(self.names, x):
            out[name] = self.choices[name][int(round(v))] if name in self.choices else float(v)
        return out


@dataclass(frozen=True)
class Record:
    """One evaluated design: its generation (1 = the initial population, 0 = the device file's own design), design
    vector, variable values, objectives (the study's sense and units), constrained values, why it has no values
    (``invalid``) or which constraint it breaks first (``violated``), both empty when it is feasible, and its total
    scaled constraint violation."""

    generation: int
    x: tuple[float, ...]
    values: dict[str, float]
    objectives: tuple[float, ...]
    constraints: tuple[float, ...]
    invalid: str
    violated: str
    violation: float
    polished: bool = False
    """Whether the design is a front design refined by the local search (:mod:`.study_polish`)."""

    @property
    def feasible(self) -> bool:
        return not self.invalid and not self.violated

    @property
    def reason(self) -> str:
        return self.invalid or self.violated


def violations(spec: StudySpec, constraints: Sequence[float]) -> tuple[np.ndarray, str]:
    """Scaled ``g <= 0`` columns of the constraints (:meth:`~.study_file._Bounded.beyond`) and the first violated one
    in words."""
    g, first = [], ""
    for c, value in zip(spec.constraints, constraints):
        for excess, bound, word in c.beyond(value):
            g.append(excess)
            if excess > 0.0 and not first:
                first = c.missed(c.label, value, bound, word)
    return np.array(g), first


def constraint_columns(spec: StudySpec) -> int:
    """How many ``g <= 0`` columns the constraints give (one per bound)."""
    return sum(len(c.sides) for c in spec.constraints)


def constraint_labels(spec: StudySpec) -> tuple[str, ...]:
    """Column names of the constrained values (``min_isotropy``, ``l1 + l2``)."""
    return tuple(c.label for c in spec.constraints)


def constrained_values(spec: StudySpec, values: dict[str, float], reduced: dict[tuple, float]) -> tuple[float, ...]:
    """The constrained values of a design of variable ``values`` whose reduced indices are ``reduced`` (by key)."""
    return tuple(c.value(values) if isinstance(c, ExpressionConstraint) else reduced[c.key] for c in spec.constraints)


def feasibility(spec: StudySpec, constraints: Sequence[float]) -> tuple[str, str, float]:
    """The one judgement of constrained values: why they give no design (a value that is not a finite number), the
    first constraint they break in words (both empty: they meet every constraint) and the total scaled violation."""
    invalid = _not_finite(constraint_labels(spec), constraints)
    if invalid:
        return invalid, "", 0.0
    g, violated = violations(spec, constraints)
    return "", violated, float(np.sum(np.maximum(g, 0.0)))


def record_of(spec: StudySpec, generation: int, x, values: dict[str, float], answer: Answer) -> Record:
    """One design's record from its answer: objectives, constrained values and whether it is feasible
    (:func:`feasibility`)."""
    reduced = dict(zip(reduced_keys(spec), answer.reduced))
    objectives = tuple(reduced[o.key] for o in spec.objectives)
    constraints = constrained_values(spec, values, reduced)
    invalid, violated, violation = (answer.reason, "", 0.0) if answer.reason else feasibility(spec, constraints)
    if not invalid and not violated:  # a design that breaks a constraint may have no objectives (module docstring)
        invalid = _not_finite([o.name for o in spec.objectives], objectives)
    return Record(generation, tuple(float(v) for v in x), values, objectives, constraints, invalid, violated,
                  violation)


def _not_finite(labels: Sequence[str], values: Sequence[float]) -> str:
    bad = [label for label, v in zip(labels, values) if not np.isfinite(v)]
    return f"{bad[0]} is not a finite number" if bad else ""


def minimized(spec: StudySpec, record: Record) -> np.ndarray:
    """The record's objectives as pymoo minimizes them (a maximized objective negated; 0 without values, which
    NSGA-II's constrained domination never reads)."""
    if record.invalid or not np.all(np.isfinite(record.objectives)):
        return np.zeros(len(spec.objectives))
    return np.array([-v if o.sense == "max" else v for o, v in zip(spec.objectives, record.objectives)])


def _g(spec: StudySpec, record: Record) -> np.ndarray:
    """pymoo's ``g <= 0`` row: the validity column, then the scaled constraints (0 for a design without values)."""
    if record.invalid:
        return np.concatenate([[1.0], np.zeros(constraint_columns(spec))])
    return np.concatenate([[0.0], violations(spec, record.constraints)[0]])


class Checkpoint:
    """Each generation's answers in ``folder`` (see the module); None folder: nothing kept.

    Each file carries a SHA-256 checksum over its content, the study's fingerprint and the seed. A file that fails
    it (edited answers, a file of another run), that holds other designs than those asked for, or whose answers are
    not numbers and texts of the study's shape is not trusted: its generation is evaluated again, and a
    :class:`~hapticdesign.errors.RunWarning` says so. The checksum is not keyed (it catches damage, not forgery), so
    the values are checked as a study file's are: floats as this class writes them (not integers such as 10^400),
    designs of the study's width, answers within +-:data:`MAX_ANSWER` (or inf or NaN)."""

    def __init__(self, folder: Path | None, study: Study, seed: int, prefix: str = ""):
        self.folder = folder
        self.prefix = prefix
        self.key = f"{study.fingerprint}:{seed}"
        self.width = len(reduced_keys(study.spec))
        if folder is None:
            return
        output_folder(folder)
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
        return self.folder / f"{self.prefix}generation-{generation:04d}.json"

    def _checksum(self, X: list, reduced: list, reasons: list) -> str:
        return hashlib.sha256(json.dumps([self.key, X, reduced, reasons]).encode()).hexdigest()

    def load(self, generation: int, X: np.ndarray) -> list[Answer] | None:
        """The answers kept for ``generation`` if its file passes verification (see the class), else None."""
        if self.folder is None or not self._path(generation).exists():
            return None
        path = self._path(generation)
        try:
            kept = json.loads(read_text(path, "checkpoint"))
            problem = self._problem(kept, X)
        except (ValueError, UserError) as exc:
            problem = f"it is not a checkpoint ({str(exc)[:80]})"
        if problem is None:
            return [Answer(tuple(float(v) for v in r), s) for r, s in zip(kept["reduced"], kept["reasons"])]
        warnings.warn(f"checkpoint {path} is not trusted ({problem}); generation {generation} is evaluated again",
                      RunWarning, stacklevel=2)
        return None

    def _problem(self, kept: object, X: np.ndarray) -> str | None:
        """Why the parsed file ``kept`` cannot answer the designs ``X``, or None."""
        if not isinstance(kept, dict) or not {"X", "reduced", "reasons", "checksum"} <= kept.keys():
            return "it lacks the designs, answers or checksum"
        if kept["checksum"] != self._checksum(kept["X"], kept["reduced"], kept["reasons"]):
            return "its checksum does not match its content, the study and the seed"
        reduced, reasons, designs = kept["reduced"], kept["reasons"], kept["X"]
        if not (isinstance(reduced, list) and isinstance(reasons, list) and len(reduced) == len(reasons) == len(X)
                and all(isinstance(r, list) and len(r) == self.width and all(_number(v) for v in r) for r in reduced)
                and all(isinstance(s, str) for s in reasons)):
            return "its answers are not numbers and reasons of this study"
        if not all(_value(v) for r in reduced for v in r):
            return f"an answer is not a value an index gives (a number within +-{MAX_ANSWER:g}, inf or NaN)"
        if not (isinstance(designs, list) and len(designs) == len(X)
                and all(isinstance(x, list) and len(x) == X.shape[1] and all(_number(v) for v in x) for x in designs)):
            return "its designs are not numbers of this study"
        return None if np.array_equal(np.array(designs, dtype=float), X) else "it holds other designs"

    def save(self, generation: int, X: np.ndarray, answers: list[Answer]) -> None:
        if self.folder is None:
            return
        x, reasons = np.asarray(X, dtype=float).tolist(), [a.reason for a in answers]
        reduced = [[float(v) for v in a.reduced] for a in answers]
        kept = {"X": x, "reduced": reduced, "reasons": reasons, "checksum": self._checksum(x, reduced, reasons)}
        write_atomically(self._path(generation), json.dumps(kept))


MAX_ANSWER = 1e300
"""The largest finite index value a checkpoint may hold: none of the toolkit's indices comes near it, and one
beyond leaves no room for the sums and differences of the front and the polishing (a forged 1e308)."""


def _number(value: object) -> bool:
    """A number as :meth:`Checkpoint.save` writes it: a float (JSON writes every float with a point or an exponent,
    so an integer, 10^400 among them, was never written by it)."""
    return isinstance(value, float)


def _value(value: float) -> bool:
    """An index value: within +-:data:`MAX_ANSWER`, or inf or NaN (no value; the record says why)."""
    return not math.isfinite(value) or abs(value) <= MAX_ANSWER


class StudyProblem(Problem):
    """The study as pymoo's Problem: each call evaluates one generation in one batch and keeps its records."""

    def __init__(self, spec: StudySpec, evaluate: Evaluator, checkpoint: Checkpoint, bounds: dict | None = None):
        self.spec = spec
        self.encoding = Encoding.of(spec, bounds or {})
        self.evaluate_batch = evaluate
        self.checkpoint = checkpoint
        self.records: list[Record] = []
        self.generation = 0
        n_g = 1 + constraint_columns(spec)
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
    """Every evaluated design (``records``, in evaluation order, run after run) and the front (indices into them,
    feasible and non-dominated over all evaluations, or over the runs' final populations with ``front: final``,
    then filtered by ``keep``, sorted by the first objective); ``among``: the records the front was chosen among
    (None: every record); ``start``: the minimized start design's variables (None without ``algorithm.start`` or
    when no start met the constraints); ``notes``: the method's own results by name, as ``optimize --json`` prints
    them (method convex: ``lower_bound``, :mod:`.study_convex`); ``probes``: designs the polishing evaluated beside
    the polished ones it kept (:mod:`.study_polish`); ``baseline``: the device file's own design evaluated as every
    design is (None when the file does not fix every variable), outside ``records`` and the front;
    ``baseline_note``: why there is none, or what to know of it (:meth:`~.study_evaluation.BoundStudy.baseline`);
    ``compliance``: which compliance between the motors and the handle each index that includes it (``kmax``) took,
    by index name (:meth:`~.study_evaluation.BoundStudy.compliance`), which the outputs state."""

    spec: StudySpec
    seed: int
    records: list[Record]
    front: list[int]
    among: list[int] | None = None
    start: dict[str, float] | None = None
    notes: dict[str, float] = field(default_factory=dict)
    probes: int = 0
    baseline: Record | None = None
    baseline_note: str = ""
    compliance: dict[str, str] = field(default_factory=dict)

    @property
    def evaluations(self) -> int:
        """Every design evaluated: the records and the polishing's probes."""
        return len(self.records) + self.probes


def front_of(spec: StudySpec, records: list[Record], among: Sequence[int] | None = None) -> list[int]:
    """Feasible, non-dominated records (designs with equal objectives once) among ``among`` (all by default) that
    meet the study's ``keep`` filters, by their first objective."""
    ok = [k for k in (range(len(records)) if among is None else among) if records[k].feasible]
    if not ok:
        return []
    X = np.array([records[k].x for k in ok])
    F = np.array([minimized(spec, records[k]) for k in ok])
    kept, seen = [], set()
    for i in pareto_filter(X, F):  # designs with the same objectives: the first evaluated stands for them
        if tuple(F[i]) not in seen and kept_by(spec, records[ok[i]].values):
            seen.add(tuple(F[i]))
            kept.append(ok[i])
    return sorted(kept, key=lambda k: (minimized(spec, records[k])[0], k))


def kept_by(spec: StudySpec, values: dict[str, float]) -> bool:
    """Whether a design of variable ``values`` meets every ``keep`` filter of the study."""
    full = spec.with_parameters(values)
    return all(excess <= 0.0 for keep in spec.keep for excess, _, _ in keep.beyond(float(keep.formula.value(full))))


def start_design(study: Study, seed: int, evaluate: Evaluator, encodings: list[Encoding]) -> np.ndarray | None:
    """The design vector minimizing ``algorithm.start.minimize`` under the study's constraints (SLSQP from seeded
    starts over the box holding every run's bounds, :func:`~hapticdesign.optimization.local_search.minimize_in_boxes`),
    or None when no start meets them. ``evaluate`` answers the constraints (objectives need not be computed)."""
    spec = study.spec
    encoding = encodings[0]
    if encoding.discrete:
        raise UserError("algorithm.start needs continuous variables only")

    def minimized_value(x: np.ndarray) -> float:
        return float(spec.algorithm.start.minimize.value(spec.with_parameters(encoding.decode(x))))

    def constraints(x: np.ndarray) -> np.ndarray:
        values = encoding.decode(x)
        record = record_of(spec, 0, x, values, evaluate([values])[0])
        if record.invalid and not any(np.isfinite(record.constraints)):
            return np.ones(len(_g(spec, record)) - 1)
        return violations(spec, record.constraints)[0]

    found = minimize_in_boxes([(e.xl, e.xu) for e in encodings], minimized_value, constraints,
                              spec.algorithm.start.starts, seed)
    return None if found is None else found[0]


def run_study(study: Study, seed: int, evaluate: Evaluator, out: Path | None = None,
              progress: Callable[[int, int], None] | None = None,
              evaluate_constraints: Evaluator | None = None, *, algorithm: PymooAlgorithm) -> StudyRun:
    """Run ``study`` with ``seed`` by pymoo's ``algorithm`` (the study's method's,
    :data:`~hapticdesign.optimization.study_methods.METHODS`); ``evaluate`` answers batches of designs; ``out`` keeps
    the checkpoint (``out/checkpoint``); ``progress(generation, generations)`` after each generation;
    ``evaluate_constraints`` answers the constraints of ``algorithm.start``'s minimization (``evaluate`` by default).

    Each run ``k`` of ``algorithm.runs`` (one run without them) is the population search over its bounds seeded
    ``seed + k``; with ``algorithm.start``, the minimized design joins the first population of every run whose bounds
    hold it, the rest of that population drawn uniformly with the run's seed (pymoo's own seeded sampling
    otherwise)."""
    if seed < 0:
        raise UserError(f"the seed must be at least 0, got {seed}")
    spec = study.spec
    folder = None if out is None else Path(out) / CHECKPOINT
    bounds = spec.algorithm.runs or [{}]
    encodings = [Encoding.of(spec, b) for b in bounds]
    start = None
    if spec.algorithm.start is not None:
        start = start_design(study, seed, evaluate_constraints or evaluate, encodings)
    records, final = [], []
    total = spec.algorithm.generations * len(bounds)
    for k, (run_bounds, encoding) in enumerate(zip(bounds, encodings)):
        checkpoint = Checkpoint(folder, study, seed, f"run{k + 1}-" if len(bounds) > 1 else "")
        problem = StudyProblem(spec, evaluate, checkpoint, run_bounds)
        initial = None
        if start is not None and np.all(encoding.xl <= start) and np.all(start <= encoding.xu):
            initial = initial_population(encoding.xl, encoding.xu, spec.algorithm.population, seed + k, start[None])
        search = AlgorithmSpec(algorithm, spec.algorithm.population, spec.algorithm.generations, initial=initial,
                               discrete=encoding.discrete, **spec.algorithm.options)
        done = k * spec.algorithm.generations
        result = run(problem, search, seed + k,
                     (lambda generation, done=done: progress(done + generation, total)) if progress else None)
        last = {r.x: len(records) + i for i, r in enumerate(problem.records)}
        final += [last[tuple(float(v) for v in x)] for x in result.X]
        records += problem.records
    among = final if spec.algorithm.front == "final" else None
    return StudyRun(spec, seed, records, front_of(spec, records, among), among,
                    start=None if start is None else encodings[0].decode(start))
