"""A study bound to its device file and the index registry: the answers for a batch of designs.

:func:`bind_study` checks what the study file alone cannot: every variable is one the device file has
(:class:`~hapticdesign.devices.design_space.DesignSpace`), every index is registered
(:mod:`hapticdesign.analysis.metrics.indices`), the workspace box is a valid grid
(:class:`~hapticdesign.analysis.workspace.Workspace`), and the work is within the stated limit. A design is
then the device at its values; the registry reaches the workspace points by the project's inverse
kinematics and gives each index per point, reduced here as the study asks. A design the device file's own
checks refuse, or one that does not reach a point, has no values and says why.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import yaml

from hapticdesign.analysis.metrics.indices import Request, evaluate_at, reduce, requests_of
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.view.figure import render_png
from hapticdesign.analysis.view.skeleton import home_pose
from hapticdesign.analysis.workspace import Workspace, reach_workspace
from hapticdesign.devices.design_space import DesignSpace
from hapticdesign.errors import UserError
from hapticdesign.files import parse_structured
from hapticdesign.model.inertia import SEED_FIELDS, seed_parameter_name
from hapticdesign.optimization.study_file import Study
from hapticdesign.optimization.study_outputs import index_maps
from hapticdesign.optimization.study_run import Answer, reduced_keys
from hapticdesign.simulation.design_indices import DESIGN_INDICES, evaluate, evaluate_designs
from hapticdesign.workload import require_within

STUDY_LIMIT = 1e5
"""Most design-point evaluations of a study without ``--force``: population x generations x workspace
points (each one a design's pose reached and its indices computed; docs/limits.md)."""


def require_study_workload(study: Study) -> None:
    """Refuse a study whose population x generations x workspace points is above :data:`STUDY_LIMIT` (method
    convex solves one program, whose size the number of variables bounds)."""
    spec = study.spec
    if spec.algorithm.method == "convex":
        return
    points = len(workspace_of(study).points())
    amount = spec.algorithm.population * spec.algorithm.generations * points
    require_within(f"a study of {spec.algorithm.population} designs x {spec.algorithm.generations} generations x "
                   f"{points} workspace points", amount, STUDY_LIMIT, "design-point evaluations")


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
    """A study with its device file's design space, its workspace points and its index names checked."""

    def __init__(self, study: Study):
        self.study = study
        spec = study.spec
        kind = _kind(study.device_path)
        if not kind:
            raise UserError(f"{study.path}: device {study.device_path.name!r} must be a device file (.yaml, .yml, "
                            ".toml or .json)")
        self.mapping = parse_structured(study.device_text, kind, str(study.device_path))
        self.keys = reduced_keys(spec)
        asked = list(dict.fromkeys(key[:2] for key in self.keys))
        self.labels = {request: f"request{k}" for k, request in enumerate(asked)}
        self.requests = [Request(index, {k: list(v) if isinstance(v, tuple) else v for k, v in options}, label)
                         for (index, options), label in self.labels.items()]
        try:
            self.space = DesignSpace(self.mapping, spec.variables)
            requests_of(self.requests, DESIGN_INDICES)
            self._check_options()
        except UserError as exc:
            raise UserError(f"{study.path}: {exc}") from None
        workspace = workspace_of(study)
        self.points = np.zeros((0, 3)) if workspace is None else workspace.points()
        self.title = f"{self.space.base.name} ({study.path.name})"

    def _check_options(self) -> None:
        """Every index with its options once at the device file's home pose, so that an option's bad value
        is refused before the run (not found in every design)."""
        device = self.space.base
        evaluate_at(device, configuration_of(device).full(home_pose(device)), self.requests, None, DESIGN_INDICES)

    def evaluate(self, batch: list[dict[str, float]]) -> list[Answer]:
        """Answers for a batch of designs, in order: the registry evaluates them together (through the compiled
        kernels where it can, :func:`~hapticdesign.simulation.design_indices.evaluate_designs`), each reduced
        here; a design the device file refuses or that misses a workspace point has none, and says why."""
        nothing = (math.nan,) * len(self.keys)
        out = []
        for result in evaluate_designs(self.space, batch, self.points, self.requests):
            if result.reason is not None:
                out.append(Answer(nothing, result.reason))
            else:
                out.append(Answer(tuple(reduce(result.values[self.labels[key[:2]]], key[2]) for key in self.keys)))
        return out

    def points_reached(self, values: dict[str, float]) -> int:
        """How many workspace points the design reaches, each from home on its own (the closest design of a
        study whose workspace no design reaches)."""
        try:
            device = self.space.device(values)
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
        for v in self.space.variables:
            value = float(values[v.name])
            if v.kind == "parameter":
                data["parameters"][v.name] = value
            elif v.kind == "inertial":
                body = next(b for b in data["bodies"] if str(b["name"]) == v.target)
                field = next(f for f in SEED_FIELDS if seed_parameter_name(f, v.target) == v.name)
                body[field] = value
            elif v.kind == "section":
                data["links"][v.target]["section"][v.field] = value
            else:
                data["actuators"][v.target][v.field] = value
        return data

    def device_file_text(self, values: dict[str, float]) -> str:
        """:meth:`device_mapping` as YAML, headed by where it comes from."""
        shown = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        names = (json.dumps(self.study.path.name), json.dumps(self.study.device_path.name))  # no line break in them
        header = f"# The design selected by study {names[0]} from device file {names[1]}:\n# {shown}\n"
        return header + yaml.safe_dump(self.device_mapping(values), sort_keys=False, allow_unicode=False)

    def pictures(self, values: dict[str, float]) -> list[tuple[bytes, str]]:
        """The selected design's picture at the workspace centre (at home when the centre is out of reach) and
        maps of its indices over the workspace points."""
        device = self.space.device(values)
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
        result = evaluate(device, self.points, self.requests)
        if result.reason is None:
            names = {label: f"{index} ({DESIGN_INDICES[index].unit})" for (index, _), label in self.labels.items()}
            maps = {names[label]: result.values[label] for label in self.labels.values()}
            out.append((index_maps(self.points, maps, "The selected design's indices over the workspace"),
                        "The selected design's indices at the workspace points"))
        return out


def bind_study(study: Study) -> BoundStudy:
    """The study bound to its device file and the index registry (see the module)."""
    return BoundStudy(study)
