"""The work of ``optimize`` and its Python door ``hapticdesign.optimize``: read the study, run its method (here or
on a Dask cluster), select, write the outputs, and answer an :class:`OptimizationResult`.

The command and the Python door are one function, :func:`optimize`: it prints nothing on stdout, its progress goes to
stderr unless told ``quiet=True`` (or given its own ``progress``), and a user error raises
:class:`~hapticdesign.errors.UserError`. Every file goes into the output folder through
:func:`~hapticdesign.files.write_atomically`; the final files are written only after the run finished, so an
interrupted run leaves complete checkpoint files and nothing half-written. A run that finished without a feasible
design writes evaluations.csv and the report of why (:func:`write_failure`), then raises the one-line error.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path

from hapticdesign.analysis.metrics.indices import Index, compliance_line
from hapticdesign.errors import RunWarning, UserError
from hapticdesign.files import quote, write_atomically
from hapticdesign.interface.report.optimization_page import PLOTLY, Picture, plotly_js, render, render_failure
from hapticdesign.optimization.study_evaluation import (BoundStudy, StudyEvaluator, bind_study, require_study_workload,
                                                        unmeetable_walls)
from hapticdesign.optimization.study_explorer import DESIGNS, STUDY_COPY, explorer_data, front_designs, study_copy
from hapticdesign.optimization.study_polish import most_designs
from hapticdesign.optimization.study_file import Study, load_study
from hapticdesign.optimization.study_methods import ConvexProgram, PopulationSearch, method_of, with_baseline
from hapticdesign.optimization.study_outputs import (Selection, baseline_lines, check_selection, device_file_text,
                                                     evaluations_csv, front_csv, pareto_figure, pictures, select_design,
                                                     spread_rows)
from hapticdesign.optimization.study_run import Record, StudyRun

FILES = ("front.csv", "evaluations.csv", "pareto.png", "pareto.svg", "selected.yaml", "report.html", PLOTLY,
         f"{DESIGNS}/design-N.yaml (each front design's device file)",
         f"{STUDY_COPY} (the study and device files as the run read them: hapticdesign explore reads it)")


def parse_select(text: str) -> dict:
    """``rms`` -> {}; ``name=w,name=w`` -> {"weights": {...}}; ``N`` -> {"design": N}."""
    text = text.strip()
    if text == "rms":
        return {}
    if text.isascii() and text.isdigit():
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


def _evaluator(bound: BoundStudy, scheduler: str | None, quiet: bool, stack) -> StudyEvaluator:
    """The study's evaluator: in this process, or on the workers of the Dask scheduler (closed with ``stack``)."""
    if scheduler is None:
        return StudyEvaluator(bound)
    from hapticdesign.simulation.campaign import check_scheduler, close_client, dask_client, dask_logging

    check_scheduler(scheduler)
    stack.enter_context(dask_logging(quiet))
    client = dask_client(scheduler, None, quiet)
    stack.callback(close_client, client, False)
    return StudyEvaluator(bound, client)


def _shown_progress(stack: ExitStack) -> Callable[[int, int], None]:
    """Generations done on stderr (:func:`~hapticdesign.interface.common.progress_bar`) and the kernels' first
    compile (:func:`~hapticdesign.simulation.warmup.compile_notice`), for as long as ``stack`` is open."""
    import sys

    from hapticdesign.interface.common import progress_bar
    from hapticdesign.simulation.warmup import compile_notice

    report = stack.enter_context(progress_bar(True))
    stack.enter_context(compile_notice(lambda line: print(line, file=sys.stderr, flush=True)))
    return lambda done, total: report("generations", done, total)


def _check_out(out: Path) -> None:
    if out.exists() and not out.is_dir():
        raise UserError(f"cannot write to {out}: it is a file, not a folder")


def _design(run: StudyRun, k: int) -> dict:
    r = run.records[k]
    out = {"variables": dict(r.values), "objectives": dict(zip((o.name for o in run.spec.objectives), r.objectives))}
    if run.spec.algorithm.polish != "none":
        out["polished"] = r.polished
    return out


def summary_of(run: StudyRun, selection: Selection) -> dict:
    """The ``--json`` answer: the front, the number of evaluations and the selected design, in the
    study's own sense and units, the method's own results (:attr:`StudyRun.notes`) and, when the study asks for
    ``kmax``, which compliance between the motors and the handle it took (``compliance``, by index name)."""
    return {"front": [_design(run, k) for k in run.front], "evaluations": run.evaluations,
            "selected": {"design": selection.position + 1, "rule": selection.rule, **_design(run, selection.record)},
            **run.notes, **({"compliance": run.compliance} if run.compliance else {})}


