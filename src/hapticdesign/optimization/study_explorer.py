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
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hapticdesign.analysis.metrics.indices import evaluate_designs, reduce, reduced_at
from hapticdesign.analysis.view.skeleton import home_pose, snapshot
from hapticdesign.analysis.workspace import reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.files import parse_structured, quote, read_text, structured_kind
from hapticdesign.model.device import Device
from hapticdesign.optimization.study_evaluation import BoundStudy, StudyEvaluator, workspace_of
from hapticdesign.optimization.study_file import Choice, IndexConstraint, Study, study_from_mapping
from hapticdesign.optimization.study_outputs import Selection, baseline_lines, device_file_text
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
    spec: list[dict] | None = None
    """The spec summary at the design's home pose (rows ``{"name", "label", "value", "unit"}``, SI units), None when
    it was not computed or the device cannot be built or is singular at home."""

    def data(self) -> dict:
        """The JSON-ready card (without the device file's text)."""
        spec = None if self.spec is None else [{**row, "value": _number(row["value"]) if row["value"] is not None
                                                 else None} for row in self.spec]
        return {"file": self.file, "maps": self.maps, "picture": self.picture, "commands": self.commands, "spec": spec}


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


def _summary(summary: Summary | None, device: Device | None) -> list[dict] | None:
    if summary is None or device is None:
        return None
    try:
        return summary(device)
    except UserError:
        return None


def _pose_text(q: np.ndarray) -> str:
    return ",".join(repr(float(v)) for v in q)


Summary = Callable[[Device], list[dict]]
"""The spec summary of a device at its home pose (the interface passes
:func:`hapticdesign.studies.spec.spec_summary`, a layer above this one)."""


def design_cards(bound: BoundStudy, designs: list[dict[str, float]], files: list[str], headers: list[list[str]],
                 summary: Summary | None = None) -> list[FrontDesign]:
    """The card of each design of variable ``designs`` (its indices evaluated with the others' in one batch), whose
    device file would be ``files[i]`` (relative to the output folder) headed by ``headers[i]``, with
    ``summary(device)`` as its spec summary when given (None where it raises a UserError: a pose singular at home)."""
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
        out.append(FrontDesign(file, device_file_text(bound, variables, header, evaluated=device is not None), maps,
                               picture, commands, _summary(summary, device)))
    return out


def front_designs(run: StudyRun, bound: BoundStudy, summary: Summary | None = None) -> list[FrontDesign]:
    """The card of every front design, in front.csv's order (the indices of all of them evaluated in one batch), with
    ``summary`` as in :func:`design_cards`."""
    records = [run.records[k] for k in run.front]
    return design_cards(bound, [r.values for r in records], [design_file(n) for n in range(1, len(records) + 1)],
                        [[f"Front design {n} of the study's report (report.html)", *baseline_lines(run, r)]
                         for n, r in enumerate(records, start=1)], summary)


def evaluation_file(n: int) -> str:
    """The name a card gives the device file of evaluation ``n`` off the front (``hapticdesign explore`` answers its
    text; it is not written into the output folder)."""
    return f"evaluation-{n}.yaml"


def evaluation_card(bound: BoundStudy, evaluation: int, generation: int, values: dict[str, float],
                    summary: Summary | None = None) -> dict:
    """The card of evaluated design number ``evaluation`` (evaluations.csv's row, of ``generation``) of variable
    ``values``, computed again from the study: its variables, objectives and constrained values as the run computed
    them (:class:`~.study_evaluation.StudyEvaluator`, :func:`~.study_run.record_of`), feasible or why not, and its
    maps, picture, commands, spec summary (with ``summary``) and device file's ``text`` (:func:`design_cards`; the
    file is named :func:`evaluation_file`)."""
    spec = bound.study.spec
    answer = StudyEvaluator(bound)([values])[0]
    record = record_of(spec, generation, Encoding.of(spec).encode(values), values, answer)
    header = f"Evaluation {evaluation} of the study (evaluations.csv), computed by hapticdesign explore"
    card = design_cards(bound, [values], [evaluation_file(evaluation)], [[header]], summary)[0]
    return {"evaluation": evaluation, "generation": generation, **_record([o.name for o in spec.objectives], record),
            **card.data(), "text": card.text}


def _record(names: list[str], record: Record) -> dict:
    return {"variables": {k: _number(v) for k, v in record.values.items()},
            "objectives": dict(zip(names, map(_number, record.objectives))),
            "constraints": [_number(v) for v in record.constraints], "feasible": record.feasible,
            "reason": record.reason}


def quantity(name: str, unit: str, **more) -> dict:
    """A column of the explorer (a variable, an objective or a constrained value): its ``name``, its ``unit`` ("1" is
    shown as "-", "" where none is known) and what else the explorer reads of it: a variable's ``low``, ``high`` and
    ``choices``; an objective's ``sense`` ("min" or "max"), ``about`` (in words), ``index`` and ``reduce``; a
    constrained value's ``at_least`` and ``at_most``."""
    return {"name": name, "unit": _unit(unit), **more}


