"""The work of ``optimize``: read the study, run it (here or on a Dask cluster), select, write the outputs.

Every file goes into the output folder through :func:`~hapticdesign.files.write_atomically`; the
final files are written only after the run succeeded, so a failed or interrupted run leaves complete
checkpoint files and nothing half-written.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from hapticdesign.analysis.metrics.indices import Index
from hapticdesign.errors import UserError
from hapticdesign.files import write_atomically
from hapticdesign.interface.report.optimization_page import Picture, render
from hapticdesign.optimization.study_convex import run_convex
from hapticdesign.optimization.study_evaluation import BoundStudy, bind_study, require_study_workload
from hapticdesign.optimization.study_file import load_study
from hapticdesign.optimization.study_outputs import (Selection, evaluations_csv, front_csv, pareto_figure,
                                                     select_design)
from hapticdesign.optimization.study_run import StudyRun, run_study

FILES = ("front.csv", "evaluations.csv", "pareto.png", "pareto.svg", "selected.yaml", "report.html")


def parse_select(text: str) -> dict:
    """``rms`` -> {}; ``name=w,name=w`` -> {"weights": {...}}; ``N`` -> {"design": N}."""
    text = text.strip()
    if text == "rms":
        return {}
    if text.isdigit():
        return {"design": int(text)}
    weights = {}
    for part in text.split(","):
        name, sep, value = part.partition("=")
        try:
            weight = float(value)
        except ValueError:
            weight = math.nan
        if not sep or not name.strip() or not (math.isfinite(weight) and weight >= 0.0):
            raise UserError(f"--select: expected rms, weights such as 'isotropy=1,mass=0.5' (each >= 0) or a front "
                            f"design number, got {text[:60]!r}")
        weights[name.strip()] = weight
    return {"weights": weights}


def _evaluator(bound: BoundStudy, scheduler: str | None, quiet: bool, stack):
    if scheduler is None:
        return bound.evaluate
    from hapticdesign.optimization.study_cluster import cluster_evaluator
    from hapticdesign.simulation.campaign import check_scheduler, close_client, dask_client, dask_logging

    check_scheduler(scheduler)
    stack.enter_context(dask_logging(quiet))
    client = dask_client(scheduler, None, quiet)
    stack.callback(close_client, client, False)
    return cluster_evaluator(client, bound.study)


def _check_out(out: Path) -> None:
    if out.exists() and not out.is_dir():
        raise UserError(f"cannot write to {out}: it is a file, not a folder")


def _design(run: StudyRun, k: int) -> dict:
    r = run.records[k]
    return {"variables": dict(r.values), "objectives": dict(zip((o.name for o in run.spec.objectives), r.objectives))}


def summary_of(run: StudyRun, selection: Selection) -> dict:
    """The ``--json`` answer: the front, the number of evaluations and the selected design, in the
    study's own sense and units."""
    out = {"front": [_design(run, k) for k in run.front], "evaluations": run.evaluations,
           "selected": {"design": selection.position + 1, "rule": selection.rule, **_design(run, selection.record)}}
    if run.bound is not None:
        out["lower_bound"] = run.bound
    return out


def summary_lines(summary: dict) -> list[str]:
    """The answer as text: the front as a table and the selected design."""
    front = summary["front"]
    names = list(front[0]["variables"]) + list(front[0]["objectives"])
    lines = [f"front: {len(front)} designs of {summary['evaluations']} evaluated",
             " ".join(f"{n[:14]:>14s}" for n in ["design", *names])]
    for n, d in enumerate(front, start=1):
        values = list(d["variables"].values()) + list(d["objectives"].values())
        lines.append(" ".join([f"{n:14d}", *(f"{v:14.6g}" for v in values)]))
    s = summary["selected"]
    lines.append(f"selected design {s['design']} ({s['rule']}): "
                 + ", ".join(f"{k} = {v:.6g}" for k, v in {**s["variables"], **s["objectives"]}.items()))
    if "lower_bound" in summary:
        lines.append(f"lower bound on the minimum (the convex relaxation): {summary['lower_bound']:.6g}")
    return lines


CLOSEST_CANDIDATES = 12
"""Designs of the last generation tried point by point when no design reaches the workspace."""