def summary_lines(summary: dict) -> list[str]:
    """The answer as text: the front as a table and the selected design."""
    front = summary["front"]
    names = list(front[0]["variables"]) + list(front[0]["objectives"])
    polished = ["polished"] if "polished" in front[0] else []
    lines = [f"front: {len(front)} designs of {summary['evaluations']} evaluated",
             " ".join(f"{n[:14]:>14s}" for n in ["design", *names, *polished])]
    for n, d in enumerate(front, start=1):
        values = list(d["variables"].values()) + list(d["objectives"].values())
        marks = [f"{'yes' if d['polished'] else 'no':>14s}"] if polished else []
        lines.append(" ".join([f"{n:14d}", *(f"{v:14.6g}" for v in values), *marks]))
    s = summary["selected"]
    lines.append(f"selected design {s['design']} ({s['rule']}): "
                 + ", ".join(f"{k} = {v:.6g}" for k, v in {**s["variables"], **s["objectives"]}.items()))
    if "lower_bound" in summary:
        lines.append(f"lower bound on the minimum (the convex relaxation): {summary['lower_bound']:.6g}")
    if "compliance" in summary:
        lines.append(compliance_line(summary["compliance"]))
    return lines


def write_outputs(out: Path, run: StudyRun, bound: BoundStudy, selection: Selection) -> list[Path]:
    """Every output file of the run in ``out`` (see :data:`FILES`)."""
    write_atomically(out / "front.csv", front_csv(run, bound.units()))
    write_atomically(out / "evaluations.csv", evaluations_csv(run, bound.units()))
    paths = [out / "front.csv", out / "evaluations.csv", *pareto_figure(run, selection, out, registry=bound.registry)]
    chosen = run.records[selection.record]
    write_atomically(out / "selected.yaml", device_file_text(bound, chosen.values, baseline_lines(run, chosen)))
    write_atomically(out / STUDY_COPY, study_copy(bound.study))
    shown = [Picture(png, caption) for png, caption in pictures(bound, chosen.values)]
    kept = (["checkpoint/ (one file per generation; a rerun into this folder continues)"]
            if method_of(run.spec).checkpointed else [])
    from hapticdesign.studies.spec import spec_summary

    designs = front_designs(run, bound, spec_summary)  # the spec summary on each card (docs/optimization.md)
    for design in designs:
        write_atomically(out / design.file, design.text)
    _remove_stale_designs(out, len(designs))
    write_atomically(out / PLOTLY, plotly_js())
    page = render(run, selection, bound.title, Picture((out / "pareto.png").read_bytes(), "Pareto front"), shown,
                  [*FILES, *kept], explorer_data(run, bound, selection, designs), bound.coarseness,
                  spread_rows(bound, chosen.values), bound.units())
    write_atomically(out / "report.html", page)
    return [*paths, out / "selected.yaml", out / STUDY_COPY, *(out / d.file for d in designs), out / PLOTLY, out / "report.html"]


def _remove_stale_designs(out: Path, count: int) -> None:
    """Remove the device files of front designs beyond ``count`` that an earlier run into ``out`` wrote."""
    for path in (out / DESIGNS).glob("design-*.yaml"):
        number = path.stem.removeprefix("design-")
        if number.isascii() and number.isdigit() and int(number) > count:
            path.unlink()


def write_failure(out: Path, run: StudyRun, bound: BoundStudy, error: UserError) -> list[Path]:
    """What a run without a feasible design leaves in ``out``: every evaluation (evaluations.csv) and the report of
    why (``error``'s sentence, the reasons counted by kind, the closest designs, the device file's design)."""
    write_atomically(out / "evaluations.csv", evaluations_csv(run, bound.units()))
    kept = (["checkpoint/ (one file per generation; a rerun into this folder continues)"]
            if method_of(run.spec).checkpointed else [])
    write_atomically(out / "report.html", render_failure(run, str(error), bound.title,
                                                         ["evaluations.csv", "report.html", *kept], bound.coarseness,
                                                         bound.units()))
    return [out / "evaluations.csv", out / "report.html"]


@dataclass(frozen=True)
class OptimizationResult:
    """What :func:`optimize` answers: the ``study`` (the problem), its ``method`` (the algorithm), the ``run`` (every
    evaluated design and the front), the ``selection`` and the ``files`` written (none without an output folder)."""

    study: Study
    method: PopulationSearch | ConvexProgram
    run: StudyRun
    selection: Selection
    files: list[Path]

    @property
    def records(self) -> list[Record]:
        """Every evaluated design, in evaluation order (evaluations.csv)."""
        return self.run.records

    @property
    def summary(self) -> dict:
        """The answer of ``optimize --json``."""
        return summary_of(self.run, self.selection)

    @property
    def front(self) -> list[dict]:
        """The front as ``optimize --json`` prints it: ``[{"variables": {...}, "objectives": {...}}, ...]``."""
        return self.summary["front"]

    @property
    def selected(self) -> dict:
        """The selected design: its number on the front, the rule, its variables and objectives."""
        return self.summary["selected"]