def explorer_table(title: str, study: str, device: str, variables: list[dict], objectives: list[dict],
                   constraints: list[dict], records: list[Record], front: list[int], selected: dict,
                   designs: list[dict], baseline: Record | None = None, workspace: dict | None = None,
                   front_file: str = "front.csv", evaluations_file: str | None = "evaluations.csv",
                   embedded: list[int] | None = None, sample: dict | None = None) -> dict:
    """The explorer's data, JSON-ready, of any set of evaluated designs (an optimization study's, or a seed's own
    studies': ``rcube optimize``, ``study phantom``): the columns (:func:`quantity`), every evaluated design as a
    :class:`~hapticdesign.optimization.study_run.Record` (its ``values`` keyed by the variables' names, its objectives
    and constrained values in the columns' order; ``count``: how many), the ``front`` as record indices (0-based;
    front design n is ``front[n - 1]``), the ``selected`` design (``{"position": its place on the front, "rule": in
    words}``), each front design's card (``designs``, :meth:`FrontDesign.data`), the design to compare with
    (``baseline``, None without one), the ``workspace`` points the cards' maps are drawn on (None: no maps) and the
    files that list the front (``front_file``, beside the page) and every design (``evaluations_file``, one row per
    record; None: the page alone lists them).

    The page embeds the records ``embedded`` (0-based, in order, holding the front; None: all of them) as columns,
    ``evaluation`` numbering each (record k is evaluation k + 1), the front as indices into those columns; ``sample``
    says how the ones off the front were drawn (``{"limit", "seed"}``, :func:`embedded_records`; None where every
    record is embedded)."""
    names = [o["name"] for o in objectives]
    embedded = list(range(len(records))) if embedded is None else list(embedded)
    place = {k: i for i, k in enumerate(embedded)}
    shown = [records[k] for k in embedded]
    return {
        "title": title,
        "study": study,
        "device": device,
        "variables": variables,
        "objectives": objectives,
        "constraints": constraints,
        "count": len(records),
        "sample": sample,
        "evaluations": {
            "evaluation": [k + 1 for k in embedded],
            "generation": [r.generation for r in shown],
            "variables": [[_number(r.values[v["name"]]) for r in shown] for v in variables],
            "objectives": [[_number(r.objectives[k]) for r in shown] for k in range(len(objectives))],
            "constraints": [[_number(r.constraints[k]) for r in shown] for k in range(len(constraints))],
            "feasible": [r.feasible for r in shown],
            "reason": [r.reason for r in shown],
            "polished": [r.polished for r in shown],
        },
        "front": [place[k] for k in front],
        "selected": selected,
        "baseline": None if baseline is None else _record(names, baseline),
        "workspace": workspace or {"points": [], "center": None, "coarseness": ""},
        "designs": designs,
        "front_file": front_file,
        "evaluations_file": evaluations_file,
    }


def explorer_data(run: StudyRun, bound: BoundStudy, selection: Selection, designs: list[FrontDesign]) -> dict:
    """Everything the explorer shows of an optimization study (:func:`explorer_table`): the study's variables (with
    their units, :meth:`BoundStudy.units`, "" where none is known), objectives (with units and reductions) and
    constraints; the evaluated designs it embeds (:func:`embedded_records`; evaluations.csv's numbers, None where it
    has none, ``count``: how many evaluations.csv holds); the front; the selected design; the device file's design;
    the workspace points; and the front designs' cards (:func:`front_designs`)."""
    spec = bound.study.spec
    units = bound.units()
    grid = "" if not bound.coarseness else f" ({bound.coarseness})"
    compliance = run.compliance
    objectives = []
    for o in spec.objectives:
        index = bound.registry[o.index]
        over = "" if index.of_parameters else f" over the workspace{grid}"
        drive = f"; drive compliance: {compliance[o.index]}" if o.index in compliance else ""
        objectives.append(quantity(o.name, index.unit, index=o.index, reduce=o.reduce, sense=o.sense,
                                   about=f"{o.sense}imize the {o.reduce} of {o.index}{over}{drive}"))
    constraints = []
    for c in spec.constraints:
        unit = bound.registry[c.index].unit if isinstance(c, IndexConstraint) else units[c.label]
        constraints.append(quantity(c.label, unit, at_least=c.at_least, at_most=c.at_most))
    variables = []
    for name, v in spec.variables.items():
        choices = list(v.values) if isinstance(v, Choice) else None
        low, high = (min(v.values), max(v.values)) if choices else v
        variables.append(quantity(name, units[name], low=float(low), high=float(high), choices=choices))
    workspace = {"points": [[float(x) for x in p] for p in bound.points], "center": bound.center,
                 "coarseness": bound.coarseness}
    return explorer_table(bound.title, bound.study.path.name, bound.study.device_path.name, variables, objectives,
                          constraints, run.records, run.front,
                          {"position": selection.position, "rule": selection.rule}, [d.data() for d in designs],
                          run.baseline, workspace, embedded=embedded_records(run),
                          sample={"limit": EMBEDDED_LIMIT, "seed": run.seed})


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
