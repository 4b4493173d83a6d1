"""The HTML report of ``optimize``, which is the study's design explorer: every evaluated design in the objective
space and in parallel coordinates (click to pick a design, box, lasso or brush to filter), the card of the picked
design (its numbers, picture, index maps and the commands that reproduce it), up to four pinned designs compared, the
state in the address's hash; then the study, the front, the selected design beside the device file's design with its
picture and index maps, why designs were infeasible, and the files beside it. For a run without a feasible design
(:func:`render_failure`): why, the closest designs and the device file's design, a page without scripts.

The page opens from disk with no server and no network: its data is JSON in a ``<script type="application/json">``
element (:func:`hapticdesign.escape.script_json`), its own script is inline (``explorer.js`` next to this module) and
Plotly.js is the installed ``plotly`` package's, written once beside the page (:data:`PLOTLY`, loaded by a relative
``<script src>``: inlined, its 4.8 MB would be copied into every report). A Content-Security-Policy allows only those
two scripts and no network request. Every user string (names, expressions, reasons, the device's name) is escaped
here, and set as text by the script."""

from __future__ import annotations

import base64
import hashlib
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from html import escape
from importlib.resources import files as package_files

from hapticdesign.analysis.metrics.indices import compliance_line
from hapticdesign.escape import script_json
from hapticdesign.interface.report.html import STYLE
from hapticdesign.interface.report.tables import cell_text
from hapticdesign.optimization.study_file import Choice
from hapticdesign.optimization.study_methods import method_of
from hapticdesign.optimization.study_outputs import (SPREAD_COLUMNS, Selection, at_bounds, changes, closest_designs,
                                                     with_unit)
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


