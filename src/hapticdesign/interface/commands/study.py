"""Commands ``study phantom``, ``study rcube`` (the seeds end to end, one report each) and ``demo``."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import nullcontext
from pathlib import Path
from typing import Optional

import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import TimeLeft, duration_text, print_json, user_errors
from hapticdesign.interface.options import DEVICE, FORCE, FORCE_HINT, JSON_OUT, PRESET, QUIET, SEED
from hapticdesign.workload import allow_large
from hapticdesign.studies.steps import STATUS_DONE, STATUS_FAILED, STATUS_SKIPPED, StepResult

study_app = typer.Typer(
    help="The seeds' pipelines end to end (seed 000 ch. 2-4, seed 001 ch. 4-7), each ending in one HTML report.",
    no_args_is_help=True,
)

QUICK = typer.Option(False, "--quick", help="A small version that finishes in a few minutes.")
OUT = typer.Option(..., "--out", help="Folder for report.html, tables/*.csv, figures/*.png|svg and summary.json.")
SCALE = typer.Option(None, "--scale", hidden=True, help="full, quick or smoke (the test suite's smallest run).")


class RichProgress:
    """Study progress on stderr: one line per step, a bar with the time left where the step reports its progress."""

    def __init__(self, console) -> None:
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, SpinnerColumn, TextColumn,
                                   TimeElapsedColumn, TimeRemainingColumn)
        from rich.table import Column

        title = TextColumn("{task.description}", markup=False, table_column=Column(overflow="fold", ratio=1))
        self.bars = Progress(SpinnerColumn(), title, BarColumn(bar_width=20), MofNCompleteColumn(),
                             TimeElapsedColumn(), TextColumn("left"), TimeRemainingColumn(), console=console,
                             expand=True)
        self.task = None

    def begin(self, title: str) -> None:
        self.task = self.bars.add_task(_short(title), total=None)

    def update(self, done: int, total: int) -> None:
        self.bars.update(self.task, completed=done, total=total)

    def end(self, result: StepResult) -> None:
        mark = "" if result.status == STATUS_DONE else f" [{result.status}]"
        self.bars.update(self.task, description=_short(result.title) + mark, total=1, completed=1)


class LineProgress:
    """Study progress in a log or a pipe (where a bar cannot redraw): a line when a step starts, one at each tenth of
    a step that reports its progress, with the time left, and one when it ends, with its time."""

    def __init__(self, echo: Callable[[str], None]) -> None:
        self.echo = echo
        self.title = ""
        self.left = TimeLeft()
        self.tenths: set[int] = set()
        self.bars = nullcontext()
        """Nothing to open or close (a :class:`RichProgress`'s live bars)."""

    def begin(self, title: str) -> None:
        self.title, self.left, self.tenths = _short(title), TimeLeft(), set()
        self.echo(f"{self.title}...")

    def update(self, done: int, total: int) -> None:
        seconds = self.left(self.title, done, total)
        tenth = (10 * done) // max(total, 1)
        if 0 < done < total and tenth not in self.tenths:
            self.tenths.add(tenth)
            after = "" if seconds is None else f", about {duration_text(seconds)} left"
            self.echo(f"  {done} of {total}{after}")

    def end(self, result: StepResult) -> None:
        self.echo(f"  {result.status} in {duration_text(result.seconds)}")


def _short(title: str) -> str:
    """A step title without its references (what follows its first parenthesis), never cut within its words: a
    title wider than the progress column wraps onto the next line."""
    return title.split(" (")[0]


def _scale(quick: bool, scale: Optional[str]) -> str:
    return scale or ("quick" if quick else "full")


def _check_out(out: Path) -> Path:
    """The report folder, created and tried with a scratch file before the study starts (and before its banner)."""
    import tempfile

    out = Path(out)
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out} is a file; give a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=out):
            pass
    except OSError as exc:
        raise UserError(f"--out {out}: cannot write the report there ({exc.strerror or exc})") from None
    return out


