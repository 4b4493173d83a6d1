"""What the optimization report's design explorer reads: every evaluated design (above :data:`EMBEDDED_LIMIT`, the
front and a seeded sample of the others), the front, the selection, the device file's design and, per front design,
its device file, its indices over the workspace points (the maps), a still picture of it and the commands that
reproduce its numbers; and the copy of the study and device files (:data:`STUDY_COPY`) from which ``hapticdesign
explore`` computes the card of any evaluated design (:func:`evaluation_card`).

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

from pathlib import Path

from hapticdesign.analysis.metrics.indices import evaluate_designs, reduce, reduced_at
from hapticdesign.analysis.view.skeleton import home_pose, snapshot
from hapticdesign.analysis.workspace import reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.files import parse_structured, quote, read_text, structured_kind
from hapticdesign.optimization.study_evaluation import BoundStudy, workspace_of
from hapticdesign.optimization.study_file import Choice, IndexConstraint, Study, StudySpec, study_from_mapping
from hapticdesign.optimization.study_outputs import Selection, baseline_lines
from hapticdesign.optimization.study_run import Encoding, Record, StudyRun, record_of

DESIGNS = "designs"
"""The folder of the output holding each front design's device file (``designs/design-3.yaml``)."""


EMBEDDED_LIMIT = 20_000
"""Most evaluated designs off the front that the explorer's page embeds: above it, a sample of this many (seeded by the
run's seed, :func:`embedded_records`) beside the front; the page says how many it shows of how many (the measured
load and filter times behind the figure: benchmarks/bench_explorer.py, docs/optimization.md)."""

STUDY_COPY = "study.json"
"""The file of the output holding the study file's and the device file's names and texts, from which
:func:`study_of_copy` rebuilds the study (``hapticdesign explore`` computes any design's card from it)."""


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


def design_cards(bound: BoundStudy, designs: list[dict[str, float]], files: list[str],
                 headers: list[str]) -> list[FrontDesign]:
    """The card of each design of variable ``designs`` (its indices evaluated with the others' in one batch), whose
    device file would be ``files[i]`` (relative to the output folder) headed by ``headers[i]``."""
    device_values = [bound.device_values(v) for v in designs]
    evaluated = (evaluate_designs(bound.space, device_values, bound.points, bound.requests, bound.registry)
                 if bound.requests and len(bound.points) else [None] * len(designs))
    uses = _uses(bound)
    out = []
    for variables, values, evaluation, file, header in zip(designs, device_values, evaluated, files, headers):
        quoted = shlex.quote(file)
        commands = [{"what": "the device file's spec sheet at its home pose", "command": f"hapticdesign spec --device {quoted}"}]
        try:
            device = bound.space.device(values)
        except UserError as exc:
            device, header = None, [*header, f"The device file refuses it: {exc}"]
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
        out.append(FrontDesign(file, bound.device_file_text(variables, header, evaluated=device is not None), maps,
                               picture, commands))
    return out


def front_designs(run: StudyRun, bound: BoundStudy) -> list[FrontDesign]:
    """The card of every front design, in front.csv's order (the indices of all of them evaluated in one batch)."""
    records = [run.records[k] for k in run.front]
    return design_cards(bound, [r.values for r in records], [design_file(n) for n in range(1, len(records) + 1)],
                        [[f"Front design {n} of the study's report (report.html)", *baseline_lines(run, r)]
                         for n, r in enumerate(records, start=1)])


def evaluation_file(n: int) -> str:
    """The name a card gives the device file of evaluation ``n`` off the front (``hapticdesign explore`` answers its
    text; it is not written into the output folder)."""
    return f"evaluation-{n}.yaml"


def evaluation_card(bound: BoundStudy, evaluation: int, generation: int, values: dict[str, float]) -> dict:
    """The card of evaluated design number ``evaluation`` (evaluations.csv's row, of ``generation``) of variable
    ``values``, computed again from the study: its variables, objectives and constrained values as the run computed
    them (:meth:`BoundStudy.evaluate`, :func:`~.study_run.record_of`), feasible or why not, and its maps, picture,
    commands and device file's ``text`` (:func:`design_cards`; the file is named :func:`evaluation_file`)."""
    spec = bound.study.spec
    record = record_of(spec, generation, Encoding.of(spec).encode(values), values, bound.evaluate([values])[0])
    header = f"Evaluation {evaluation} of the study (evaluations.csv), computed by hapticdesign explore"
    card = design_cards(bound, [values], [evaluation_file(evaluation)], [[header]])[0]
    return {"evaluation": evaluation, "generation": generation, **_record(spec, record),
            **card.data(), "text": card.text}


