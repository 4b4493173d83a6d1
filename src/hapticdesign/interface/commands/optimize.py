"""Command ``optimize``: a study file's multi-objective optimization of any device file (docs/optimization.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from hapticdesign.interface.common import note, print_json, progress_bar, user_errors
from hapticdesign.interface.options import FORCE, FORCE_HINT, JSON_OUT, QUIET, SEED
from hapticdesign.workload import allow_large

STUDY = typer.Argument(..., help="Study file (YAML or TOML): device, variables, workspace, objectives, constraints, algorithm.")
OUT = typer.Option(None, "--out", help="Folder for front.csv, evaluations.csv, pareto.png|svg, report.html, selected.yaml "
                   "and the checkpoint (a rerun into the same folder continues).")
SCHEDULER = typer.Option(None, "--scheduler", help="Evaluate each generation's designs on the Dask cluster at this "
                         "address (tcp://host:8786).")
INDICES = typer.Option(None, "--indices", help="A Python file of your own design indices (decorated with "
                       "@hapticdesign.index) that the study may name. Its code RUNS, as 'python FILE' would; a study "
                       "file alone never runs code.")
SELECT = typer.Option("rms", "--select", help="Design to select: rms (least RMS of the normalized objectives, seed 001), "
                      "weights such as 'isotropy=1,mass=0.5' (least weighted RMS), or a number N (front.csv's design N).")


def register(app: typer.Typer) -> None:
    @app.command()
    def optimize(study: Path = STUDY, seed: int = SEED, out: Optional[Path] = OUT, scheduler: Optional[str] = SCHEDULER,
                 select: str = SELECT, indices: Optional[Path] = INDICES, json_out: bool = JSON_OUT, quiet: bool = QUIET,
                 force: bool = FORCE) -> None:
        """Optimize a device file's variables for a study file's objectives and constraints (NSGA-II, NSGA-III, PSO or the convex LN program; selection by seed 001 §7.2)."""
        from hapticdesign.interface.commands.optimize_adapter import optimize as run, parse_select, summary_lines

        with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
            rule = parse_select(select)
            with progress_bar(not (quiet or json_out)) as report:
                progress = (lambda done, total: report("generations", done, total)) if report else None
                result = run(study, seed, out, scheduler=scheduler, progress=progress, quiet=quiet or json_out,
                             indices=indices or (), **rule)
            if out is not None:
                note(f"wrote {len(result.files)} files to {out}", quiet)
            if json_out:
                print_json(result.summary)
                return
            for line in summary_lines(result.summary):
                typer.echo(line)
