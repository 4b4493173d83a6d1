"""Shared command-line plumbing: one-line errors with exit status 2, JSON output, vectors.

Every command body runs inside :func:`user_errors`: a :class:`~hapticdesign.errors.UserError`
(or a malformed file) becomes one line on stderr and exit status 2, never a traceback. Library
errors name no flag; :func:`flagged` adds the flags of the running command's options to an
:class:`~hapticdesign.errors.InputError`.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np
import typer
from typer._click.globals import get_current_context

from hapticdesign.errors import InputError, PhysicalConsistencyWarning, RenamedWarning, RunWarning, UserError
from hapticdesign.files import dumps_json, to_jsonable, write_atomically


@contextmanager
def user_errors(strict: bool = False, quiet: bool = False) -> Iterator[None]:
    """Turn user mistakes into ``error: ...`` on stderr and exit 2; consistency and run warnings into one line each,
    as they are raised (a warning before a long run shows before it), an old name's once; other warnings are not
    shown."""

    def show(message, category, *args, **kwargs) -> None:
        if not quiet and issubclass(category, (PhysicalConsistencyWarning, RunWarning, RenamedWarning)):
            typer.echo(f"warning: {message}", err=True)

    with warnings.catch_warnings():
        warnings.simplefilter("always", PhysicalConsistencyWarning)
        warnings.simplefilter("always", RunWarning)
        warnings.simplefilter("once", RenamedWarning)
        warnings.showwarning = show
        try:
            yield
        except UserError as exc:
            typer.echo(f"error: {shortened(flagged(exc))}", err=True)
            raise typer.Exit(2) from None


LONGEST_WORD = 200
"""Most characters of one word (a run without spaces) of an error line: a file path fits, a hostile value of 100,000
characters quoted by some message is cut (the line stays one short line)."""


def shortened(message: str) -> str:
    """``message`` on one line with each word longer than :data:`LONGEST_WORD` cut (``...`` marks the cut)."""
    flat = " ".join(message.splitlines())
    return re.sub(rf"\S{{{LONGEST_WORD + 1},}}", lambda m: m.group()[:LONGEST_WORD - 3] + "...", flat)


def flagged(exc: UserError) -> str:
    """The message of ``exc`` for the command line: an :class:`InputError`'s inputs that are options
    of the running command (input ``allow_long`` is ``--allow-long``) are named by their flags, the
    leading input in place of its name, the others appended in parentheses."""
    message = str(exc)
    context = get_current_context(silent=True)
    if not isinstance(exc, InputError) or context is None:
        return message
    options = {opt for param in context.command.params for opt in param.opts}
    flags = {name: f"--{name.replace('_', '-')}" for name in exc.inputs}
    flags = {name: flag for name, flag in flags.items() if flag in options}
    lead = exc.inputs[0] if exc.inputs else None
    if lead in flags and message.startswith(lead):
        message = flags.pop(lead) + message[len(lead):]
    return f"{message} ({', '.join(flags.values())})" if flags else message


def parse_vector(text: str | None, n: int | None, name: str, most: int = 1000) -> np.ndarray:
    """Parse ``"0.1,0.2,0.3"`` into a vector of length ``n`` (zeros when ``text`` is None), or of any
    length from 1 to ``most`` when ``n`` is None."""
    if text is None:
        return np.zeros(n or 0)
    try:
        values = [float(v) for v in text.replace(" ", "").split(",") if v != ""]
    except ValueError:
        raise UserError(f"--{name}: expected comma-separated numbers, got {text[:60]!r}") from None
    if n is None and not 1 <= len(values) <= most:
        raise UserError(f"--{name}: give 1 to {most} comma-separated numbers, got {len(values)}")
    if n is not None and len(values) != n:
        raise UserError(f"--{name}: expected {n} values, got {len(values)}")
    if not all(math.isfinite(v) for v in values):
        raise UserError(f"--{name}: values must be finite (got {text!r})")
    return np.array(values)


def print_json(value) -> None:
    """One strict JSON object on stdout (a NaN or infinity is a one-line error, not output)."""
    typer.echo(dumps_json(value))


Report = Callable[[str, int, int | None], None]


def duration_text(seconds: float) -> str:
    """A duration for people: ``"40 s"``, ``"3.5 min"``, ``"2.1 h"``."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


class TimeLeft:
    """Estimates of the time left in the steps of a long run, from the pace since each step's first report.

    The first item of a step often carries one-off work (numba loads or compiles its kernels), so the pace
    is measured from the first report on: the estimate is the items still to do at the mean time per item
    since then. It is given once ``min_seconds`` have passed or a tenth of the step is done, whichever
    comes first; before that it is None."""

    def __init__(self, clock: Callable[[], float] | None = None, min_seconds: float = 1.0):
        import time

        self.clock = clock or time.monotonic
        self.min_seconds = min_seconds
        self.first: dict[str, tuple[float, int]] = {}

    def __call__(self, step: str, done: int, total: int | None) -> float | None:
        """Seconds left in ``step`` after ``done`` of ``total`` items, or None while unknown."""
        now = self.clock()
        start, start_done = self.first.setdefault(step, (now, done))
        if total is None or done <= start_done:
            return None
        elapsed = now - start
        if elapsed < self.min_seconds and 10 * done < total:
            return None
        return elapsed / (done - start_done) * (total - done)


