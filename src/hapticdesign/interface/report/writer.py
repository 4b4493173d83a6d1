"""Write a study's report folder: report.html, tables/*.csv, figures/*.png|svg, pages/*.html, summary.json."""

from __future__ import annotations

import json
from pathlib import Path

from hapticdesign.files import output_folder, to_jsonable, write_atomically
from hapticdesign.interface.report.html import render
from hapticdesign.interface.report.tables import csv_text
from hapticdesign.interface.report.versions import versions
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
    found = versions()
    html = render(study, found,
                  lambda step, table: f"tables/{_stem(step.key, table.name)}.csv",
                  lambda step, figure: f"figures/{_stem(step.key, figure.name)}",
                  lambda step, page: f"pages/{_stem(step.key, page.name)}.html")
    report = out / "report.html"
    write_atomically(report, html)
    write_atomically(out / "summary.json", json.dumps(to_jsonable(summary(study, report)), indent=2))
    return report


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
