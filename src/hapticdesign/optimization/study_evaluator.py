"""The answers for a batch of a bound study's designs (:mod:`.study_evaluation`), here or on a Dask cluster.

A design is the device at its values; the registry evaluates the pose indices of a batch together (through the
compiled kernels where it can, :func:`~hapticdesign.analysis.metrics.indices.evaluate_designs`), each reduced as the
study asks; the parameter indices are evaluated for the whole batch at once. A design the device file refuses, or one
that misses a workspace point, has no values and says why.

Batches go through one hook, pymoo's element-wise runner
(:func:`~hapticdesign.optimization.pymoo_run.elementwise_runner`): in this process a batch is one piece of work; with
the Dask client of ``optimize --scheduler`` it is cut into contiguous chunks, a few per worker, each sent with the
study itself (its text and its device file's text, so a worker needs no file of the caller's machine); each worker
binds the study once (kept per study fingerprint) and answers its chunks. The answers are gathered in the designs'
order, so a run on a cluster gives the same numbers as a run here.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np

from hapticdesign.analysis.metrics.indices import Evaluation, Request, evaluate_designs, evaluate_parameters, reduce
from hapticdesign.analysis.workspace import reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.optimization.pymoo_run import elementwise_runner
from hapticdesign.optimization.study_evaluation import BoundStudy, bind_study
from hapticdesign.optimization.study_file import IndexConstraint, Study
from hapticdesign.optimization.study_run import Answer, constrained_values, feasibility

CHUNKS_PER_WORKER = 4
"""Chunks of a batch per Dask worker."""

KMAX_UNREAD = ("coulomb", "torque_continuous", "torque_peak")
"""The motor fields (``actuators.<joint>.<field>``) the ``kmax`` index does not read: its loop is linear in the
handle's J_v, H and B."""


class StudyEvaluator:
    """The study's :data:`~hapticdesign.optimization.study_run.Evaluator`: called on a batch of designs (variable name
    -> value), it answers them in order through pymoo's element-wise runner, a loop here or the workers of the Dask
    ``client`` (see the module)."""

    def __init__(self, bound: BoundStudy, client=None):
        self.bound = bound
        self.client = client
        self.runner = elementwise_runner(client)
        self.work = self.answers if client is None else partial(evaluate_chunk, bound.study)
        """What answers one chunk: this process's bound study, or a worker's binding of the study."""

    def __call__(self, batch: list[dict[str, float]]) -> list[Answer]:
        return [answer for answers in self.runner(self.work, self._chunks(batch)) for answer in answers]

    def _chunks(self, batch: list[dict[str, float]]) -> list[list[dict[str, float]]]:
        """The whole batch in this process; contiguous chunks, :data:`CHUNKS_PER_WORKER` per worker, on a cluster."""
        if self.client is None:
            return [batch]
        workers = max(1, len(self.client.scheduler_info().get("workers", {})))
        size = max(1, math.ceil(len(batch) / (CHUNKS_PER_WORKER * workers)))
        return [batch[k:k + size] for k in range(0, len(batch), size)]

    def constraints(self, batch: list[dict[str, float]]) -> list[Answer]:
        """:meth:`answers` in this process without the indices that only the objectives read."""
        return self.answers(batch, objectives=False)

    def answers(self, batch: list[dict[str, float]], objectives: bool = True,
                every_objective: bool = False) -> list[Answer]:
        """Answers for a batch of designs, in order (see the module). The parameter indices only the objectives read
        are evaluated only for the designs that meet every constraint (:func:`~.study_run.feasibility`; NSGA-II's
        constrained domination never reads the objectives of the others), and for none without ``objectives`` (for
        every valid design with ``every_objective``: the device file's design, whose objectives are compared even when
        it breaks a constraint)."""
        bound = self.bound
        device_values = [bound.device_values(v) for v in batch]
        if bound.requests:
            results = evaluate_designs(bound.space, device_values, bound.points, bound.requests, bound.registry)
        else:
            results = [self._checked(v) for v in device_values]
        valid = [k for k, r in enumerate(results) if r.reason is None]
        values = {k: dict(results[k].values) for k in valid}
        first = [r for r in bound.parameter_requests if r.key in bound.constrained]
        failed = self._parameter_values(first, [device_values[k] for k in valid], valid, values)
        valid = [k for k in valid if k not in failed]
        if objectives:
            feasible = [k for k in valid if every_objective or self._feasible(batch[k], values[k])]
            later = [r for r in bound.parameter_requests if r.key not in bound.constrained]
            failed |= self._parameter_values(later, [device_values[k] for k in feasible], feasible, values)
        nothing = (math.nan,) * len(bound.keys)
        out = []
        for k, result in enumerate(results):
            reason = result.reason if result.reason is not None else failed.get(k)
            out.append(Answer(nothing, reason) if reason is not None else Answer(self._reduced(values[k])))
        return out

    def _reduced(self, got: dict[str, np.ndarray]) -> tuple[float, ...]:
        """Each reduced index of the study (:attr:`BoundStudy.keys`) from the values per point of its requests (NaN for
        a request not evaluated)."""
        bound = self.bound
        return tuple(reduce(got[label], key[2], bound.center) if (label := bound.labels[key[:2]]) in got else math.nan
                     for key in bound.keys)

    def _feasible(self, variables: dict[str, float], got: dict[str, np.ndarray]) -> bool:
        """Whether a design whose constrained requests are evaluated meets every constraint."""
        spec = self.bound.study.spec
        reduced = dict(zip(self.bound.keys, self._reduced(got)))
        invalid, violated, _ = feasibility(spec, constrained_values(spec, variables, reduced))
        return not invalid and not violated

    def _checked(self, device_values: dict[str, float]) -> Evaluation:
        """A design of a study of parameter indices alone, whose device is not built: its device values must pass the
        design space's check (finite numbers; a formula may give inf or NaN), or it has none, and says why."""
        try:
            self.bound.space.checked_values(device_values)
        except UserError as exc:
            return Evaluation({}, str(exc))
        return Evaluation({})

    def _parameter_values(self, requests: list[Request], designs: list[dict[str, float]], rows: list[int],
                          values: dict[int, dict[str, np.ndarray]]) -> dict[int, str]:
        """The parameter indices ``requests`` of ``designs`` (device values), written to ``values[rows[i]]``; a design
        whose index cannot be computed (a pose its links do not reach, a length its formulas make negative) has
        none: the rows of such designs -> why (each design then evaluated alone, the others keep their values)."""
        if not requests or not designs:
            return {}
        try:
            self._parameter_columns(requests, designs, rows, values)
            return {}
        except UserError:
            pass
        failed = {}
        for design, k in zip(designs, rows):
            try:
                self._parameter_columns(requests, [design], [k], values)
            except UserError as exc:
                failed[k] = str(exc)
        return failed

    def _parameter_columns(self, requests: list[Request], designs: list[dict[str, float]], rows: list[int],
                           values: dict[int, dict[str, np.ndarray]]) -> None:
        base = self.bound.space.base.params
        params = {name: np.array([float(d.get(name, base[name])) for d in designs]) for name in base}
        for key, column in evaluate_parameters(params, requests, self.bound.registry).items():
            for i, k in enumerate(rows):
                values[k][key] = column[i:i + 1]


