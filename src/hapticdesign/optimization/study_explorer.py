"""What the optimization report's design explorer reads: every evaluated design, the front, the selection, the
device file's design and, per front design, its device file, its indices over the workspace points (the maps), a
still picture of it and the commands that reproduce its numbers.

Everything here is JSON-ready (numbers as floats, NaN as None) and carries user strings (names, reasons, the device's
name) as data: the page (:mod:`hapticdesign.interface.report.optimization_page`) embeds it with
:func:`hapticdesign.escape.script_json` and shows strings only as text. The numbers are the records' own floats, so
the page shows what front.csv and evaluations.csv hold (both written with ``repr``).
"""

from __future__ import annotations

import json
import math
import shlex
from dataclasses import dataclass

import numpy as np

from hapticdesign.analysis.metrics.indices import evaluate_designs, reduce, reduced_at
from hapticdesign.analysis.view.skeleton import home_pose, snapshot
from hapticdesign.analysis.workspace import reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.optimization.study_evaluation import BoundStudy, workspace_of
from hapticdesign.optimization.study_file import Choice, IndexConstraint
from hapticdesign.optimization.study_outputs import Selection, baseline_lines, device_file_text
from hapticdesign.optimization.study_run import Record, StudyRun

DESIGNS = "designs"
"""The folder of the output holding each front design's device file (``designs/design-3.yaml``)."""


def design_file(n: int) -> str:
    """The device file of front design ``n`` (1-based, as front.csv numbers it), relative to the output folder."""
    return f"{DESIGNS}/design-{n}.yaml"


