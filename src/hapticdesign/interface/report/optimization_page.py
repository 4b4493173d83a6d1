"""The HTML report of ``optimize``: the study, the front, the selected design beside the device file's design with
its picture and index maps, and the files beside it; for a run without a feasible design (:func:`render_failure`),
why, the closest designs and the device file's design. One document, inline styles, base64 PNG figures, no
scripts; every user string (names, expressions, reasons, the device's name) is escaped."""

from __future__ import annotations

import base64
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from html import escape

from hapticdesign.interface.report.html import STYLE
from hapticdesign.interface.report.tables import cell_text
from hapticdesign.optimization.study_evaluation import SPREAD_COLUMNS
from hapticdesign.optimization.study_file import Choice
from hapticdesign.optimization.study_methods import method_of
from hapticdesign.optimization.study_outputs import Selection, at_bounds, changes, closest_designs, with_unit
from hapticdesign.optimization.study_run import Record, StudyRun, constraint_labels


@dataclass(frozen=True)
class Picture:
    """A PNG figure of the report with its caption."""

    png: bytes
    caption: str


def _image(picture: Picture) -> str:
    data = base64.b64encode(picture.png).decode("ascii")
    return (f'<figure><img alt="{escape(picture.caption)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{escape(picture.caption)}</figcaption></figure>")


TEXT = ' class="text"'


def _table(title: str, columns: list[str], rows: list[list], highlight: int | None = None) -> str:
    head = "".join(f"<th>{escape(c)}</th>" for c in columns)
    body = []
    for k, row in enumerate(rows):
        style = ' style="background:#fde2e2"' if k == highlight else ""
        cells = "".join(f"<td{TEXT if isinstance(v, str) else ''}>{escape(cell_text(v))}</td>" for v in row)
        body.append(f"<tr{style}>{cells}</tr>")
    wide = ' class="wide"' if len(columns) > 8 else ""
    return (f'<div class="table-wrap"><table{wide}><caption>{escape(title)}</caption><thead><tr>{head}</tr></thead>'
            f"<tbody>{''.join(body)}</tbody></table></div>")


def _options(options: dict) -> str:
    return ", ".join(f"{k} = {v}" for k, v in options.items())


def _study_rows(run: StudyRun, coarseness: str, units: Mapping[str, str]) -> str:
    spec = run.spec
    over = f" of {coarseness}" if coarseness else ""
    variables = [[name, units.get(name, ""), *(("choice of " + ", ".join(f"{v:g}" for v in var.values), "") if isinstance(var, Choice)
                          else (f"{var[0]:g}", f"{var[1]:g}"))] for name, var in spec.variables.items()]
    objectives = [[o.name, o.index, units.get(o.name, ""), _options(o.options), o.reduce + over, o.sense]
                  for o in spec.objectives]
    constraints = [[c.label + (f" ({_options(c.options)})" if getattr(c, "options", None) else ""),
                    units.get(c.label, ""), "" if c.at_least is None else c.at_least, "" if c.at_most is None else c.at_most]
                   for c in spec.constraints]
    parts = [_table("Variables", ["variable", "unit", "low or choices", "high"], variables),
             _table("Objectives (reduced over the workspace)", ["name", "index", "unit", "options", "reduction",
                                                                  "sense"], objectives)]
    if constraints:
        parts.append(_table("Constraints", ["constrained value", "unit", ">=", "<="], constraints))
    parts.append(f"<p>{escape(method_of(spec).describe(run), quote=False)}</p>")
    return "".join(parts)


NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")
"""A number in a reason (not the digits of a name such as ``l1``)."""


def reason_kind(reason: str) -> tuple[str, list[float]]:
    """A reason without its numbers (each shown as ``#``) and the numbers, in order: ``"l1 + l2 = 0.300198, not <=
    0.3"`` is ``("l1 + l2 = #, not <= #", [0.300198, 0.3])``."""
    return NUMBER.sub("#", reason), [float(n) for n in NUMBER.findall(reason)]


def _reasons(run: StudyRun) -> str:
    """Infeasible designs grouped by the kind of reason (numbers aside: the designs of one kind differ only in
    them), the most frequent first, with the range of each number over the group."""
    groups: dict[str, list[list[float]]] = {}
    for r in run.records:
        if not r.feasible:
            kind, numbers = reason_kind(r.reason.split(":")[0])
            groups.setdefault(kind, []).append(numbers)
    if not groups:
        return "<p>Every evaluated design was feasible.</p>"
    rows = []
    for kind, numbers in sorted(groups.items(), key=lambda kv: (-len(kv[1]), kv[0]))[:12]:
        columns = list(zip(*numbers)) if len({len(n) for n in numbers}) == 1 else []
        ranges = "; ".join(f"{min(c):.6g}" if min(c) == max(c) else f"{min(c):.6g} to {max(c):.6g}" for c in columns)
        rows.append([kind, len(numbers), ranges])
    return _table("Why designs were infeasible, by kind of reason (# stands for the numbers; evaluations.csv has "
                  "each design's reason)", ["reason", "designs", "numbers (#, in order: range)"], rows)


def _baseline(run: StudyRun, units: Mapping[str, str], chosen: Record | None = None) -> str:
    """The device file's design: what to know of it and, in a table, its variables, objectives and constrained values
    (beside ``chosen``'s, with each objective's change from it, gained or lost, and ``chosen``'s variables at a bound
    of their range)."""
    spec, base = run.spec, run.baseline
    if base is None:
        words = f"No device file's design to compare: {run.baseline_note}."
    else:
        words = ("The device file's design is " + ("feasible" if base.feasible else f"not feasible: {base.reason}")
                 + (f"; {run.baseline_note}" if run.baseline_note else "") + ".")
    text = f"<p>{escape(words, quote=False)}</p>"
    names, labels = [o.name for o in spec.objectives], constraint_labels(spec)
    if chosen is None:
        if base is None:
            return text
        rows = ([[name, base.values[name]] for name in spec.variables] + [[*row] for row in zip(names, base.objectives)]
                + [[*row] for row in zip(labels, base.constraints)])
        rows = [[row[0], units.get(row[0], ""), *row[1:]] for row in rows]
        return text + _table("The device file's design", ["quantity", "unit", "device file's design"], rows)
    bounds = at_bounds(spec, chosen.values)
    moved = changes(run, chosen)

    def old(attribute: str) -> tuple:
        return (None,) * len(getattr(chosen, attribute)) if base is None else getattr(base, attribute)

    rows = ([[name, None if base is None else base.values[name], chosen.values[name], "", bounds.get(name, "")]
             for name in spec.variables]
            + [[name, o, n, "", ""] for name, o, n in zip(names, old("objectives"), chosen.objectives)]
            + [[label, o, n, "", ""] for label, o, n in zip(labels, old("constraints"), chosen.constraints)])
    for k, change in enumerate(moved):  # the objectives' rows follow the variables'
        percent = f"{change.percent:+.3g} %" if math.isfinite(change.percent) else ""
        rows[len(spec.variables) + k][3:] = [percent, change.verdict]
    rows = [[row[0], units.get(row[0], ""), *row[1:]] for row in rows]
    return text + _table("The selected design beside the device file's design (selected.yaml)",
                         ["quantity", "unit", "device file's design", "selected", "change",
                          "gained or lost; at a bound"], rows)


def _document(title: str, body: list[str], files: list[str]) -> str:
    """One HTML document of ``body``'s parts and the list of ``files``."""
    parts = [*body, "<h2>Files</h2><ul class=\"files\">", *(f"<li>{escape(f)}</li>" for f in files), "</ul>"]
    return (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>{escape(title)}</title>'
            f"<style>{STYLE}</style></head><body>{''.join(parts)}</body></html>\n")


def render(run: StudyRun, selection: Selection, title: str, pareto: Picture, pictures: list[Picture],
           files: list[str], coarseness: str = "", spread: list[list] | None = None,
           units: Mapping[str, str] | None = None) -> str:
    """The report as one HTML document; ``coarseness`` says how coarse the workspace grid is (``27 points, grid 3``),
    ``spread`` gives the selected design's pose indices over the points
    (:meth:`~hapticdesign.optimization.study_evaluation.BoundStudy.spread_rows`), ``units`` each quantity's unit
    (:meth:`~hapticdesign.optimization.study_evaluation.BoundStudy.units`), shown in the tables' headers or a unit
    column."""
    spec = run.spec
    units = units or {}
    names = [o.name for o in spec.objectives]
    columns = ["design", *(with_unit(c, units) for c in (*names, *spec.variables, *constraint_labels(spec)))]
    rows = [[n, *run.records[k].objectives, *(run.records[k].values[v] for v in spec.variables),
             *run.records[k].constraints] for n, k in enumerate(run.front, start=1)]
    chosen = run.records[selection.record]
    over = [_table(f"The selected design's indices over the workspace ({coarseness}): at the box's centre, median, "
                   "mean and the extremes with the points where they are taken", ["index", "unit", *SPREAD_COLUMNS],
                   spread)] if spread else []
    body = [f"<h1>Optimization study: {escape(title)}</h1>", "<h2>Study</h2>", _study_rows(run, coarseness, units),
            "<h2>Pareto front</h2>", _image(pareto),
            _table(f"The front: {len(run.front)} feasible, non-dominated designs (front.csv)", columns, rows,
                   selection.position),
            "<h2>Selected design</h2>",
            f"<p>Design {selection.position + 1} of the front, by the {escape(selection.rule)}; as a device file: "
            "selected.yaml.</p>",
            _baseline(run, units, chosen), *over,
            *(_image(p) for p in pictures),
            "<h2>Infeasible designs</h2>", _reasons(run)]
    return _document(title, body, files)


def _closest(run: StudyRun, units: Mapping[str, str]) -> str:
    """The designs closest to feasible (:func:`~hapticdesign.optimization.study_outputs.closest_designs`) in a table."""
    spec = run.spec
    closest = closest_designs(run)
    if not closest:
        return ("<p>No design has constrained values: each misses a workspace point or the device file refuses it (the "
                "sentence above names the design that reaches the most points).</p>")
    columns = ["evaluation", "why not feasible", "scaled violation",
               *(with_unit(c, units) for c in (*(o.name for o in spec.objectives), *spec.variables,
                                               *constraint_labels(spec)))]
    rows = [[k + 1, run.records[k].reason or "meets the constraints; the keep filters remove it",
             run.records[k].violation, *run.records[k].objectives, *(run.records[k].values[v] for v in spec.variables),
             *run.records[k].constraints] for k in closest]
    return _table(f"The {len(rows)} designs closest to feasible (least total scaled constraint violation; "
                  "evaluations.csv has every design)", columns, rows)


def render_failure(run: StudyRun, why: str, title: str, files: list[str], coarseness: str = "",
                   units: Mapping[str, str] | None = None) -> str:
    """The report of a run without a feasible design as one HTML document: ``why`` (the run's one-line error), the
    closest designs, the device file's design and the reasons counted by kind; ``coarseness`` and ``units`` as for
    :func:`render`."""
    units = units or {}
    body = [f"<h1>Optimization study: {escape(title)}</h1>", "<h2>Study</h2>", _study_rows(run, coarseness, units),
            "<h2>No feasible design</h2>", f"<p>{escape(why, quote=False)}</p>", _closest(run, units),
            "<h2>The device file's design</h2>", _baseline(run, units),
            "<h2>Infeasible designs</h2>", _reasons(run)]
    return _document(title, body, files)
