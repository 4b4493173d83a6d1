"""A study: a named sequence of timed steps run under one set of settings, ending in a report."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, is_dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from hapticdesign.files import output_folder
from hapticdesign.studies.steps import STATUS_DONE, Context, Progress, SilentProgress, Step, StepResult, run_steps


@dataclass
class StudyResult:
    """Everything the report shows: settings, step results with timings, when and how long."""

    name: str
    title: str
    intro: str
    settings: dict[str, Any]
    steps: list[StepResult]
    started: str
    seconds: float

    def step(self, key: str) -> StepResult:
        return next(s for s in self.steps if s.key == key)

    def numbers(self) -> dict[str, Any]:
        """Key numbers of the finished steps, by step."""
        return {s.key: s.outcome.numbers for s in self.steps if s.status == STATUS_DONE and s.outcome.numbers}

    def statuses(self) -> dict[str, str]:
        return {s.key: s.status for s in self.steps}


def run_pipeline(name: str, title: str, intro: str, steps: Sequence[Step], settings: Any, work_dir: Path,
              progress: Progress | None = None) -> StudyResult:
    """Run ``steps`` in order with a shared context; scratch files go to ``work_dir``."""
    work_dir = output_folder(work_dir)
    started = datetime.now(timezone.utc).isoformat(timespec="seconds")
    context = Context(settings, work_dir, progress or SilentProgress())
    t0 = time.perf_counter()
    results = run_steps(steps, context)
    plain = asdict(settings) if is_dataclass(settings) else dict(settings)
    return StudyResult(name, title, intro, plain, results, started, time.perf_counter() - t0)