def _number(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def _unit(unit: str) -> str:
    return "-" if unit == "1" else unit


@dataclass(frozen=True)
class FrontDesign:
    """One front design's card beyond its numbers: its device file's ``text`` (written to ``file``), its ``maps``
    (per pose index of the study: the values at the workspace points and the objectives and constraints that reduce
    it, with the point where they are taken), a ``picture`` (:func:`~hapticdesign.analysis.view.skeleton.snapshot`;
    None when the device cannot be built) and the ``commands`` that reproduce it, run in the output folder."""

    file: str
    text: str
    maps: dict
    picture: dict | None
    commands: list[dict]

    def data(self) -> dict:
        """The JSON-ready card (without the device file's text)."""
        return {"file": self.file, "maps": self.maps, "picture": self.picture, "commands": self.commands}


def _uses(bound: BoundStudy) -> dict[str, list[tuple[str, str]]]:
    """Per request label: the objectives and index constraints that reduce it, as (name, reduction)."""
    spec = bound.study.spec
    out: dict[str, list[tuple[str, str]]] = {}
    for use, name in [*((o, o.name) for o in spec.objectives),
                      *((c, c.label) for c in spec.constraints if isinstance(c, IndexConstraint))]:
        label = bound.labels.get(use.request)
        if label is not None:
            out.setdefault(label, []).append((name, use.reduce))
    return out


def _picture(bound: BoundStudy, device) -> tuple[dict, str]:
    """The device at the workspace centre (at home when the centre is out of reach, or without a workspace) and where."""
    workspace = workspace_of(bound.study)
    q, where = home_pose(device), "at home"
    if workspace is not None:
        try:
            q = reach_workspace(device, np.asarray(workspace.center, dtype=float)[None, :]).q[0]
            where = "at the workspace centre"
        except UserError:
            pass
    return {**snapshot(device, q), "where": where}, where


def _pose_text(q: np.ndarray) -> str:
    return ",".join(repr(float(v)) for v in q)


def front_designs(run: StudyRun, bound: BoundStudy) -> list[FrontDesign]:
    """The card of every front design, in front.csv's order (the indices of all of them evaluated in one batch)."""
    records = [run.records[k] for k in run.front]
    device_values = [bound.device_values(r.values) for r in records]
    evaluated = (evaluate_designs(bound.space, device_values, bound.points, bound.requests, bound.registry)
                 if bound.requests and len(bound.points) else [None] * len(records))
    uses = _uses(bound)
    out = []
    for n, (record, values, evaluation) in enumerate(zip(records, device_values, evaluated), start=1):
        file = design_file(n)
        quoted = shlex.quote(file)
        commands = [{"what": "the device file's spec sheet at its home pose", "command": f"hapticdesign spec --device {quoted}"}]
        try:
            device = bound.space.device(values)
        except UserError:
            device = None
        picture = None
        if device is not None:
            picture, where = _picture(bound, device)
            commands.append({"what": f"the 3D view {where}",
                             "command": f"hapticdesign show --device {quoted} --q {_pose_text(np.array(picture['q']))}"})
        maps: dict = {}
        if evaluation is not None and evaluation.reason is None and device is not None:
            poses = reach_workspace(device, bound.points)
            for r in bound.requests:
                got = evaluation.values[r.key]
                reductions = []
                for name, how in uses.get(r.key, []):
                    at = reduced_at(got, how, bound.center)
                    reductions.append({"name": name, "how": how, "value": _number(reduce(got, how, bound.center)),
                                       "at": at})
                    if at is not None:
                        commands.append({"what": f"the spec sheet where {name} takes its {how} "
                                                 f"({', '.join(f'{x:.6g}' for x in bound.points[at])} m)",
                                         "command": f"hapticdesign spec --device {quoted} --q {_pose_text(poses.q[at])}"})
                named = r.index + (json.dumps(r.options, sort_keys=True) if r.options else "")
                maps[named] = {"index": r.index, "unit": _unit(bound.registry[r.index].unit),
                               "values": [_number(v) for v in got], "reductions": reductions}
        text = device_file_text(bound, record.values, [f"Front design {n} of the study's report (report.html)",
                                                       *baseline_lines(run, record)])
        out.append(FrontDesign(file, text, maps, picture, commands))
    return out


def _record(run: StudyRun, record: Record) -> dict:
    names = [o.name for o in run.spec.objectives]
    return {"variables": {k: _number(v) for k, v in record.values.items()},
            "objectives": dict(zip(names, map(_number, record.objectives))),
            "constraints": [_number(v) for v in record.constraints], "feasible": record.feasible,
            "reason": record.reason}


def explorer_data(run: StudyRun, bound: BoundStudy, selection: Selection, designs: list[FrontDesign]) -> dict:
    """Everything the explorer shows, JSON-ready: the study's variables (with their units, :meth:`BoundStudy.units`,
    "" where none is known), objectives (with units and reductions) and constraints; every evaluated design as columns (evaluations.csv's numbers, None where it has none); the front as
    record indices (0-based); the selected design; the device file's design; the workspace points; and the front
    designs' cards (:func:`front_designs`)."""
    spec = bound.study.spec
    records = run.records
    units = bound.units()
    grid = "" if not bound.coarseness else f" ({bound.coarseness})"
    objectives = []
    for o in spec.objectives:
        index = bound.registry[o.index]
        over = "" if index.of_parameters else f" over the workspace{grid}"
        objectives.append({"name": o.name, "index": o.index, "unit": _unit(index.unit), "reduce": o.reduce,
                           "sense": o.sense, "about": f"{o.sense}imize the {o.reduce} of {o.index}{over}"})
    constraints = []
    for c in spec.constraints:
        unit = _unit(bound.registry[c.index].unit) if isinstance(c, IndexConstraint) else _unit(units[c.label])
        constraints.append({"name": c.label, "unit": unit, "at_least": c.at_least, "at_most": c.at_most})
    variables = []
    for name, v in spec.variables.items():
        choices = list(v.values) if isinstance(v, Choice) else None
        low, high = (min(v.values), max(v.values)) if choices else v
        variables.append({"name": name, "unit": _unit(units[name]), "low": float(low), "high": float(high),
                          "choices": choices})
    return {
        "title": bound.title,
        "study": bound.study.path.name,
        "device": bound.study.device_path.name,
        "variables": variables,
        "objectives": objectives,
        "constraints": constraints,
        "evaluations": {
            "generation": [r.generation for r in records],
            "variables": [[_number(r.values[v["name"]]) for r in records] for v in variables],
            "objectives": [[_number(r.objectives[k]) for r in records] for k in range(len(objectives))],
            "constraints": [[_number(r.constraints[k]) for r in records] for k in range(len(constraints))],
            "feasible": [r.feasible for r in records],
            "reason": [r.reason for r in records],
            "polished": [r.polished for r in records],
        },
        "front": list(run.front),
        "selected": {"position": selection.position, "rule": selection.rule},
        "baseline": None if run.baseline is None else _record(run, run.baseline),
        "workspace": {"points": [[float(x) for x in p] for p in bound.points], "center": bound.center,
                      "coarseness": bound.coarseness},
        "designs": [d.data() for d in designs],
    }
