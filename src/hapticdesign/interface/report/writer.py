"""Write a study's report folder: report.html, tables/*.csv, figures/*.png|svg, pages/*.html, summary.json and, for a
step with designs to explore, explorer/<step>/report.html (the design explorer, with Plotly.js and its cards' files)."""

from __future__ import annotations

import json
from pathlib import Path

from hapticdesign.files import output_folder, to_jsonable, write_atomically
from hapticdesign.interface.report.html import render
from hapticdesign.interface.report.tables import csv_text
from hapticdesign.interface.report.optimization_page import PLOTLY
from hapticdesign.interface.report.seed_explorers import REPORT, step_page, write_explorer
from hapticdesign.interface.report.versions import versions
from hapticdesign.studies.steps import Explorer
from hapticdesign.studies.study import StudyResult


def _stem(step_key: str, name: str) -> str:
    return f"{step_key}_{name}"


def write_report(study: StudyResult, out: Path) -> Path:
    """Write every artefact of ``study`` under ``out`` and return the path of ``report.html``."""
    out = Path(out)
    output_folder(out / "tables")
    output_folder(out / "figures")
    for step in study.steps:
        for table in step.outcome.tables:
            write_atomically(out / "tables" / f"{_stem(step.key, table.name)}.csv", csv_text(table))
        for figure in step.outcome.figures:
            stem = out / "figures" / _stem(step.key, figure.name)
            write_atomically(stem.with_suffix(".png"), figure.png)
            write_atomically(stem.with_suffix(".svg"), figure.svg)
        for page in step.outcome.pages:
            write_atomically(out / "pages" / f"{_stem(step.key, page.name)}.html", page.html)
        if step.outcome.explorer is not None:
            _write_explorer(out / _explorer_folder(step.key), step.outcome.explorer)
    found = versions()
    html = render(study, found,
                  lambda step, table: f"tables/{_stem(step.key, table.name)}.csv",
                  lambda step, figure: f"figures/{_stem(step.key, figure.name)}",
                  lambda step, page: f"pages/{_stem(step.key, page.name)}.html",
                  lambda step: f"{_explorer_folder(step.key)}/{REPORT}")
    report = out / "report.html"
    write_atomically(report, html)
    write_atomically(out / "summary.json", json.dumps(to_jsonable(summary(study, report)), indent=2))
    return report


def _explorer_folder(step_key: str) -> str:
    return f"explorer/{step_key}"


def _write_explorer(folder: Path, explorer: Explorer) -> None:
    """A step's designs in the design explorer: the files its cards read, then report.html and Plotly.js."""
    for name, text in explorer.files.items():
        write_atomically(folder / name, text)
    files = sorted([*explorer.files, REPORT, PLOTLY])
    write_explorer(folder, step_page(explorer.title, explorer.data, explorer.paragraphs, files))


def summary(study: StudyResult, report: Path) -> dict:
    """The study's key numbers, statuses and timings (what ``--json`` prints)."""
    return {
        "study": study.name,
        "report": str(Path(report).resolve()),
        "seconds": round(study.seconds, 3),
        "steps": {s.key: {"status": s.status, "seconds": round(s.seconds, 3), **({"reason": s.reason} if s.reason else {})}
                  for s in study.steps},
        "numbers": study.numbers(),
    }