def _run(module, settings, out: Path, quiet: bool, as_json: bool) -> dict:
    """Run one study with progress (unless quiet or JSON) and write its report; returns the summary."""
    from rich.console import Console

    from hapticdesign.interface.report import write_report
    from hapticdesign.interface.report.writer import summary

    console = Console(stderr=True)
    show = not (quiet or as_json)
    if show:
        minutes = settings.estimate_seconds() / 60
        size = f"{settings.scale} run, " if hasattr(settings, "scale") else ""
        console.print(f"{module.TITLE}\n{size}estimated {minutes:.1f} min on a quiet 2-core machine with compiled "
                      "kernels (longer on a busy machine; a first run compiles them, several minutes more)",
                      soft_wrap=True, markup=False)
    if show:
        progress = RichProgress(console) if console.is_terminal else LineProgress(lambda line: typer.echo(line, err=True))
        with progress.bars:
            result = module.run(settings, out / "work", progress)
    else:
        result = module.run(settings, out / "work")
    report = write_report(result, out)
    if show:
        console.print(f"{result.title}: {result.seconds:.1f} s", soft_wrap=True, markup=False)
    return summary(result, report)


def _finish(found: dict, quiet: bool, as_json: bool) -> None:
    """Print the summary (JSON) or the report's path, then one stderr line per step that failed (always) or was
    skipped (unless quiet); a failed step makes the exit status 2, after the report is written."""
    if as_json:
        print_json(found)
    elif not quiet:
        typer.echo(f"report: {found['report']}")
    _end_on_failed_steps([found], quiet)


def _end_on_failed_steps(studies: list[dict], quiet: bool) -> None:
    failed = [line for found in studies for line in _step_lines(found, STATUS_FAILED)]
    skipped = [line for found in studies for line in _step_lines(found, STATUS_SKIPPED)]
    for line in failed + ([] if quiet else skipped):
        typer.echo(line, err=True)
    if failed:
        raise typer.Exit(2)


def _step_lines(found: dict, status: str) -> list[str]:
    label = "error" if status == STATUS_FAILED else "note"
    return [f"{label}: step {key} {status}: {step.get('reason', '')}" for key, step in found["steps"].items()
            if step["status"] == status]


def _warm_phantom_loop() -> None:
    """Compile (or load) the rendering loop of the built-in Phantom, as the seed 000 study's rendering steps run
    it; the target of :func:`_compile_phantom_loop_aside`'s second process."""
    from hapticdesign.devices.registry import preset
    from hapticdesign.simulation.loop import warm_up

    warm_up(preset("phantom-3dof"))


def _compile_phantom_loop_aside():
    """On a machine whose numba cache lacks the rendering loop, compile it in a second process while the seed 000
    study's first steps (equations, Linearity Number: about 8 s) run here: the loop is the tour's one noticeable
    compile (about 12 of its 15 compiling CPU-s, ``benchmarks/bench_compile.py demo``)."""
    from hapticdesign.simulation import kernel
    from hapticdesign.simulation.warmup import compile_aside

    return compile_aside(kernel.run_loop, _warm_phantom_loop)


def phantom(quick: bool = QUICK, out: Path = OUT, seed: int = SEED,
            workers: int = typer.Option(2, "--workers", help="Local processes for the simulation campaign."),
            quiet: bool = QUIET, as_json: bool = JSON_OUT, scale: Optional[str] = SCALE) -> None:
    """Seed 000 end to end: equations of motion, LN, linearization, 6-DOF verdict, design sets, chapter 4."""
    from hapticdesign.studies import phantom as study

    with user_errors(quiet=True):
        settings = study.PhantomSettings.for_scale(_scale(quick, scale), seed, workers)
        out = _check_out(out)
        _compile_phantom_loop_aside()
        _finish(_run(study, settings, out, quiet, as_json), quiet, as_json)