def index_module(path: Path) -> list[Index]:
    """Run the Python file ``path`` (its code, as ``python path`` would) and return the design indices it defines with
    :func:`hapticdesign.index`."""
    import importlib.util

    path = Path(path)
    if path.suffix != ".py" or not path.is_file():
        raise UserError(f"indices file {quote(str(path))}: not a Python file (.py) of design indices")
    spec = importlib.util.spec_from_file_location(f"hapticdesign_user_indices_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except UserError as exc:
        raise UserError(f"indices file {quote(str(path))}: {exc}") from None
    except Exception as exc:  # the user's code: one line saying where it failed
        raise UserError(f"indices file {quote(str(path))}: running it failed: {type(exc).__name__}: {exc}") from None
    found = [value for value in vars(module).values() if isinstance(value, Index)]
    if not found:
        raise UserError(f"indices file {quote(str(path))}: it defines no index (decorate a function with @hapticdesign.index)")
    return found


def optimize(study: Path | str, seed: int = 1, out: Path | str | None = None, *, scheduler: str | None = None,
             weights: dict[str, float] | None = None, design: int | None = None,
             progress: Callable[[int, int], None] | None = None, quiet: bool = False,
             indices: Sequence[Index] | Path | str = ()) -> OptimizationResult:
    """Run the study file ``study`` with ``seed`` by its method and select a front design: the least RMS of the
    normalized objectives, the least weighted RMS with ``weights`` (objective name -> weight), or the front's
    ``design``-th (seed 001 §7.2). ``out``: a folder for the outputs and the checkpoint (a rerun into it
    continues); ``scheduler``: a Dask scheduler's address whose workers evaluate the designs;
    ``progress(generation, generations)``, called after each generation; without it the run shows its progress on
    stderr (:func:`~hapticdesign.interface.common.progress_bar`: a bar with the time left on a terminal, a line each
    tenth in a log) and says when the toolkit's kernels compile for the first time on the machine, unless ``quiet``;
    ``quiet``: nothing on stderr, Dask's own logging silenced too; ``indices``: your own design
    indices (functions decorated with :func:`hapticdesign.index`, or a Python file defining them, run in this
    process), which the study may name beside the registered ones. Nothing is printed on stdout; a bad study, seed or
    selection raises :class:`~hapticdesign.errors.UserError`; a ``kmax`` constraint that no design can meet, known
    before the run (:func:`~hapticdesign.optimization.study_evaluation.unmeetable_walls`), is a
    :class:`~hapticdesign.errors.RunWarning` before the run starts. The device file's own design is evaluated beside
    the run (:func:`~hapticdesign.optimization.study_methods.with_baseline`); a run without a feasible design
    writes evaluations.csv and report.html to ``out`` before its UserError."""
    if isinstance(indices, (str, Path)):
        indices = index_module(Path(indices))
    own = list(indices)
    if own and scheduler is not None:
        raise UserError("your own indices live in this process; the workers of a scheduler would not have them")
    study = load_study(study)
    check_selection(study.spec, weights, design, study.spec.algorithm.designs + most_designs(study.spec))
    bound = bind_study(study, indices=own)
    require_study_workload(study, bound.registry)
    for message in unmeetable_walls(bound):
        warnings.warn(message, RunWarning, stacklevel=2)
    out = None if out is None else Path(out)
    if out is not None:
        _check_out(out)
    method = method_of(study.spec)
    if scheduler is not None and not method.evaluates_designs:
        raise UserError(f"a scheduler distributes the evaluation of designs; method {method.name} solves one program "
                        "here")
    with ExitStack() as stack:
        if progress is None and not quiet:
            progress = _shown_progress(stack)
        evaluate = _evaluator(bound, scheduler, quiet, stack)
        run = method.run(bound, seed, evaluate, out, progress)
    run = with_baseline(run, bound)
    if not run.front:
        error = method.empty_front(run, bound)
        if out is None:
            raise error
        write_failure(out, run, bound, error)
        raise UserError(f"{error} (why, by reason, and the closest designs: {out / 'report.html'})")
    selection = select_design(run, weights, design)
    written = [] if out is None else write_outputs(out, run, bound, selection)
    return OptimizationResult(study, method, run, selection, written)