_BOUND: dict[str, BoundStudy] = {}


def evaluate_chunk(study: Study, chunk: list[dict[str, float]]) -> list[Answer]:
    """Answers for ``chunk`` on a worker (the study bound once per worker process)."""
    bound = _BOUND.get(study.fingerprint)
    if bound is None:
        bound = _BOUND[study.fingerprint] = bind_study(study)
    return StudyEvaluator(bound).answers(chunk)


def points_reached(bound: BoundStudy, values: dict[str, float]) -> int:
    """How many workspace points the design reaches, each from home on its own (the closest design of a study whose
    workspace no design reaches)."""
    try:
        device = bound.space.device(bound.device_values(values))
    except UserError:
        return 0
    count = 0
    for point in bound.points:
        try:
            reach_workspace(device, point[None, :])
            count += 1
        except UserError:
            pass
    return count


def _unread_by_kmax(name: str) -> bool:
    return name.startswith("actuators.") and name.rsplit(".", 1)[-1] in KMAX_UNREAD


def unmeetable_walls(bound: BoundStudy) -> list[str]:
    """The ``kmax`` constraints that no design of the study can meet, in words, known before the run where that is
    rigorous: ``kmax`` is the sampled wall's exact limit from the handle's ``J_v``, ``H`` and ``B`` at each workspace
    point (:func:`~hapticdesign.analysis.wall_stiffness.kmax`), so when every device variable of the study is a motor
    field it does not read (:data:`KMAX_UNREAD`), every design has the device file's value, computed once here. Where
    a variable changes the geometry, an inertia, a damping or a gear ratio, no bound holds for every design (the
    handle's damping and mass follow them), and nothing is said before the run."""
    spec = bound.study.spec
    walls = [c for c in spec.constraints if isinstance(c, IndexConstraint) and c.index == "kmax"]
    if not walls or not all(_unread_by_kmax(name) for name in bound.space.names):
        return []
    answer = StudyEvaluator(bound).constraints([bound.middle()])[0]
    if answer.reason:
        return []
    reduced = dict(zip(bound.keys, answer.reduced))
    out = []
    for c in walls:
        value = reduced[c.key]
        missed = [(limit, word) for excess, limit, word in c.beyond(value) if excess > 0.0]
        if missed:
            limit, word = missed[0]
            out.append(f"{bound.study.path.name}: no design can meet {c.label} {word} {limit:g} N/m: every design's "
                       f"{c.label} is the device file's {value:.6g} N/m (no variable of the study changes the "
                       "geometry, inertias, damping or gear ratios it depends on)")
    return out
