"""A study bound to its device file and the index registry: the answers for a batch of designs.

:func:`bind_study` checks what the study file alone cannot: every variable is one the device file has
(:class:`~hapticdesign.devices.design_space.DesignSpace`), every index is registered
(:data:`hapticdesign.analysis.metrics.indices.INDICES`, with the caller's own indices beside it), the workspace box
is a valid grid (:class:`~hapticdesign.analysis.workspace.Workspace`), and the work is within the stated limit. A design is
then the device at its values; the registry reaches the workspace points by the project's inverse
kinematics and gives each index per point, reduced here as the study asks. A design the device file's own
checks refuse, or one that does not reach a point, has no values and says why.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Iterable, Mapping, Sequence

import numpy as np
import yaml

from hapticdesign.analysis.metrics.indices import (
    INDICES, Evaluation, Index, Registry, Request, evaluate_at, evaluate_designs, evaluate_parameters, reduce,
    reduced_at, reduction_label, requests_of, spread,
)
from hapticdesign.analysis.metrics.indices.registry import EVALUATION_LIMIT, require_evaluations
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.view.figure import render_png
from hapticdesign.analysis.view.skeleton import home_pose
from hapticdesign.analysis.workspace import Workspace, WorkspacePoses, reach_workspace
from hapticdesign.devices.design_space import DesignSpace
from hapticdesign.errors import UserError
from hapticdesign.files import parse_structured, quote, structured_kind
from hapticdesign.model.device import Device
from hapticdesign.optimization.study_file import Choice, IndexConstraint, Study
from hapticdesign.optimization.study_outputs import index_maps
from hapticdesign.optimization.study_polish import most_designs
from hapticdesign.optimization.study_run import Answer, reduced_keys, violations

STUDY_LIMIT = EVALUATION_LIMIT
"""Most design-point evaluations of a study without ``--force``: population x generations x workspace
points (each one a design's pose reached and its indices computed; docs/limits.md)."""


KMAX_UNREAD = ("coulomb", "torque_continuous", "torque_peak")
"""The motor fields (``actuators.<joint>.<field>``) the ``kmax`` index does not read: its loop is linear in the
handle's J_v, H and B."""


def _unread_by_kmax(name: str) -> bool:
    return name.startswith("actuators.") and name.rsplit(".", 1)[-1] in KMAX_UNREAD


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
    """A study with its device file's design space, its workspace points and its index names checked."""

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
        self._evaluated: dict[tuple, tuple] = {}

    def _middle(self) -> dict[str, float]:
        """The design in the middle of the variables' bounds (a choice's first value)."""
        return {name: v.values[0] if isinstance(v, Choice) else (v[0] + v[1]) / 2
                for name, v in self.study.spec.variables.items()}

    def _check_options(self) -> None:
        """Every index with its options once at the device file's home pose (the parameter indices at the design in
        the middle of the variables' bounds), so that an option's bad value is refused before the run (not found in every design)."""
        device = self.space.base
        evaluate_at(device, configuration_of(device).full(home_pose(device)), self.requests, None, self.registry)
        middle = self._middle()
        full = self.study.spec.with_parameters(middle)
        for name, f in self.study.spec.parameters.items():  # the formula that fails, not an index reading its value
            if not math.isfinite(float(full[name])):
                raise UserError(f"parameters.{name}: {quote(f.text)} is {float(full[name])} at the middle of the "
                                "variables' bounds; a parameter must be a finite number")
        params = {name: np.array([float(value)]) for name, value in
                  {**device.params, **self.device_values(middle)}.items()}
        evaluate_parameters(params, self.parameter_requests, self.registry)

    def unmeetable_walls(self) -> list[str]:
        """The ``kmax`` constraints that no design of the study can meet, in words, known before the run where that is
        rigorous: ``kmax`` is the sampled wall's exact limit from the handle's ``J_v``, ``H`` and ``B`` at each
        workspace point (:func:`~hapticdesign.analysis.wall_stiffness.kmax`), so when every device variable of the
        study is a motor field it does not read (:data:`KMAX_UNREAD`), every design has the device file's value,
        computed once here. Where a variable changes the geometry, an inertia, a damping or a gear ratio, no bound
        holds for every design (the handle's damping and mass follow them), and nothing is said before the run."""
        walls = [c for c in self.study.spec.constraints if isinstance(c, IndexConstraint) and c.index == "kmax"]
        if not walls or not all(_unread_by_kmax(name) for name in self.space.names):
            return []
        answer = self.evaluate([self._middle()], objectives=False)[0]
        if answer.reason:
            return []
        reduced = dict(zip(self.keys, answer.reduced))
        out = []
        for c in walls:
            value = reduced[c.key]
            if c.at_least is not None and value < c.at_least:
                word, bound = ">=", c.at_least
            elif c.at_most is not None and value > c.at_most:
                word, bound = "<=", c.at_most
            else:
                continue
            out.append(f"{self.study.path.name}: no design can meet {c.label} {word} {bound:g} N/m: every design's "
                       f"{c.label} is the device file's {value:.6g} N/m (no variable of the study changes the "
                       "geometry, inertias, damping or gear ratios it depends on)")
        return out

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
        """Answers for a batch of designs, in order: the registry evaluates the pose indices together (through the
        compiled kernels where it can, :func:`~hapticdesign.analysis.metrics.indices.evaluate_designs`), each
        reduced here; a design the device file refuses or that misses a workspace point has none, and says why.
        The parameter indices are evaluated for the whole batch at once (no device is built when the study asks
        only for them); those only the objectives read are evaluated only for the designs that meet every
        constraint (NSGA-II's constrained domination never reads the objectives of the others), and for none
        without ``objectives`` (for every valid design with ``every_objective``: the device file's design, whose
        objectives are compared even when it breaks a constraint)."""
        device_values = [self.device_values(v) for v in batch]
        if self.requests:
            results = evaluate_designs(self.space, device_values, self.points, self.requests, self.registry)
        else:
            results = [self._checked(v) for v in device_values]
        valid = [k for k, r in enumerate(results) if r.reason is None]
        values = {k: dict(results[k].values) for k in valid}
        first = [r for r in self.parameter_requests if r.key in self.constrained]
        failed = self._parameter_values(first, [device_values[k] for k in valid], valid, values)
        valid = [k for k in valid if k not in failed]
        if objectives:
            feasible = [k for k in valid if every_objective or self._feasible(batch[k], values[k])]
            later = [r for r in self.parameter_requests if r.key not in self.constrained]
            failed |= self._parameter_values(later, [device_values[k] for k in feasible], feasible, values)
        nothing = (math.nan,) * len(self.keys)
        out = []
        for k, result in enumerate(results):
            reason = result.reason if result.reason is not None else failed.get(k)
            if reason is not None:
                out.append(Answer(nothing, reason))
            else:
                got = values[k]
                out.append(Answer(tuple(reduce(got[label], key[2], self.center) if (label := self.labels[key[:2]]) in got
                                        else math.nan for key in self.keys)))
        return out

    def _checked(self, device_values: dict[str, float]) -> Evaluation:
        """A design of a study of parameter indices alone, whose device is not built: its device values must pass the
        design space's check (finite numbers; a formula may give inf or NaN), or it has none, and says why."""
        try:
            self.space.checked_values(device_values)
        except UserError as exc:
            return Evaluation({}, str(exc))
        return Evaluation({})

    def evaluate_constraints(self, batch: list[dict[str, float]]) -> list[Answer]:
        """:meth:`evaluate` without the indices that only the objectives read."""
        return self.evaluate(batch, objectives=False)

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
        base = self.space.base.params
        params = {name: np.array([float(d.get(name, base[name])) for d in designs]) for name in base}
        for key, column in evaluate_parameters(params, requests, self.registry).items():
            for i, k in enumerate(rows):
                values[k][key] = column[i:i + 1]

    def _feasible(self, variables: dict[str, float], values: dict[str, np.ndarray]) -> bool:
        spec = self.study.spec
        constrained = []
        for c in spec.constraints:
            if isinstance(c, IndexConstraint):
                constrained.append(reduce(values[self.labels[c.key[:2]]], c.reduce, self.center))
            else:
                constrained.append(c.value(variables))
        g, _ = violations(spec, constrained)
        return bool(np.all(np.isfinite(g)) and np.all(g <= 0.0))

    def points_reached(self, values: dict[str, float]) -> int:
        """How many workspace points the design reaches, each from home on its own (the closest design of a
        study whose workspace no design reaches)."""
        try:
            device = self.space.device(self.device_values(values))
        except UserError:
            return 0
        count = 0
        for point in self.points:
            try:
                reach_workspace(device, point[None, :])
                count += 1
            except UserError:
                pass
        return count

    def device_mapping(self, values: dict[str, float]) -> dict:
        """The device file's mapping with ``values`` written in: a device file every command reads."""
        data = copy.deepcopy(self.mapping)
        values = self.device_values(values)
        for v in self.space.variables:
            v.write(data, float(values[v.name]))
        return data

    def device_file_text(self, values: dict[str, float], comments: Sequence[str] = (), evaluated: bool = True) -> str:
        """:meth:`device_mapping` as YAML, headed by where it comes from, the ``comments`` lines (the device file's
        design beside it) and, with ``evaluated``, where the study evaluated it (:meth:`where_evaluated`; a design the
        device file refuses has no such lines, and the comments say why)."""
        shown = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        names = (json.dumps(self.study.path.name), json.dumps(self.study.device_path.name))  # no line break in them
        header = f"# The design selected by study {names[0]} from device file {names[1]}:\n# {shown}\n"
        lines = "".join(f"# {' '.join(line.splitlines())}\n" for line in comments)  # a reason's line break stays a comment
        return (header + lines + (self.where_evaluated(values) if evaluated else "")
                + yaml.safe_dump(self.device_mapping(values), sort_keys=False, allow_unicode=False))

    def _at_points(self, values: dict[str, float]) -> tuple[Device, WorkspacePoses | None, dict | None]:
        """A design's device, its poses at the workspace points and its indices there per request key (None, None
        without points, indices or a reached workspace): computed once per design for selected.yaml and the
        report's pictures."""
        key = tuple(sorted(values.items()))
        if key not in self._evaluated:
            device = self.space.device(self.device_values(values))
            poses = got = None
            if len(self.points) and self.requests:
                try:
                    poses = reach_workspace(device, self.points)
                    got = evaluate_at(device, poses.full, self.requests, None, self.registry).values
                except UserError:
                    poses = got = None
            self._evaluated = {key: (device, poses, got)}
        return self._evaluated[key]

    def where_evaluated(self, values: dict[str, float]) -> str:
        """Comment lines naming, for each index the study reduced over its workspace points, the value with how coarse
        the grid is (``max of 27 points, grid 3``) and, for ``min``, ``max`` and ``center``, the point where the design
        takes it and its actuated coordinates there, with the ``spec`` command that gives the sheet at that pose
        (issue 35: a sheet at home, outside the study's box, reads another pose's numbers; at this pose its renderable
        stiffness is the study's ``kmax`` with the same loop settings); then each pose index by every reduction
        (:meth:`spread_rows`)."""
        device, poses, got = self._at_points(values)
        if got is None:
            return ""
        lines = []
        for index, options, how in self.keys:
            label = self.labels.get((index, options))
            if label not in got:
                continue
            named = index + (json.dumps(dict(options), sort_keys=True) if options else "")
            value = reduce(got[label], how, self.center)
            head = (f"# {how} {named} over the study's points ({reduction_label(how, len(self.points), self.grid)}) = "
                    f"{value:.6g} {self.registry[index].unit}")
            k = reduced_at(got[label], how, self.center)
            if k is None:
                lines.append(head + "\n")
                continue
            point = ", ".join(f"{x:.6g}" for x in self.points[k])
            q = ",".join(repr(float(x)) for x in poses.q[k])
            lines.append(f"{head} at ({point}) m; the sheet there: hapticdesign spec --device THIS_FILE --q {q}\n")
        for row in self.spread_rows(values):
            named, unit, *numbers = row
            shown = ", ".join(f"{how} {v}" for how, v in zip(SPREAD_COLUMNS, numbers) if v != "")
            lines.append(f"# {named} over the study's {self.coarseness} ({unit}): {shown}\n")
        return "".join(lines)

    @property
    def grid(self) -> int:
        """The workspace's points per axis (0 without a workspace)."""
        workspace = self.study.spec.workspace
        return 0 if workspace is None else workspace.grid

    def spread_rows(self, values: dict[str, float]) -> list[list]:
        """Each index of the study at the workspace's poses over the points, for a design: the index (with its
        options), its unit and :data:`SPREAD_COLUMNS` (the extremes' points as ``(x, y, z)`` in m; ``center`` blank for
        an even grid); none when the design does not reach every point."""
        _, _, got = self._at_points(values)
        if got is None:
            return []
        rows = []
        for r in self.requests:
            s = spread(got[r.key], self.center)
            named = r.index + (json.dumps(r.options, sort_keys=True) if r.options else "")
            rows.append([named, self.registry[r.index].unit,
                         *("" if s[c] is None else f"{s[c]:.6g}" for c in ("center", "median", "mean", "min")),
                         self._extreme(s, "min"), f"{s['max']:.6g}", self._extreme(s, "max")])
        return rows

    def _extreme(self, s: dict, how: str) -> str:
        """Where an extreme of :func:`~hapticdesign.analysis.metrics.indices.spread` is taken, and at how many points
        when it ties (a symmetric device's mirrored corners)."""
        ties = s[f"{how}_count"]
        return _point(self.points[s[f"{how}_at"]]) + (f" (one of {ties} points)" if ties > 1 else "")

    def pictures(self, values: dict[str, float]) -> list[tuple[bytes, str]]:
        """The selected design's picture at the workspace centre (at home when the centre is out of reach) and
        maps of its indices over the workspace points."""
        device, _, got = self._at_points(values)
        workspace = workspace_of(self.study)
        if workspace is None:
            return [(render_png(device, home_pose(device), dpi=100), "The selected design at home")]
        try:
            q = reach_workspace(device, np.asarray(workspace.center, dtype=float)[None, :]).q[0]
            where = "at the workspace centre"
        except UserError:
            q = home_pose(device)
            where = "at home"
        out = [(render_png(device, q, dpi=100), f"The selected design {where}")]
        if got is not None:
            names = {r.key: f"{r.index} ({self.registry[r.index].unit})" for r in self.requests}
            maps = {names[key]: got[key] for key in names}
            out.append((index_maps(self.points, maps, "The selected design's indices over the workspace"),
                        "The selected design's indices at the workspace points"))
        return out


SPREAD_COLUMNS = ("center", "median", "mean", "min", "min_at", "max", "max_at")
"""What :meth:`BoundStudy.spread_rows` gives of an index over the workspace points, in order: the value at the box's
centre, the median, the mean, the smallest and its point, the largest and its point (with how many points tie for an
extreme)."""


def _point(p: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in p) + ") m"


def bind_study(study: Study, indices: Iterable[Index] = (), registry: Registry = INDICES) -> BoundStudy:
    """The study bound to its device file and ``registry`` with ``indices`` (a caller's own, made with
    :func:`hapticdesign.index`) beside it (see the module)."""
    return BoundStudy(study, registry.with_indices(indices) if indices else registry)