def _table(title: str, columns: list[str], rows: list[list], highlight: int | None = None, ident: str = "") -> str:
    head = "".join(f"<th>{escape(c)}</th>" for c in columns)
    body = []
    for k, row in enumerate(rows):
        style = ' style="background:#fde2e2"' if k == highlight else ""
        cells = "".join(f"<td{TEXT if isinstance(v, str) else ''}>{escape(cell_text(v))}</td>" for v in row)
        body.append(f"<tr{style}>{cells}</tr>")
    wide = ' class="wide"' if len(columns) > 8 else ""
    ident = f' id="{escape(ident)}"' if ident else ""
    return (f'<div class="table-wrap"><table{ident}{wide}><caption>{escape(title)}</caption><thead><tr>{head}</tr></thead>'
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
    if run.compliance:
        parts.append(f'<p id="compliance">{escape(compliance_line(run.compliance), quote=False)} (the compliance between '
                     "the motors and the handle the device file gives: its actuators' transmission_stiffness, its "
                     "links' sections)</p>")
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


def _document(title: str, body: list[str], files: list[str], scripts: str = "", policy: str = "") -> str:
    """One HTML document of ``body``'s parts, the list of ``files`` and the ``scripts`` at the end, under the
    Content-Security-Policy ``policy``."""
    parts = [*body, "<h2>Files</h2><ul class=\"files\">", *(f"<li>{escape(f)}</li>" for f in files), "</ul>"]
    meta = f'<meta http-equiv="Content-Security-Policy" content="{escape(policy)}">' if policy else ""
    return (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">{meta}<title>{escape(title)}</title>'
            f'<link rel="icon" href="data:,"><style>{STYLE}{EXPLORER_STYLE if scripts else ""}</style></head>'
            f"<body>{''.join(parts)}{scripts}</body></html>\n")


PLOTLY = "plotly.min.js"
"""Plotly.js as the report loads it, from the output folder (:func:`plotly_js`)."""

EXPLORER_STYLE = """
#explorer .toolbar { display: flex; flex-wrap: wrap; gap: .4em 1em; align-items: center; font-size: .9em; }
#explorer select { max-width: 22em; }
#filter-status { color: #444; }
#explorer-note { color: #a01818; }
#parallel { display: block; border: 1px solid #dde; background: #fff; cursor: crosshair; margin: .4em 0; }
#parallel-tip { position: absolute; background: #222; color: #fff; font-size: .8em; padding: .15em .4em;
                border-radius: 3px; pointer-events: none; }
#design-card { border: 2px solid #f39c12; border-radius: 6px; padding: .2em 1em 1em; margin: 1em 0; }
.card-row { display: flex; flex-wrap: wrap; gap: 1.2em; align-items: flex-start; }
.card-row > * { flex: 0 0 auto; margin: 0; }
.card-row figure { max-width: 400px; }
.card-row canvas { border: 1px solid #dde; background: #fbfbfd; cursor: grab; }
.maps { display: flex; flex-wrap: wrap; gap: .6em; }
.map { min-width: 300px; }
#compare tr.differs td { background: #fff6d6; }
#compare td.best { font-weight: bold; color: #1a6b1a; }
#compare figure.pinned { margin: 0; }
#front-table tbody tr { cursor: pointer; }
#front-table tbody tr:hover { background: #eef4ff; }
"""


def plotly_js() -> str:
    """The installed ``plotly`` package's Plotly.js (minified), which the report loads from :data:`PLOTLY`."""
    from plotly.offline import get_plotlyjs

    return get_plotlyjs()


def _explorer_script() -> str:
    return package_files("hapticdesign.interface.report").joinpath("explorer.js").read_text(encoding="utf-8")


def shown_count(data: dict) -> str:
    """How many of the evaluated designs the page holds, in words (the explorer's ``data``,
    :func:`~hapticdesign.optimization.study_explorer.explorer_table`)."""
    shown, count, front = len(data["evaluations"]["evaluation"]), data["count"], len(data["front"])
    if shown == count:
        return f"This page holds all {count:,} evaluated designs."
    sample = data["sample"]
    return (f"This page holds {shown:,} of the {count:,} evaluated designs: the front's {front:,} (and the polished "
            f"ones) and a sample of {sample['limit']:,} of the others, drawn with the run's seed {sample['seed']} "
            "(evaluations.csv has every one; hapticdesign explore computes the card of any design shown).")


def _explorer(data: dict) -> tuple[str, str, str]:
    """The explorer's section, its scripts (the data, Plotly.js, the explorer's own) and the page's policy: the
    inline script by its hash, Plotly.js from the page's folder (a ``file:`` address, or the server's own when
    ``hapticdesign explore`` serves the folder, which also answers the cards: ``connect-src 'self'``), no other
    network. ``'unsafe-eval'`` lets those two scripts build functions from their own text: Plotly's WebGL traces (the
    large scatter plots, ``scattergl``) compile their drawing commands so and show "WebGL is not supported" without it;
    no inline script or handler runs (a user string in the page stays text)."""
    code = _explorer_script()
    digest = base64.b64encode(hashlib.sha256(code.encode("utf-8")).digest()).decode("ascii")
    policy = (f"default-src 'none'; script-src 'sha256-{digest}' 'unsafe-eval' file: 'self'; connect-src 'self'; "
              "style-src 'unsafe-inline'; img-src data: blob:; font-src data:")
    shown, count = len(data["evaluations"]["evaluation"]), data["count"]
    section = (
        '<section id="explorer"><h2>Explore the designs</h2>'
        '<p class="note">Every evaluated design: click a point or a line to pick a design (its card follows), drag a '
        "box or a lasso on a plot or along an axis of the parallel coordinates to filter (a click on an axis clears "
        "its range), pin up to four designs to compare them. The address keeps the view: a link reopens it. "
        "Each quantity's unit is in brackets (a variable's from its device file). <code>window.hdExplorer</code> scripts it (docs/optimization.md)."
        f'</p><p id="shown-count" class="note" data-shown="{shown}" data-count="{count}">'
        f"{escape(shown_count(data))}</p>"
        '<p id="explorer-note"></p>'
        '<div class="toolbar"><label>x <select id="x-axis"></select></label><label>y <select id="y-axis"></select>'
        '</label><button id="clear-filters" type="button">Clear filters</button><span id="filter-status"></span></div>'
        '<div id="objective-space"></div><div id="pairs"></div>'
        "<h3>Parallel coordinates of the feasible designs (the front in blue)</h3>"
        '<canvas id="parallel" height="380" width="1000"></canvas><div id="parallel-tip" hidden></div>'
        '<h3>The picked design</h3><div id="design-card"></div>'
        '<h3>Compare</h3><div id="compare"></div></section>')
    scripts = (f'<script type="application/json" id="explorer-data">{script_json(data)}</script>'
               f'<script src="{PLOTLY}"></script><script>{code}</script>')
    return section, scripts, policy


def render(run: StudyRun, selection: Selection, title: str, pareto: Picture, pictures: list[Picture],
           files: list[str], explorer: dict, coarseness: str = "", spread: list[list] | None = None,
           units: Mapping[str, str] | None = None) -> str:
    """The report as one HTML document: the explorer of ``explorer``'s data
    (:func:`~hapticdesign.optimization.study_explorer.explorer_data`), then the static report; ``coarseness`` says how
    coarse the workspace grid is (``27 points, grid 3``), ``spread`` gives the selected design's pose indices over the
    points (:func:`~hapticdesign.optimization.study_outputs.spread_rows`), ``units`` each quantity's unit
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
    body = ["<h2>Study</h2>",
            _study_rows(run, coarseness, units),
            "<h2>Pareto front</h2>", _image(pareto),
            _table(f"The front: {len(run.front)} feasible, non-dominated designs (front.csv; click a row to pick it)",
                   columns, rows, selection.position, ident="front-table"),
            "<h2>Selected design</h2>",
            f"<p>Design {selection.position + 1} of the front, by the {escape(selection.rule)}; as a device file: "
            "selected.yaml.</p>",
            _baseline(run, units, chosen), *over,
            *(_image(p) for p in pictures),
            "<h2>Infeasible designs</h2>", _reasons(run)]
    return explorer_page(title, f"Optimization study: {title}", explorer, body, files)


def explorer_page(title: str, heading: str, explorer: dict, body: list[str], files: list[str]) -> str:
    """A design explorer as one HTML document, the one page every study's designs open in (``optimize``'s report,
    ``rcube optimize``'s, ``study phantom``'s campaign): the ``heading``, the explorer of ``explorer``'s data
    (:func:`~hapticdesign.optimization.study_explorer.explorer_table`), then ``body``'s parts (HTML, every user string
    in them escaped) and the list of ``files`` beside it; Plotly.js is loaded from :data:`PLOTLY` beside the page."""
    section, scripts, policy = _explorer(explorer)
    return _document(title, [f"<h1>{escape(heading)}</h1>", section, *body], files, scripts, policy)


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