def estimate_line(step: str, total: int, seconds_left: float) -> str:
    """The line that states a run's size and the time it will take, once its pace is known."""
    return f"{step}: {total} in all; at the pace so far, about {duration_text(seconds_left)} left"


LOG_AFTER = 2.0
"""Seconds of a step after which its progress is written to a log (a step that ends sooner needs none)."""


@contextmanager
def progress_bar(enabled: bool) -> Iterator[Report | None]:
    """Progress of long work on stderr, fed by ``report(step, done, total)`` (``total`` None: unknown).

    Each step with a known total first states its size and the time it will take, once its pace is known
    (:class:`TimeLeft`). On a terminal a rich bar follows with the time elapsed and the time left (the step's name
    whole, wrapped rather than cut where the terminal is narrow); in a log or
    a pipe one line each tenth, with the time left, once the step has run :data:`LOG_AFTER` seconds (a step that
    ends sooner writes nothing). Yields None (nothing on stderr) when ``enabled`` is false
    (``--quiet`` or ``--json``), so progress never mixes with a command's output on stdout."""
    from rich.console import Console

    if not enabled:
        yield None
        return
    console = Console(stderr=True)
    left = TimeLeft()
    estimated: set[str] = set()

    def first_estimate(step: str, done: int, total: int | None, seconds: float | None, say) -> None:
        if seconds is not None and total is not None and step not in estimated and done < total:
            estimated.add(step)
            say(estimate_line(step, total, seconds))

    if not console.is_terminal:
        tenths: dict[str, set[int]] = {}
        began: dict[str, float] = {}
        last = [left.clock()]  # the time of the last report: a step's work began after the report before its first

        def lines(step: str, done: int, total: int | None) -> None:
            seconds = left(step, done, total)
            now = left.clock()
            began.setdefault(step, last[0])
            last[0] = now
            if now - began[step] < LOG_AFTER:
                return
            first_estimate(step, done, total, seconds, lambda text: typer.echo(text, err=True))
            if total is None:
                return
            tenth = (10 * done) // max(total, 1)
            if tenth not in tenths.setdefault(step, set()):
                tenths[step].add(tenth)
                after = f", about {duration_text(seconds)} left" if seconds is not None and done < total else ""
                typer.echo(f"{step}: {done} of {total}{after}", err=True)

        yield lines
        return
    from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn,
                               TimeRemainingColumn)
    from rich.table import Column

    title = TextColumn("{task.description}", markup=False, table_column=Column(overflow="fold", ratio=1))
    with Progress(title, BarColumn(bar_width=20), MofNCompleteColumn(), TimeElapsedColumn(), TextColumn("left"),
                  TimeRemainingColumn(), console=console, transient=True, expand=True) as bars:
        tasks: dict[str, int] = {}

        def report(step: str, done: int, total: int | None) -> None:
            if step not in tasks:
                tasks[step] = bars.add_task(step, total=total)
            bars.update(tasks[step], completed=done, total=total)
            first_estimate(step, done, total, left(step, done, total), bars.console.print)

        yield report


@contextmanager
def activity(enabled: bool, description: str) -> Iterator[None]:
    """An indeterminate progress bar for a step that cannot report how far it is (see :func:`progress_bar`)."""
    with progress_bar(enabled) as report:
        if report is not None:
            report(description, 0, None)
        yield


def note(message: str, quiet: bool) -> None:
    """An informational line on stderr (files written, ...), silenced by ``--quiet``."""
    if not quiet:
        typer.echo(message, err=True)


def fail(message: str) -> None:
    """Raise a :class:`UserError` (for use in option callbacks)."""
    raise UserError(message)


__all__ = ["activity", "fail", "note", "parse_vector", "print_json", "progress_bar", "to_jsonable", "user_errors",
           "write_atomically"]


def joint_units(device) -> list[dict[str, str]]:
    """Per coordinate: its unit and those of its torque (force), stiffness and damping (revolute
    joints in rad, N m, N m/rad, N m s/rad; prismatic joints in m, N, N/m, N s/m)."""
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.model.mechanism import JointType

    types = device.mechanism.joint_types
    coordinates = device.mechanism.coordinates
    out = []
    for name in configuration_of(device).names:
        prismatic = types[coordinates.index(name)] == JointType.PRISMATIC
        out.append({"joint": name, "position": "m" if prismatic else "rad", "effort": "N" if prismatic else "N m",
                    "stiffness": "N/m" if prismatic else "N m/rad", "damping": "N s/m" if prismatic else "N m s/rad"})
    return out