def _no_front(run: StudyRun, bound: BoundStudy) -> UserError:
    """Why the front is empty, with the closest design: the most workspace points reached (each from home),
    or the least constraint violation."""
    valid = [r for r in run.records if not r.invalid]
    if not valid:
        last = [r for r in run.records if r.generation == run.records[-1].generation][:CLOSEST_CANDIDATES]
        counts = [bound.points_reached(r.values) for r in last]
        best = int(np.argmax(counts))
        shown = ", ".join(f"{k} = {v:.6g}" for k, v in last[best].values.items())
        return UserError(f"no design of {run.evaluations} reaches the whole workspace; the closest ({shown}) reaches "
                         f"{counts[best]} of {len(bound.points)} points ({last[best].invalid})")
    closest = min(valid, key=lambda r: r.violation)
    shown = ", ".join(f"{k} = {v:.6g}" for k, v in closest.values.items())
    return UserError(f"no design of {run.evaluations} meets the constraints; the closest ({shown}) has {closest.violated}")


def write_outputs(out: Path, run: StudyRun, bound: BoundStudy, selection: Selection) -> list[Path]:
    """Every output file of the run in ``out`` (see :data:`FILES`)."""
    write_atomically(out / "front.csv", front_csv(run))
    write_atomically(out / "evaluations.csv", evaluations_csv(run))
    paths = [out / "front.csv", out / "evaluations.csv", *pareto_figure(run, selection, out, registry=bound.registry)]
    values = run.records[selection.record].values
    write_atomically(out / "selected.yaml", bound.device_file_text(values))
    pictures = [Picture(png, caption) for png, caption in bound.pictures(values)]
    kept = [] if run.bound is not None else ["checkpoint/ (one file per generation; a rerun into this folder continues)"]
    page = render(run, selection, bound.title, Picture((out / "pareto.png").read_bytes(), "Pareto front"), pictures,
                  [*FILES, *kept])
    write_atomically(out / "report.html", page)
    return [*paths, out / "selected.yaml", out / "report.html"]


def index_module(path: Path) -> list[Index]:
    """Run the Python file ``path`` (its code, as ``python path`` would) and return the design indices it defines with
    :func:`hapticdesign.index`."""
    import importlib.util

    path = Path(path)
    if path.suffix != ".py" or not path.is_file():
        raise UserError(f"--indices: {path} is not a Python file (.py) of design indices")
    spec = importlib.util.spec_from_file_location(f"hapticdesign_user_indices_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except UserError as exc:
        raise UserError(f"--indices {path}: {exc}") from None
    except Exception as exc:  # the user's code: one line saying where it failed
        raise UserError(f"--indices {path}: running it failed: {type(exc).__name__}: {exc}") from None
    found = [value for value in vars(module).values() if isinstance(value, Index)]
    if not found:
        raise UserError(f"--indices {path}: it defines no index (decorate a function with @hapticdesign.index)")
    return found


def optimize(study_path: Path, seed: int, out: Path | None, scheduler: str | None, rule: dict,
             progress: Callable[[int, int], None] | None, quiet: bool,
             indices: Path | None = None) -> tuple[dict, list[Path]]:
    """Run the study file ``study_path`` with ``seed`` (and the design indices the Python file ``indices`` defines,
    running its code); write the outputs into ``out`` (when given)."""
    from contextlib import ExitStack

    if indices is not None and scheduler is not None:
        raise UserError("--indices runs a Python file in this process; the workers of --scheduler would not have its "
                        "indices")
    own = [] if indices is None else index_module(indices)
    study = load_study(study_path)
    bound = bind_study(study, indices=own)
    require_study_workload(study)
    if out is not None:
        _check_out(out)
    if study.spec.algorithm.method == "convex":
        if scheduler is not None:
            raise UserError("--scheduler distributes NSGA-II's generations; method convex solves one program here")
        run = run_convex(bound, seed)
    else:
        with ExitStack() as stack:
            evaluate = _evaluator(bound, scheduler, quiet, stack)
            run = run_study(study, seed, evaluate, out, progress, bound.evaluate_constraints)
    if not run.front:
        if run.bound is not None:
            raise UserError(f"{study_path}: the convex program's design is infeasible: {run.records[0].reason}")
        raise _no_front(run, bound)
    selection = select_design(run, **rule)
    written = [] if out is None else write_outputs(out, run, bound, selection)
    return summary_of(run, selection), written
