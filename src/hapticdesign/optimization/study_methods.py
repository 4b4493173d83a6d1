"""The study's optimization methods: one record per method (:data:`METHODS`, by the ``algorithm.method`` of a study
file) carrying its settings (its record of the study file, a pydantic model of
:mod:`~hapticdesign.optimization.study_file`), its pymoo algorithm (:class:`~.pymoo_run.PymooAlgorithm`) and its
:meth:`~PopulationSearch.run` (pymoo's style: the study is the Problem, the method the Algorithm, the
:class:`~hapticdesign.optimization.study_run.StudyRun` the Result that keeps them).

- ``nsga2``, ``nsga3``, ``pso``: a population search of pymoo, each generation checkpointed, then the front polished
  as ``algorithm.polish`` asks (:mod:`.study_polish`).
- ``convex``: seed 000's LN minimization over inertial parameters as one exact convex program (:mod:`.study_convex`).

What a method does differently (how it runs, how its report and its empty front read, whether it keeps a checkpoint
or evaluates designs on a cluster) is asked of its record here, nowhere by its name.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.optimization.pymoo_run import NSGA_II, NSGA_III, PARTICLE_SWARM, PymooAlgorithm
from hapticdesign.optimization.study_convex import ln_of, run_convex
from hapticdesign.optimization.study_evaluation import BoundStudy, StudyEvaluator, points_reached
from hapticdesign.optimization.study_file import Convex, Nsga2, Nsga3, Pso, StudySpec, method_name
from hapticdesign.optimization.study_polish import polish
from hapticdesign.optimization.study_run import Answer, Encoding, Evaluator, StudyRun, record_of, run_study

Progress = Callable[[int, int], None]

CLOSEST_CANDIDATES = 12
"""Designs of the last generation tried point by point when no design reaches the workspace."""
POLISHED = {"ends": "each objective's best front design", "all": "every front design"}
"""What a polishing setting refines, in words (the report)."""


@dataclass(frozen=True)
class PopulationSearch:
    """A pymoo population search over the study's variables: its ``settings`` (the study file's record), pymoo's
    ``algorithm`` and the ``title`` that names it in the report."""

    settings: type[Nsga2 | Nsga3 | Pso]
    algorithm: PymooAlgorithm
    title: str

    checkpointed = True
    """A run keeps each generation in the output folder's checkpoint, and a rerun continues."""
    evaluates_designs = True
    """Its designs go to an evaluator in batches (here, or on a Dask cluster)."""

    @property
    def name(self) -> str:
        return method_name(self.settings)

    def run(self, bound: BoundStudy, seed: int, evaluate: Evaluator | None = None, out: Path | None = None,
            progress: Progress | None = None) -> StudyRun:
        """The search seeded ``seed`` (:func:`~hapticdesign.optimization.study_run.run_study`), its front polished;
        ``evaluate`` answers batches of designs (:class:`~.study_evaluation.StudyEvaluator` in this process by
        default), ``out`` keeps the checkpoint, ``progress(generation, generations)``."""
        if not self.algorithm.genetic and Encoding.of(bound.study.spec).discrete:
            genetic = ", ".join(m.name for m in METHODS.values() if m.algorithm is not None and m.algorithm.genetic)
            raise UserError(f"variables that are discrete choices need a genetic method ({genetic}), not {self.name}")
        here = StudyEvaluator(bound)
        evaluate = evaluate or here
        run = run_study(bound.study, seed, evaluate, out, progress, here.constraints, algorithm=self.algorithm)
        return polish(run, bound.study, evaluate, out)

    def evaluate_baseline(self, bound: BoundStudy, values: dict[str, float]) -> Answer:
        """The answer for the device file's design of variable ``values``: the bound study's, as every design's, with
        its objectives even when it breaks a constraint."""
        return StudyEvaluator(bound).answers([values], every_objective=True)[0]

    def describe(self, run: StudyRun) -> str:
        """The run in words (the report)."""
        spec, settings = run.spec, run.spec.algorithm
        if spec.workspace is None:
            where = "No workspace: every index is a closed form of the device's parameters. "
        else:
            box = spec.workspace.box
            where = (f"Workspace: box centred at {list(box.center)} m, edges {list(box.size)} m, {spec.workspace.grid} "
                     "points per axis of nonzero size. ")
        polished = [n for n, k in enumerate(run.front, start=1) if run.records[k].polished]
        if settings.polish == "none":
            polishing = (" Not polished (polish: none): the front is the search's alone, whose ends may stop short of "
                         "the optima (the default, polish: ends, refines them).")
        else:
            default = ", the default" if "polish" not in settings.model_fields_set else ""
            polishing = (f" Polished (polish: {settings.polish}{default}: {POLISHED[settings.polish]} refined by "
                         "SLSQP under the constraints): "
                         + (f"front designs {', '.join(map(str, polished))}" if polished else "no design improved")
                         + f"; the local search evaluated {run.probes} more designs, not listed in evaluations.csv.")
        return (f"{where}{self.title}, population {settings.population}, {settings.generations} generations, seed "
                f"{run.seed}: {len(run.records)} designs evaluated, {sum(r.feasible for r in run.records)} "
                f"feasible.{polishing}")

    def empty_front(self, run: StudyRun, bound: BoundStudy) -> UserError:
        """Why the front is empty, with the closest design: the most workspace points reached (each from home),
        or the least constraint violation."""
        valid = [r for r in run.records if not r.invalid]
        if not valid:
            last = [r for r in run.records if r.generation == run.records[-1].generation][:CLOSEST_CANDIDATES]
            counts = [points_reached(bound, r.values) for r in last]
            best = int(np.argmax(counts))
            shown = ", ".join(f"{k} = {v:.6g}" for k, v in last[best].values.items())
            return UserError(f"no design of {run.evaluations} reaches the whole workspace; the closest ({shown}) "
                             f"reaches {counts[best]} of {len(bound.points)} points ({last[best].invalid})")
        feasible = [r for r in valid if r.feasible]
        if feasible:
            return _kept_none(run, feasible)
        closest = min(valid, key=lambda r: r.violation)
        shown = ", ".join(f"{k} = {v:.6g}" for k, v in closest.values.items())
        return UserError(f"no design of {run.evaluations} meets the constraints; the closest ({shown}) has "
                         f"{closest.violated}")