def _record(spec: StudySpec, record: Record) -> dict:
    names = [o.name for o in spec.objectives]
    return {"variables": {k: _number(v) for k, v in record.values.items()},
            "objectives": dict(zip(names, map(_number, record.objectives))),
            "constraints": [_number(v) for v in record.constraints], "feasible": record.feasible,
            "reason": record.reason}


def explorer_data(run: StudyRun, bound: BoundStudy, selection: Selection, designs: list[FrontDesign]) -> dict:
    """Everything the explorer shows, JSON-ready: the study's variables (with their units, :meth:`BoundStudy.units`,
    "" where none is known), objectives (with units and reductions) and constraints; the evaluated designs it embeds
    (:func:`embedded_records`) as columns (evaluations.csv's numbers, None where it has none; ``evaluation``: their
    numbers there) and ``count``, how many designs evaluations.csv holds; the front as indices into those columns
    (0-based); the selected design; the device file's design; the workspace points; and the front designs' cards
    (:func:`front_designs`)."""
    spec = bound.study.spec
    embedded = embedded_records(run)
    place = {k: i for i, k in enumerate(embedded)}
    records = [run.records[k] for k in embedded]
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
        "count": len(run.records),
        "sample": {"limit": EMBEDDED_LIMIT, "seed": run.seed},
        "evaluations": {
            "evaluation": [k + 1 for k in embedded],
            "generation": [r.generation for r in records],
            "variables": [[_number(r.values[v["name"]]) for r in records] for v in variables],
            "objectives": [[_number(r.objectives[k]) for r in records] for k in range(len(objectives))],
            "constraints": [[_number(r.constraints[k]) for r in records] for k in range(len(constraints))],
            "feasible": [r.feasible for r in records],
            "reason": [r.reason for r in records],
            "polished": [r.polished for r in records],
        },
        "front": [place[k] for k in run.front],
        "selected": {"position": selection.position, "rule": selection.rule},
        "baseline": None if run.baseline is None else _record(run.spec, run.baseline),
        "workspace": {"points": [[float(x) for x in p] for p in bound.points], "center": bound.center,
                      "coarseness": bound.coarseness},
        "designs": [d.data() for d in designs],
    }


def embedded_records(run: StudyRun) -> list[int]:
    """The records (0-based, in evaluation order) the explorer's page embeds: all of them when at most
    :data:`EMBEDDED_LIMIT` lie off the front; else the front, the polished designs and :data:`EMBEDDED_LIMIT` of the
    others drawn without replacement by a generator seeded with the run's seed (the same run, the same sample)."""
    kept = set(run.front) | {k for k, r in enumerate(run.records) if r.polished}
    others = [k for k in range(len(run.records)) if k not in kept]
    if len(others) <= EMBEDDED_LIMIT:
        return list(range(len(run.records)))
    drawn = np.random.default_rng(run.seed).choice(len(others), size=EMBEDDED_LIMIT, replace=False)
    return sorted(kept | {others[i] for i in drawn})


def study_copy(study: Study) -> str:
    """The text of :data:`STUDY_COPY`: the study file's and the device file's names and texts, as the run read them."""
    return json.dumps({"study": {"name": study.path.name, "text": study.study_text},
                       "device": {"name": study.device_path.name, "text": study.device_text}}, indent=1)


def study_of_copy(path: Path) -> Study:
    """The study saved in :data:`STUDY_COPY` at ``path`` (:func:`study_copy`), bound to the device file's text saved
    beside it (its ``device`` entry is not read again: the device file may have changed or moved since the run); a
    file that is not such a copy is a one-line UserError."""
    try:
        data = json.loads(read_text(path, "study copy"))
        names = {part: data[part]["name"] for part in ("study", "device")}
        texts = {part: data[part]["text"] for part in ("study", "device")}
    except (ValueError, TypeError, KeyError):
        raise UserError(f"{path}: not the copy of a study that optimize writes (study and device, each a name and a "
                        "text)") from None
    if not all(isinstance(v, str) and structured_kind(v) and Path(v).name == v for v in names.values()) or \
            not all(isinstance(v, str) for v in texts.values()):
        raise UserError(f"{path}: not the copy of a study that optimize writes (a name is not a study or device "
                        f"file's: {quote(str(names))})")
    where = f"{path} (study)"
    spec = study_from_mapping(parse_structured(texts["study"], structured_kind(names["study"]), where), where)
    return Study(spec, path.parent / names["study"], path.parent / names["device"], texts["study"], texts["device"])
