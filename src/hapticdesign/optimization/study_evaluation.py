"""A study bound to its device file and the index registry: the parsed device file, its design space and the plan of
index requests (the answers for a batch of designs: :mod:`.study_evaluator`; a design's device file, spread and
pictures: :mod:`.study_outputs`).

:func:`bind_study` checks what the study file alone cannot: every variable is one the device file has
(:class:`~hapticdesign.devices.design_space.DesignSpace`), every index is registered
(:data:`hapticdesign.analysis.metrics.indices.INDICES`, with the caller's own indices beside it), the workspace box
is a valid grid (:class:`~hapticdesign.analysis.workspace.Workspace`), and the work is within the stated limit. A design is
then the device at its values; the registry reaches the workspace points by the project's inverse
kinematics and gives each index per point, reduced as the study asks. A design the device file's own
checks refuse, or one that does not reach a point, has no values and says why.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np

from hapticdesign.analysis.metrics.indices import (
    INDICES, Index, Registry, Request, evaluate_at, evaluate_parameters, requests_of,
)
from hapticdesign.analysis.metrics.indices.registry import EVALUATION_LIMIT, require_evaluations
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.view.skeleton import home_pose
from hapticdesign.analysis.workspace import Workspace
from hapticdesign.devices.design_space import DesignSpace
from hapticdesign.errors import UserError
from hapticdesign.files import parse_structured, quote
from hapticdesign.optimization.study_file import Choice, IndexConstraint, Study
from hapticdesign.optimization.study_polish import most_designs
from hapticdesign.optimization.study_run import reduced_keys

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


def _kind(path: Path) -> str:
    return {".yml": "yaml", ".yaml": "yaml", ".toml": "toml", ".json": "json"}.get(path.suffix.lower(), "")


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
        kind = _kind(study.device_path)
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


def bind_study(study: Study, indices: Iterable[Index] = (), registry: Registry = INDICES) -> BoundStudy:
    """The study bound to its device file and ``registry`` with ``indices`` (a caller's own, made with
    :func:`hapticdesign.index`) beside it (see the module)."""
    return BoundStudy(study, registry.with_indices(indices) if indices else registry)
