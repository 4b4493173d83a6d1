"""Study steps: what one step produces (text, tables, figures, key numbers) and a timed runner.

A step is a function ``step(context) -> Outcome``. The runner times it and records one of four
states: ``done``; ``not available`` when an earlier step it builds on did not finish (the step
raised :class:`NotAvailable`; the report says so and shows no numbers); ``skipped`` when the
device cannot have what the step computes (the step raised :class:`Skipped` with the reason, e.g.
no symbolic tree equations for a closed loop); ``failed`` with the one-line reason when the engine raised. Steps import the engines plainly, so a renamed engine
function fails the tests instead of showing "not available" in a report. A study therefore always ends in a report.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from hapticdesign.files import figure_bytes

STATUS_DONE = "done"
STATUS_MISSING = "not available"
STATUS_FAILED = "failed"
STATUS_SKIPPED = "skipped"


class NotAvailable(Exception):
    """A step cannot run because an earlier step it builds on did not finish."""


class Skipped(Exception):
    """A step does not apply to this device; the message says why."""


@dataclass
class Table:
    """A table for the report and for ``tables/<name>.csv``."""

    name: str
    title: str
    columns: list[str]
    rows: list[list[Any]]
    note: str = ""


@dataclass
class Figure:
    """A figure as PNG bytes and SVG text (for the report and ``figures/<name>.png|svg``)."""

    name: str
    title: str
    png: bytes
    svg: str
    caption: str = ""


def figure_from_matplotlib(fig, name: str, title: str, caption: str = "") -> Figure:
    """Render a matplotlib figure to PNG and SVG, then close it."""
    import matplotlib.pyplot as plt

    png = figure_bytes(fig, "png", dpi=110, bbox_inches="tight")
    svg = figure_bytes(fig, "svg", bbox_inches="tight").decode("utf-8")
    plt.close(fig)
    return Figure(name, title, png, svg, caption)


def figure_from_files(stem, name: str, title: str, caption: str = "") -> Figure:
    """A figure an engine already wrote as ``<stem>.png`` and ``<stem>.svg``."""
    stem = Path(stem)
    return Figure(name, title, stem.with_suffix(".png").read_bytes(), stem.with_suffix(".svg").read_text(), caption)


@dataclass
class Page:
    """A self-contained HTML page beside the report (``pages/<name>.html``), e.g. the interactive device view."""

    name: str
    title: str
    html: str


@dataclass
class Explorer:
    """A step's designs in the design explorer, the page every study opens in, written beside the report as
    ``explorer/<step>/report.html``: its ``title``, the explorer's ``data``
    (:func:`~hapticdesign.optimization.study_explorer.explorer_table`), the ``files`` beside the page that the
    cards' commands read (path inside the folder -> text) and ``paragraphs`` under the explorer."""

    title: str
    data: dict
    files: dict[str, str] = field(default_factory=dict)
    paragraphs: list[str] = field(default_factory=list)


@dataclass
class Outcome:
    """What a finished step contributes: prose, equations or listings, tables, figures, pages, key numbers and its
    designs in the design explorer."""

    summary: str = ""
    paragraphs: list[str] = field(default_factory=list)
    listings: list[tuple[str, str]] = field(default_factory=list)
    tables: list[Table] = field(default_factory=list)
    figures: list[Figure] = field(default_factory=list)
    pages: list[Page] = field(default_factory=list)
    numbers: dict[str, Any] = field(default_factory=dict)
    explorer: Explorer | None = None


@dataclass
class StepResult:
    """A step after the runner: its state, duration and outcome."""

    key: str
    title: str
    status: str
    seconds: float
    outcome: Outcome
    reason: str = ""


class Progress(Protocol):
    """What the runner reports to (a rich progress bar on the command line, or nothing)."""

    def begin(self, title: str) -> None: ...

    def update(self, done: int, total: int) -> None: ...

    def end(self, result: StepResult) -> None: ...


class SilentProgress:
    def begin(self, title: str) -> None:
        pass

    def update(self, done: int, total: int) -> None:
        pass

    def end(self, result: StepResult) -> None:
        pass


@dataclass
class Context:
    """Shared by the steps of one study: settings, scratch folder, results of earlier steps."""

    settings: Any
    work_dir: Path
    progress: Progress
    shared: dict[str, Any] = field(default_factory=dict)

    def update(self, done: int, total: int) -> None:
        self.progress.update(done, total)


@dataclass(frozen=True)
class Step:
    key: str
    title: str
    run: Callable[[Context], Outcome]


def run_steps(steps: Sequence[Step], context: Context) -> list[StepResult]:
    """Run the steps in order, timing each; missing engines and engine errors are recorded, not raised."""
    results = []
    for step in steps:
        context.progress.begin(step.title)
        start = time.perf_counter()
        try:
            outcome, status, reason = step.run(context), STATUS_DONE, ""
        except NotAvailable as exc:
            outcome, status, reason = Outcome(), STATUS_MISSING, str(exc)
        except Skipped as exc:
            outcome, status, reason = Outcome(), STATUS_SKIPPED, str(exc)
        except Exception as exc:  # an engine error ends this step only; the report shows it
            last = traceback.extract_tb(exc.__traceback__)[-1]
            outcome, status = Outcome(), STATUS_FAILED
            reason = f"{type(exc).__name__}: {exc} (at {last.filename.rsplit('/', 1)[-1]}:{last.lineno})"
        result = StepResult(step.key, step.title, status, time.perf_counter() - start, outcome, reason)
        context.progress.end(result)
        results.append(result)
    return results