def rcube(quick: bool = QUICK, out: Path = OUT, seed: int = SEED, quiet: bool = QUIET, as_json: bool = JSON_OUT,
          scale: Optional[str] = SCALE) -> None:
    """Seed 001 end to end: kinematics, final design against the seed, workspace maps, optimization chain."""
    from hapticdesign.studies import rcube as study

    with user_errors(quiet=True):
        settings = study.RCubeSettings.for_scale(_scale(quick, scale), seed)
        _finish(_run(study, settings, _check_out(out), quiet, as_json), quiet, as_json)


def device(device_file: Optional[Path] = DEVICE, preset: Optional[str] = PRESET,
           out: Path = OUT, seed: int = SEED, quiet: bool = QUIET, as_json: bool = JSON_OUT,
           force: bool = FORCE) -> None:
    """Seed 000's analyses on your own device (--device FILE): dynamics, LN, linearization, rendering."""
    from hapticdesign.studies import device as study

    with user_errors(quiet=True), allow_large(force, FORCE_HINT):
        settings = study.DeviceSettings.for_device(device_file, preset, seed)
        _finish(_run(study, settings, _check_out(out), quiet, as_json), quiet, as_json)


def _print_equations(echo) -> None:
    """The default 3-DOF Phantom's exact H and G, the size of the fully symbolic form, and evaluations."""
    import numpy as np
    import sympy as sp

    from hapticdesign.analysis.dynamics.device import inverse_dynamics
    from hapticdesign.analysis.dynamics.symbolic import derive, export
    from hapticdesign.devices.registry import preset

    device = preset("phantom-3dof")
    echo(f"Equations of motion of the built-in {device.name} (seed 000 eq. 2.50: tau = H thetadd + C thetad^2 + G)")
    numeric = derive(device, "none")
    echo(export(numeric, "text", "H"))
    echo(export(numeric, "text", "G"))
    full = derive(device, "all")
    terms = sum(len(sp.Add.make_args(sp.expand(e))) for e in (*full.H, *full.C, *full.G))
    echo(f"Fully symbolic (every length and inertial parameter a symbol): {terms} terms in H, C and G.")
    echo("The default design is fully linear (LN = 0): H is constant and G vanishes (up to 1e-11 from the rounded "
         "parameters), so tau below does not depend on q.")
    for q in (np.zeros(3), np.array([0.3, -0.4, 0.7])):
        qd, qdd = np.full(3, 0.5), np.ones(3)
        tau = inverse_dynamics(device, q, qd, qdd)
        echo(f"q = {q.tolist()}, qd = {qd.tolist()}, qdd = {qdd.tolist()}: tau = "
             + " ".join(f"{v:.6e}" for v in tau) + " N m")


def demo(out: Path = typer.Option(Path("out/demo"), "--out", help="Folder for the two reports."),
         quiet: bool = QUIET, as_json: bool = JSON_OUT, scale: Optional[str] = SCALE) -> None:
    """The toolkit in one command: the Phantom's equations of motion (seed 000 eq. 2.50), then both studies in quick form."""
    from hapticdesign.studies import phantom as phantom_study
    from hapticdesign.studies import rcube as rcube_study

    with user_errors(quiet=True):
        out = _check_out(out)
        level = scale or "quick"
        _compile_phantom_loop_aside()
        if not (quiet or as_json):
            _print_equations(typer.echo)
        found = {
            "phantom": _run(phantom_study, phantom_study.PhantomSettings.for_scale(level), out / "phantom", quiet, as_json),
            "rcube": _run(rcube_study, rcube_study.RCubeSettings.for_scale(level), out / "rcube", quiet, as_json),
        }
        if as_json:
            print_json(found)
        elif not quiet:
            for name, item in found.items():
                typer.echo(f"{name} report: {item['report']}")
        _end_on_failed_steps(list(found.values()), quiet)


def register(app: typer.Typer) -> None:
    study_app.command("phantom")(phantom)
    study_app.command("rcube")(rcube)
    study_app.command("device")(device)
    app.add_typer(study_app, name="study")
    app.command("demo")(demo)
