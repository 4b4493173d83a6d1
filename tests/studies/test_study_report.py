"""The step runner and the report writer on hand-made steps: missing engines, engine errors, files."""

from __future__ import annotations

import csv
import json

from hapticdesign.interface.report import write_report
from hapticdesign.studies.plots import plt
from hapticdesign.studies.steps import (
    STATUS_DONE,
    STATUS_FAILED,
    STATUS_MISSING,
    NotAvailable,
    Outcome,
    Step,
    Table,
    figure_from_matplotlib,
)
from hapticdesign.studies.study import run_pipeline


def _done(ctx):
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    return Outcome(summary="ok", tables=[Table("t", "a table", ["x", "y"], [[1, 0.1 + 0.2], ["b", None]])],
                   figures=[figure_from_matplotlib(fig, "f", "a figure")], numbers={"x": 0.1 + 0.2})


def _missing(ctx):
    raise NotAvailable("this step builds on hapticdesign.no_such_engine, which did not finish")


def _broken(ctx):
    raise ZeroDivisionError("boom")


def test_report_shows_each_state_honestly(tmp_path):
    steps = [Step("a", "Done step", _done), Step("b", "Missing step", _missing), Step("c", "Broken step", _broken)]
    result = run_pipeline("demo", "A study", "intro", steps, {"scale": "smoke"}, tmp_path / "work")
    assert result.statuses() == {"a": STATUS_DONE, "b": STATUS_MISSING, "c": STATUS_FAILED}
    assert "ZeroDivisionError: boom" in result.step("c").reason
    report = write_report(result, tmp_path)
    html = report.read_text()
    assert "did not finish" in html and "hapticdesign.no_such_engine" in html
    assert "<script" not in html and "http" not in html.replace("http-equiv", "")
    with open(tmp_path / "tables" / "a_t.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows == [["x", "y"], ["1", repr(0.1 + 0.2)], ["b", ""]]  # full precision in the CSV
    assert (tmp_path / "figures" / "a_f.png").exists() and (tmp_path / "figures" / "a_f.svg").exists()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["numbers"] == {"a": {"x": 0.1 + 0.2}}  # no numbers from steps that did not finish
    assert summary["steps"]["b"]["status"] == STATUS_MISSING
