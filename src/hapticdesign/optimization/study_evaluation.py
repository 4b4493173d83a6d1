"""A study bound to its device file and the index registry (:class:`BoundStudy`: the parsed device file, its design
space and the plan of index requests) and its evaluator (:class:`StudyEvaluator`: the answers for a batch of designs,
here or on a Dask cluster); a design's device file, spread and pictures: :mod:`.study_outputs`.

:func:`bind_study` checks what the study file alone cannot: every variable is one the device file has
(:class:`~hapticdesign.devices.design_space.DesignSpace`), every index is registered
(:data:`hapticdesign.analysis.metrics.indices.INDICES`, with the caller's own indices beside it), the workspace box
is a valid grid (:class:`~hapticdesign.analysis.workspace.Workspace`), and the work is within the stated limit. A design is
then the device at its values; the registry evaluates the pose indices of a batch together (through the compiled
kernels where it can, :func:`~hapticdesign.analysis.metrics.indices.evaluate_designs`), reaching the workspace points by
the project's inverse kinematics, each index reduced as the study asks; the parameter indices are evaluated for the
whole batch at once. A design the device file's own checks refuse, or one that does not reach a point, has no values
and says why.

Batches go through one hook, pymoo's element-wise runner
(:func:`~hapticdesign.optimization.pymoo_run.elementwise_runner`): in this process a batch is one piece of work; with
the Dask client of ``optimize --scheduler`` it is cut into contiguous chunks, a few per worker, each sent with the
study itself (its text and its device file's text, so a worker needs no file of the caller's machine); each worker
binds the study once (kept per study fingerprint) and answers its chunks. The answers are gathered in the designs'
order, so a run on a cluster gives the same numbers as a run here.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Mapping
from functools import partial

import numpy as np

from hapticdesign.analysis.metrics.indices import (
    INDICES, Evaluation, Index, Registry, Request, drive_compliance, evaluate_at, evaluate_designs,
    evaluate_parameters, reduce, requests_of,
)
from hapticdesign.analysis.metrics.indices.registry import EVALUATION_LIMIT, require_evaluations
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.view.skeleton import home_pose
from hapticdesign.analysis.workspace import Workspace, reach_workspace
from hapticdesign.devices.design_space import DesignSpace
from hapticdesign.errors import UserError
from hapticdesign.files import parse_structured, quote, structured_kind
from hapticdesign.optimization.pymoo_run import elementwise_runner
from hapticdesign.optimization.study_file import Choice, IndexConstraint, Study
from hapticdesign.optimization.study_polish import most_designs
from hapticdesign.optimization.study_run import Answer, constrained_values, feasibility, reduced_keys

STUDY_LIMIT = EVALUATION_LIMIT
"""Most design-point evaluations of a study without ``--force``: population x generations x workspace
points (each one a design's pose reached and its indices computed; docs/limits.md)."""


def require_study_workload(study: Study, registry: Mapping[str, Index] = INDICES) -> None:
    """Refuse a study whose designs (population x generations x runs of a population search and at most as many as
    its polishing may ask, :func:`~.study_polish.most_designs`; one for method convex, whose program the number of
    variables bounds) x workspace points, each counted as its costliest index (:attr:`Index.cost`), is above
    :data:`STUDY_LIMIT`."""
    spec = study.spec
    workspace = workspace_of(study) if spec.algorithm.over_poses else None
    points = 1 if workspace is None else len(workspace.points())
    designs = spec.algorithm.designs + most_designs(spec)
    require_evaluations(f"a study of {designs} designs (population x generations x runs, and the polishing's most) "
                        f"x {points} workspace points", designs * points, [u.index for u in spec.index_uses],
                        registry)


def workspace_of(study: Study) -> Workspace | None:
    """The study's workspace grid (None for a study without one, method convex)."""
    if study.spec.workspace is None:
        return None
    box = study.spec.workspace.box
    try:
        return Workspace(box.center, box.size, study.spec.workspace.grid)
    except UserError as exc:
        raise UserError(f"{study.path}: {exc}") from None


class BoundStudy:
    """A study with its device file's design space, its workspace points and its index requests checked: the
    ``mapping`` of the device file, its ``space``, the reduced index ``keys`` of the study, the ``labels`` of its
    requests, the requests at the workspace's poses (``requests``) and of the parameters alone
    (``parameter_requests``), and the workspace ``points``."""

    def __init__(self, study: Study, registry: Registry = INDICES):
        self.study = study
        self.registry = registry
        """The indices the study may name."""
        spec = study.spec
        kind = structured_kind(study.device_path)
        if not kind:
            raise UserError(f"{study.path}: device {study.device_path.name!r} must be a device file (.yaml, .yml, "
                            ".toml or .json)")
        self.mapping = parse_structured(study.device_text, kind, str(study.device_path))
        if not isinstance(self.mapping, dict):  # as every reader of a device file says it
            raise UserError(f"{study.device_path}: expected a mapping (name: value) at the top level")
        self.keys = reduced_keys(spec)
        asked = list(dict.fromkeys(key[:2] for key in self.keys))
        self.labels = {request: f"request{k}" for k, request in enumerate(asked)}
        requests = [Request(index, {k: list(v) if isinstance(v, tuple) else v for k, v in options}, label)
                    for (index, options), label in self.labels.items()]
        try:
            requests_of(requests, registry)
        except UserError as exc:
            raise UserError(f"{study.path}: {exc}") from None
        self.requests = [r for r in requests if not registry[r.index].of_parameters]
        """The indices at the workspace's poses."""
        self.parameter_requests = [r for r in requests if registry[r.index].of_parameters]
        """The indices of the parameters alone."""
        constrained = {c.key[:2] for c in spec.constraints if isinstance(c, IndexConstraint)}
        self.constrained = {self.labels[request] for request in constrained}
        parameters = self.mapping.get("parameters") if isinstance(self.mapping.get("parameters"), dict) else {}
        self.device_names = [v for v in spec.variables if v not in spec.formula_variables or v in parameters]
        """The variables that are device design variables; the others are read by the ``parameters`` formulas."""
        try:
            self.space = DesignSpace(self.mapping, [*self.device_names, *spec.parameters])
            self._check_options()
        except UserError as exc:
            raise UserError(f"{study.path}: {exc}") from None
        workspace = workspace_of(study)
        self.points = np.zeros((0, 3)) if workspace is None else workspace.points()
        self.center = None if workspace is None else workspace.center_index
        """The place of the box's centre among the points (None for an even grid), which ``reduce: center`` reads."""
        self.coarseness = "" if workspace is None else workspace.describe()
        """How coarse the workspace grid is: ``27 points, grid 3``."""
        self.title = f"{self.space.base.name} ({study.path.name})"

    @property
    def grid(self) -> int:
        """The workspace's points per axis (0 without a workspace)."""
        workspace = self.study.spec.workspace
        return 0 if workspace is None else workspace.grid

    def middle(self) -> dict[str, float]:
        """The design in the middle of the variables' bounds (a choice's first value)."""
        return {name: v.values[0] if isinstance(v, Choice) else (v[0] + v[1]) / 2
                for name, v in self.study.spec.variables.items()}

    def _check_options(self) -> None:
        """Every index with its options once at the device file's home pose (the parameter indices at the design in
        the middle of the variables' bounds), so that an option's bad value is refused before the run (not found in every design)."""
        device = self.space.base
        evaluate_at(device, configuration_of(device).full(home_pose(device)), self.requests, None, self.registry)
        middle = self.middle()
        full = self.study.spec.with_parameters(middle)
        for name, f in self.study.spec.parameters.items():  # the formula that fails, not an index reading its value
            if not math.isfinite(float(full[name])):
                raise UserError(f"parameters.{name}: {quote(f.text)} is {float(full[name])} at the middle of the "
                                "variables' bounds; a parameter must be a finite number")
        params = {name: np.array([float(value)]) for name, value in
                  {**device.params, **self.device_values(middle)}.items()}
        evaluate_parameters(params, self.parameter_requests, self.registry)

    def units(self) -> dict[str, str]:
        """The unit of each column of the study's tables (front.csv, evaluations.csv, the report): a device variable's
        in its device file (:meth:`~hapticdesign.devices.design_space.Variable.unit`), a variable that only a
        ``parameters`` formula reads the unit of the device value that formula sets to it alone, an objective's and
        an index constraint's their index's, an expression constraint's its variables' when they share one; ``""``
        where none is known."""
        spec = self.study.spec
        device = {v.name: v.unit(self.space.spec) for v in self.space.variables}
        alone = {f.text.strip(): name for name, f in spec.parameters.items() if name in device}
        out = {name: device.get(name, device.get(alone.get(name, ""), "")) for name in spec.variables}
        out.update({o.name: self.registry[o.index].unit for o in spec.objectives})
        for c in spec.constraints:
            if isinstance(c, IndexConstraint):
                out[c.label] = self.registry[c.index].unit
            else:
                shared = {out.get(name, "") for name, _ in c.parsed.terms}
                out[c.label] = shared.pop() if len(shared) == 1 else ""
        return out

    def compliance(self) -> dict[str, str]:
        """Which compliance between the motors and the handle each index of the study that includes it (``kmax``)
        takes, by index name (:func:`~hapticdesign.analysis.metrics.indices.drive_compliance` of the device file's
        design: the fields of the device file, which every design of the study shares, decide it)."""
        return drive_compliance(self.space.base, [key[0] for key in self.keys], self.registry)

    def device_values(self, values: dict[str, float]) -> dict[str, float]:
        """The device design variables' values of a design: its variables' and the ``parameters`` formulas'."""
        full = self.study.spec.with_parameters(values)
        return {name: float(full[name]) for name in self.space.names}

    def baseline(self) -> tuple[dict[str, float] | None, str]:
        """The device file's own design: each variable at the value the device file states, and what is to be said of
        it. A variable that only the ``parameters`` formulas read takes the file's value of a device value that a
        formula sets to it alone (``actuators.q1.gear_ratio: "ratio1"``). None, and why, when the file fixes a
        variable nowhere (or leaves a motor field unset); else the values and, when there is any, a note naming the
        values outside the study's range and the device values the study's formulas set otherwise than the file."""
        spec = self.study.spec
        stated = self.space.defaults()
        alone = {f.text.strip(): name for name, f in spec.parameters.items() if name in stated}
        values = {}
        for name in spec.variables:
            value = stated.get(name, stated.get(alone.get(name, ""), math.nan))
            if not math.isfinite(value):
                return None, (f"device file {self.study.device_path.name} states no value of variable {name} (a "
                              "parameters formula setting a device value to it alone would give it)")
            values[name] = value
        notes = []
        for name, variable in spec.variables.items():
            low, high = ((min(variable.values), max(variable.values)) if isinstance(variable, Choice)
                         else variable)
            if not low <= values[name] <= high:
                notes.append(f"{name} = {values[name]:.6g} is outside the study's range [{low:g}, {high:g}]")
        for name, value in self.device_values(values).items():
            if not math.isclose(value, stated[name], rel_tol=1e-9, abs_tol=1e-15):
                notes.append(f"the study's formula sets {name} = {value:.6g} where the file states {stated[name]:.6g}")
        return values, "; ".join(notes)

    def evaluate(self, batch: list[dict[str, float]], objectives: bool = True,
                 every_objective: bool = False) -> list[Answer]:
        """Deprecated (one release): :meth:`StudyEvaluator.answers` of ``StudyEvaluator(bound)``."""
        warnings.warn("BoundStudy.evaluate is deprecated: use StudyEvaluator(bound)(batch) "
                      "(hapticdesign.optimization.study_evaluation)", FutureWarning, stacklevel=2)
        return StudyEvaluator(self).answers(batch, objectives, every_objective)

    def evaluate_constraints(self, batch: list[dict[str, float]]) -> list[Answer]:
        """Deprecated (one release): :meth:`StudyEvaluator.constraints` of ``StudyEvaluator(bound)``."""
        warnings.warn("BoundStudy.evaluate_constraints is deprecated: use StudyEvaluator(bound).constraints(batch) "
                      "(hapticdesign.optimization.study_evaluation)", FutureWarning, stacklevel=2)
        return StudyEvaluator(self).constraints(batch)


def bind_study(study: Study, indices: Iterable[Index] = (), registry: Registry = INDICES) -> BoundStudy:
    """The study bound to its device file and ``registry`` with ``indices`` (a caller's own, made with
    :func:`hapticdesign.index`) beside it (see the module)."""
    return BoundStudy(study, registry.with_indices(indices) if indices else registry)


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