def _kept_none(run: StudyRun, feasible: list) -> UserError:
    """Why the front is empty when designs meet the constraints: the ``keep`` filters remove them all; the design
    closest to passing them (least scaled excess) and the filter it fails."""
    spec = run.spec

    def misses(record) -> tuple[float, str]:
        full = spec.with_parameters(record.values)
        total, first = 0.0, ""
        for keep in spec.keep:
            v = float(keep.formula.value(full))
            for excess, bound, word in keep.beyond(v):
                excess = excess if math.isfinite(v) else math.inf
                if excess > 0.0:
                    total += excess
                    first = first or keep.missed(keep.formula.text, v, bound, word)
        return total, first

    closest = min(feasible, key=lambda r: misses(r)[0])
    shown = ", ".join(f"{k} = {v:.6g}" for k, v in closest.values.items())
    return UserError(f"{len(feasible)} of {run.evaluations} designs meet the constraints, but the keep filters remove "
                     f"every one; the closest ({shown}) has {misses(closest)[1]}")


@dataclass(frozen=True)
class ConvexProgram:
    """Seed 000's LN minimization as one exact convex program (:mod:`.study_convex`): one design, no generations."""

    settings: type[Convex] = Convex
    algorithm: None = None
    """No pymoo algorithm: the program is solved at once."""
    checkpointed = False
    evaluates_designs = False

    @property
    def name(self) -> str:
        return method_name(self.settings)

    def run(self, bound: BoundStudy, seed: int, evaluate: Evaluator | None = None, out: Path | None = None,
            progress: Progress | None = None) -> StudyRun:
        """The program's design (``seed`` kept for the record; ``evaluate``, ``out`` and ``progress`` unused: the
        program is solved here at once)."""
        return run_convex(bound, seed)

    def evaluate_baseline(self, bound: BoundStudy, values: dict[str, float]) -> Answer:
        """The LN of the device file's design of variable ``values``, as the program's design is evaluated."""
        return ln_of(bound, values)

    def describe(self, run: StudyRun) -> str:
        return (f"Method convex: LN minimized exactly over the inertial parameters as one convex program (seed 000 eq. "
                f"3.1-3.4), every body {run.spec.algorithm.realizability} realizable; the relaxation's lower bound on "
                f"the minimum is {run.notes['lower_bound']:.6g}.")

    def empty_front(self, run: StudyRun, bound: BoundStudy) -> UserError:
        return UserError(f"{bound.study.path}: the convex program's design is infeasible: {run.records[0].reason}")


METHODS = {method.name: method for method in (PopulationSearch(Nsga2, NSGA_II, "NSGA-II"),
                                               PopulationSearch(Nsga3, NSGA_III, "NSGA-III"),
                                               PopulationSearch(Pso, PARTICLE_SWARM, "Particle swarm"),
                                               ConvexProgram())}
"""The study file's methods by name, each its settings, pymoo algorithm and run."""


def with_baseline(run: StudyRun, bound: BoundStudy) -> StudyRun:
    """``run`` with the device file's own design (:meth:`~.study_evaluation.BoundStudy.baseline`) evaluated by the
    study's method as every design is (through the bound study's registry, or the convex program's LN), its
    objectives even when it breaks a constraint (generation 0, kept apart from the records and the front); without
    one, the note says why. What the device file's fields decide for every design comes with it: which compliance
    between the motors and the handle ``kmax`` takes (:meth:`~.study_evaluation.BoundStudy.compliance`)."""
    values, note = bound.baseline()
    if values is None:
        return replace(run, baseline_note=note, compliance=bound.compliance())
    answer = method_of(run.spec).evaluate_baseline(bound, values)
    record = record_of(run.spec, 0, Encoding.of(run.spec).encode(values), values, answer)
    return replace(run, baseline=record, baseline_note=note, compliance=bound.compliance())


def method_of(spec: StudySpec) -> PopulationSearch | ConvexProgram:
    """The method object of the study's ``algorithm``."""
    return METHODS[spec.algorithm.method]
