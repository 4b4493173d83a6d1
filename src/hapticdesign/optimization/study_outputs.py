"""What a study run leaves: the front and every evaluation as CSV, the selected design, the Pareto figure, and what a
design's outputs say of it (its device file with where the study's indices are taken over the workspace points, their
spread and its pictures; its device, poses and indices there computed once for all of these, the last design kept).

The selected design follows seed 001's rule (§7.2, Figures 7.2-7.3): each objective is normalized over
the front (eq. 7.1) and turned so that 0 is its best value (eq. 7.2-7.4), and the design with the least
RMS of these, or the least weighted RMS, is chosen (:func:`~hapticdesign.optimization.front_selection.least_rms`).
Numbers in the CSV files are written with Python's shortest round-trip representation, so the same run
gives the same bytes and reading them back gives the same floats.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import yaml

from hapticdesign.analysis.metrics.indices import (INDICES, Index, compliance_line, evaluate_at, reduce, reduced_at,
                                                   reduction_label, spread)
from hapticdesign.analysis.view.figure import render_png
from hapticdesign.analysis.view.skeleton import home_pose
from hapticdesign.analysis.workspace import Workspace, WorkspacePoses, reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.files import csv_rows, figure_bytes, save_figure
from hapticdesign.model.device import Device
from hapticdesign.optimization.front_selection import least_rms, normalize
from hapticdesign.optimization.study_evaluation import BoundStudy, workspace_of
from hapticdesign.optimization.study_file import Choice, StudySpec
from hapticdesign.optimization.study_run import Record, StudyRun, constraint_labels


@dataclass(frozen=True)
class Selection:
    """The chosen design: its ``position`` on the front (0-based), its record index and the rule in words."""

    position: int
    record: int
    rule: str


def normalized_front(run: StudyRun) -> np.ndarray:
    """The front's objectives normalized (eq. 7.1) with 0 the best value of each (eq. 7.2-7.4)."""
    columns = []
    for k, objective in enumerate(run.spec.objectives):
        n = normalize([run.records[i].objectives[k] for i in run.front])
        columns.append(1.0 - n if objective.sense == "max" else n)
    return np.column_stack(columns)


def check_selection(spec, weights: dict[str, float] | None = None, design: int | None = None,
                    designs: int | None = None) -> None:
    """What a selection can be refused for before the study runs (``spec`` the study's): a front design number
    below 1 or above the ``designs`` the study may evaluate (the front holds at most that many), a weight named after
    no objective (a one-line :class:`~hapticdesign.errors.UserError`). :func:`select_design` checks it again with
    the front's size."""
    if design is not None and not 1 <= design <= (design if designs is None else designs):
        raise UserError(f"front design {design}: a front design is numbered from 1" + (
            "" if design < 1 or designs is None else f" and the study evaluates at most {designs} designs"))
    names = [o.name for o in spec.objectives]
    unknown = [n for n in (weights or {}) if n not in names]
    if unknown:
        raise UserError(f"no objective named {unknown[0]!r} to weigh (objectives: {', '.join(names)})")


def select_design(run: StudyRun, weights: dict[str, float] | None = None, design: int | None = None) -> Selection:
    """The least-RMS design of the front, the least weighted RMS with ``weights`` per objective name
    (objectives not named weigh 1), or the front's ``design``-th row (1-based, as in front.csv)."""
    if not run.front:
        raise UserError("no feasible design to select: the front is empty")
    check_selection(run.spec, weights, design)
    if design is not None:
        if not 1 <= design <= len(run.front):
            raise UserError(f"the front has designs 1 to {len(run.front)}, not {design}")
        return Selection(design - 1, run.front[design - 1], f"design {design} of the front, chosen by hand")
    names = [o.name for o in run.spec.objectives]
    weights = dict(weights or {})
    w = [float(weights.get(n, 1.0)) for n in names]
    position = least_rms(normalized_front(run), w)
    rule = ("least RMS of the normalized objectives (seed 001 Fig. 7.2)" if not weights else
            "least weighted RMS of the normalized objectives (seed 001 Fig. 7.3; weights "
            + ", ".join(f"{n} {x:g}" for n, x in zip(names, w)) + ")")
    return Selection(position, run.front[position], rule)


@dataclass(frozen=True)
class Change:
    """One objective from the device file's design (``old``) to the selected design (``new``): the change in percent
    of ``|old|`` and whether it was ``gained`` or ``lost`` in the objective's sense (``same``; empty when either has no
    value)."""

    name: str
    old: float
    new: float
    percent: float
    verdict: str

    def __str__(self) -> str:
        percent = f" ({self.percent:+.3g} %)" if np.isfinite(self.percent) else ""
        return f"{self.name} {self.old:.6g} -> {self.new:.6g}{percent}{', ' + self.verdict if self.verdict else ''}"


def changes(run: StudyRun, record: Record) -> list[Change]:
    """Each objective from the device file's design (:attr:`StudyRun.baseline`) to ``record``; none without it."""
    if run.baseline is None:
        return []
    out = []
    for objective, old, new in zip(run.spec.objectives, run.baseline.objectives, record.objectives):
        percent = 100.0 * (new - old) / abs(old) if old != 0.0 else math.nan
        better = new < old if objective.sense == "min" else new > old
        verdict = ("" if not (np.isfinite(old) and np.isfinite(new)) else "same" if new == old
                   else "gained" if better else "lost")
        out.append(Change(objective.name, old, new, percent, verdict))
    return out


AT_BOUND = 1e-6
"""How close to a bound of its range, as a fraction of the range, a continuous variable sits at it."""


def at_bounds(spec: StudySpec, values: Mapping[str, float]) -> dict[str, str]:
    """The variables of a design at a bound of their range (within :data:`AT_BOUND` of it; a choice at its least or
    greatest value), each with the bound in words: the search may want to go beyond it."""
    out = {}
    for name, variable in spec.variables.items():
        low, high = (min(variable.values), max(variable.values)) if isinstance(variable, Choice) else variable
        tolerance = 0.0 if isinstance(variable, Choice) else AT_BOUND * (high - low)
        for bound, word in ((low, "lower"), (high, "upper")):
            if abs(values[name] - bound) <= tolerance:
                out[name] = f"at the {word} bound {bound:g} of its range"
    return out


def baseline_lines(run: StudyRun, record: Record) -> list[str]:
    """The device file's design beside ``record`` in words (selected.yaml's header): the device file's variables,
    each objective gained or lost, and the variables of ``record`` at a bound of their range."""
    if run.baseline is None:
        lines = [f"No device file's design to compare: {run.baseline_note}"]
    else:
        shown = ", ".join(f"{k} = {v:.6g}" for k, v in run.baseline.values.items())
        lines = [f"The device file's design ({shown}){': ' + run.baseline_note if run.baseline_note else ''}",
                 "  " + ("feasible" if run.baseline.feasible else f"not feasible: {run.baseline.reason}")
                 + "; from it to this design: " + "; ".join(map(str, changes(run, record)))]
    bounds = at_bounds(run.spec, record.values)
    lines += [f"At a bound: {name} = {record.values[name]:.6g} {words}" for name, words in bounds.items()]
    return lines


CLOSEST = 10
"""Designs the report of a study without a feasible design lists as the closest."""


def closest_designs(run: StudyRun, count: int = CLOSEST) -> list[int]:
    """The ``count`` records with constrained values closest to feasible (least total scaled violation, the first
    evaluated first; designs that meet the constraints, whose ``keep`` filters remove them, first of all)."""
    valid = [k for k, r in enumerate(run.records) if not r.invalid]
    return sorted(valid, key=lambda k: (run.records[k].violation, k))[:count]


def _number(value: float) -> str:
    return repr(float(value)) if np.isfinite(value) else ""


def _polished(run: StudyRun) -> tuple[list[str], Callable[[Record], list[str]]]:
    """The ``polished`` column (yes or no) of a study that polishes its front, none otherwise."""
    if run.spec.algorithm.polish == "none":
        return [], lambda r: []
    return ["polished"], lambda r: ["yes" if r.polished else "no"]


def with_unit(name: str, units: Mapping[str, str] | None) -> str:
    """A column's header: ``name [unit]`` where ``units`` knows its unit (:meth:`BoundStudy.units
    <hapticdesign.optimization.study_evaluation.BoundStudy.units>`), else the name alone (:func:`without_unit`
    reads the name back)."""
    unit = (units or {}).get(name, "")
    return f"{name} [{unit}]" if unit else name


def without_unit(header: str) -> str:
    """The study's name of a column of front.csv or evaluations.csv: ``l1 [m]`` -> ``l1``,
    ``min_force[torque=continuous] [N]`` -> ``min_force[torque=continuous]``, ``design`` -> ``design``."""
    head, sep, unit = header.rpartition(" [")
    return head if sep and unit.endswith("]") else header


def _quantity_columns(spec: StudySpec, units: Mapping[str, str] | None) -> list[str]:
    """The headers of the variables, objectives and constrained values, with their units."""
    return [with_unit(name, units) for name in (*spec.variables, *(o.name for o in spec.objectives),
                                                *constraint_labels(spec))]


def front_csv(run: StudyRun, units: Mapping[str, str] | None = None) -> str:
    """One row per front design: its number, variables, objectives and constrained values (and whether it was
    polished, for a study that polishes); each quantity's header carries its unit in brackets where ``units`` knows
    it (``l1 [m]``, ``mass [kg]``): one header row, every other row numbers."""
    spec = run.spec
    polished, cell = _polished(run)
    header = ["design", *_quantity_columns(spec, units), *polished]
    rows = []
    for n, k in enumerate(run.front, start=1):
        r = run.records[k]
        rows.append([str(n), *(_number(r.values[v]) for v in spec.variables), *map(_number, r.objectives),
                     *map(_number, r.constraints), *cell(r)])
    return csv_rows(header, rows)


def evaluations_csv(run: StudyRun, units: Mapping[str, str] | None = None) -> str:
    """Every evaluated design: generation, variables, objectives, constrained values, feasible or why not (and
    whether it was polished, for a study that polishes: the polished designs follow the last generation; the
    polishing's other probes are counted in the run's evaluations, not listed); units in the headers as in
    :func:`front_csv`."""
    spec = run.spec
    polished, cell = _polished(run)
    header = ["evaluation", "generation", *_quantity_columns(spec, units), "feasible", "reason", *polished]
    rows = []
    for n, r in enumerate(run.records, start=1):
        rows.append([str(n), str(r.generation), *(_number(r.values[v]) for v in spec.variables),
                     *map(_number, r.objectives), *map(_number, r.constraints), "yes" if r.feasible else "no",
                     r.reason, *cell(r)])
    return csv_rows(header, rows)


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def front_limits(values: np.ndarray, pad: float = 0.08) -> tuple[float, float]:
    """Axis limits from the front's own range, ``pad`` of it on each side (a front of one value: 5 % of its
    magnitude, or 1 at 0): the feasible designs far from the front no longer squash it into a band."""
    low, high = float(np.min(values)), float(np.max(values))
    margin = pad * (high - low) if high > low else 0.05 * (abs(high) or 1.0)
    return low - margin, high + margin


BASELINE = "device file's design"
"""The device file's own design in the figures' legends."""


def normalized_like_front(run: StudyRun, objectives: np.ndarray) -> np.ndarray:
    """``objectives`` normalized by the front's range as :func:`normalized_front` does (0 best; outside 0 to 1 when
    beyond the front)."""
    out = []
    for k, (objective, value) in enumerate(zip(run.spec.objectives, objectives)):
        column = np.array([run.records[i].objectives[k] for i in run.front])
        low, span = column.min(), np.ptp(column)
        n = (value - low) / span if span > 0.0 else 0.0
        out.append(1.0 - n if objective.sense == "max" else n)
    return np.array(out)


AXIS_LABEL_WIDTH = 44
"""Characters of an axis label's line in the Pareto figure (a longer label wraps, so that it stays in the figure)."""


def pareto_figure(run: StudyRun, selection: Selection | None, out: Path, name: str = "pareto",
                  registry: Mapping[str, Index] = INDICES) -> list[Path]:
    """The front in pairs of objectives, each labelled with its reduction and how coarse the grid is (every feasible
    design in grey, the front in blue, the selected design as a red star, the device file's design as a black
    diamond, said when it is not feasible; the axes span the front's range and the device file's design,
    :func:`front_limits`, and the legend counts the feasible designs beyond them); one objective: its value per
    evaluation (the device file's design a dashed line); more than three: parallel coordinates of the normalized
    front (0 best; the device file's design dashed, normalized alike)."""
    import textwrap

    from matplotlib.ticker import MaxNLocator

    plt = _pyplot()
    spec = run.spec
    units = {o.index: registry[o.index].unit for o in spec.objectives}
    box = spec.workspace
    grids = {o.index: "" if box is None or registry[o.index].of_parameters
             else "; " + Workspace(box.box.center, box.box.size, box.grid).describe() for o in spec.objectives}
    labels = [textwrap.fill(f"{o.name}: {o.reduce} {o.index} ({'-' if units[o.index] == '1' else units[o.index]}"
                            f"{grids[o.index]}), {o.sense}imize", AXIS_LABEL_WIDTH) for o in spec.objectives]
    feasible = [r for r in run.records if r.feasible]
    F_all = np.array([r.objectives for r in feasible]).reshape(len(feasible), len(labels))
    F = np.array([run.records[k].objectives for k in run.front]).reshape(len(run.front), len(labels))
    pick = None if selection is None else F[selection.position]
    base = (np.array(run.baseline.objectives) if run.baseline is not None
            and np.all(np.isfinite(run.baseline.objectives)) else None)
    baseline = BASELINE if base is None or run.baseline.feasible else f"{BASELINE} (not feasible)"
    k = len(labels)
    if k == 1:
        fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
        numbers = [n for n, r in enumerate(run.records, start=1) if r.feasible]
        ax.scatter(numbers, F_all[:, 0], s=6, color="0.6", label="feasible designs")
        if pick is not None:
            ax.scatter([selection.record + 1], [pick[0]], marker="*", s=140, color="red", label="selected")
        if base is not None:
            ax.axhline(base[0], color="black", linestyle="--", linewidth=1.0, label=baseline)
        ax.set_xlabel("evaluation")
        ax.set_ylabel(labels[0])
        ax.legend(fontsize=8)
    elif k <= 3:
        pairs = [(0, 1)] if k == 2 else [(0, 1), (0, 2), (1, 2)]
        fig, axes = plt.subplots(1, len(pairs), figsize=(5.5 * len(pairs), 4.5), dpi=100, squeeze=False)
        for ax, (i, j) in zip(axes[0], pairs):
            shown = F if base is None else np.vstack([F, base])
            (x_low, x_high), (y_low, y_high) = front_limits(shown[:, i]), front_limits(shown[:, j])
            beyond = int(np.sum((F_all[:, i] < x_low) | (F_all[:, i] > x_high) | (F_all[:, j] < y_low)
                                | (F_all[:, j] > y_high)))
            ax.scatter(F_all[:, i], F_all[:, j], s=6, color="0.75",
                       label=f"feasible designs ({beyond} beyond the axes)" if beyond else "feasible designs")
            ax.scatter(F[:, i], F[:, j], s=22, color="tab:blue", label="front")
            if pick is not None:
                ax.scatter([pick[i]], [pick[j]], marker="*", s=160, color="red", label="selected")
            if base is not None:
                ax.scatter([base[i]], [base[j]], marker="D", s=50, color="black", label=baseline)
            ax.set_xlim(x_low, x_high)
            ax.set_ylim(y_low, y_high)
            ax.xaxis.set_major_locator(MaxNLocator(5))  # a narrow range of long numbers: few ticks, none colliding
            ax.yaxis.set_major_locator(MaxNLocator(6))
            ax.set_xlabel(labels[i])
            ax.set_ylabel(labels[j])
            ax.legend(fontsize=8)
    else:
        fig, ax = plt.subplots(figsize=(1.6 * k + 2, 4.5), dpi=100)
        normalized = normalized_front(run)
        for row in normalized:
            ax.plot(range(k), row, color="tab:blue", alpha=0.4, linewidth=0.8)
        if selection is not None:
            ax.plot(range(k), normalized[selection.position], color="red", linewidth=2.2, label="selected")
        if base is not None:
            ax.plot(range(k), normalized_like_front(run, base), color="black", linestyle="--", linewidth=1.6,
                    label=baseline)
        if selection is not None or base is not None:
            ax.legend(fontsize=8)
        ax.set_xticks(range(k), [o.name for o in spec.objectives], rotation=20)
        ax.set_ylabel("normalized objective (0 = best on the front)")
    fig.suptitle(f"Pareto front: {len(run.front)} designs of {run.evaluations} evaluated")
    fig.tight_layout()
    paths = [save_figure(fig, out / f"{name}.{ext}") for ext in ("png", "svg")]
    plt.close(fig)
    return paths


def index_maps(points: np.ndarray, values: dict[str, np.ndarray], title: str) -> bytes:
    """PNG of :func:`index_figure`."""
    plt = _pyplot()
    fig = index_figure(points, values, title)
    png = figure_bytes(fig, "png")
    plt.close(fig)
    return png


def index_figure(points: np.ndarray, values: dict[str, np.ndarray], title: str):
    """Each index over the workspace points (one panel per index, labelled with its unit; colour = value): the two
    axes of the box that vary for a planar workspace, a 3D scatter for a solid one, its colour bar under it (clear of
    the z axis's ticks). An index the same at every point is drawn in one colour and says so instead of a scale."""
    plt = _pyplot()
    from matplotlib.ticker import MaxNLocator

    from hapticdesign.simulation.figures import colour_scale

    varying = [k for k in range(3) if np.ptp(points[:, k]) > 0.0]
    n = len(values)
    solid = len(varying) == 3
    fig = plt.figure(figsize=(4.6 * n, 4.6 if solid else 4.0), dpi=100, layout="constrained")
    axes = varying if solid or len(varying) == 2 else (varying + [k for k in range(3) if k not in varying])[:2]
    coordinates = [points[:, k] * 1e3 for k in axes]
    for i, (label, v) in enumerate(values.items(), start=1):
        ax = fig.add_subplot(1, n, i, projection="3d" if solid else None)
        v = np.asarray(v, dtype=float)
        constant = colour_scale(v)[2]  # the value of an index the same at every point (round-off aside), else None
        if constant is not None:
            shown = ax.scatter(*coordinates, color="tab:blue", s=40 if solid else 60)
        else:
            shown = ax.scatter(*coordinates, c=v, cmap="viridis", s=40 if solid else 60)
        for k, name in zip(axes, ("set_xlabel", "set_ylabel", "set_zlabel")):
            getattr(ax, name)(f"{'xyz'[k]} (mm)", fontsize=8)
        for axis in (ax.xaxis, ax.yaxis, *((ax.zaxis,) if solid else ())):
            axis.set_major_locator(MaxNLocator(4))
        ax.tick_params(labelsize=7)
        if constant:
            ax.set_title(f"{label}\n{constant[0]:.6g} at every point", fontsize=9)
            continue
        bar = fig.colorbar(shown, ax=ax, shrink=0.8, location="bottom" if solid else "right", pad=0.08 if solid else 0.02)
        bar.set_label(label, fontsize=8)
        bar.ax.tick_params(labelsize=7)
        (bar.ax.xaxis if solid else bar.ax.yaxis).set_major_locator(MaxNLocator(4))
        ax.set_title(label, fontsize=9)
    fig.suptitle(title)
    return fig


SPREAD_COLUMNS = ("center", "median", "mean", "min", "min_at", "max", "max_at")
"""What :func:`spread_rows` gives of an index over the workspace points, in order: the value at the box's centre, the
median, the mean, the smallest and its point, the largest and its point (with how many points tie for an extreme)."""


def device_mapping(bound: BoundStudy, values: dict[str, float]) -> dict:
    """The device file's mapping with the design of variable ``values`` written in: a device file every command
    reads."""
    data = copy.deepcopy(bound.mapping)
    device_values = bound.device_values(values)
    for v in bound.space.variables:
        v.write(data, float(device_values[v.name]))
    return data


def device_file_text(bound: BoundStudy, values: dict[str, float], comments: Sequence[str] = (),
                     evaluated: bool = True) -> str:
    """:func:`device_mapping` as YAML, headed by where it comes from, the ``comments`` lines (the device file's design
    beside it) and, with ``evaluated``, where the study evaluated it (:func:`where_evaluated`; a design the device file
    refuses has no such lines, and the comments say why)."""
    shown = ", ".join(f"{k} = {v!r}" for k, v in values.items())
    names = (json.dumps(bound.study.path.name), json.dumps(bound.study.device_path.name))  # no line break in them
    header = f"# The design selected by study {names[0]} from device file {names[1]}:\n# {shown}\n"
    lines = "".join(f"# {' '.join(line.splitlines())}\n" for line in comments)  # a reason's line break stays a comment
    return (header + lines + (where_evaluated(bound, values) if evaluated else "")
            + yaml.safe_dump(device_mapping(bound, values), sort_keys=False, allow_unicode=False))


def _at_points(bound: BoundStudy, values: dict[str, float]) -> tuple[Device, WorkspacePoses | None, dict | None]:
    """A design's device, its poses at the workspace points and its indices there per request key (None, None
    without points, indices or a reached workspace)."""
    return _evaluated(bound, tuple(sorted(values.items())))


@lru_cache(maxsize=1)
def _evaluated(bound: BoundStudy, design: tuple) -> tuple[Device, WorkspacePoses | None, dict | None]:
    device = bound.space.device(bound.device_values(dict(design)))
    poses = got = None
    if len(bound.points) and bound.requests:
        try:
            poses = reach_workspace(device, bound.points)
            got = evaluate_at(device, poses.full, bound.requests, None, bound.registry).values
        except UserError:
            poses = got = None
    return device, poses, got


def where_evaluated(bound: BoundStudy, values: dict[str, float]) -> str:
    """Comment lines naming, for each index the study reduced over its workspace points, the value with how coarse
    the grid is (``max of 27 points, grid 3``) and, for ``min``, ``max`` and ``center``, the point where the design
    takes it and its actuated coordinates there, with the ``spec`` command that gives the sheet at that pose
    (issue 35: a sheet at home, outside the study's box, reads another pose's numbers; at this pose its renderable
    stiffness is the study's ``kmax`` with the same loop settings); then each pose index by every reduction
    (:func:`spread_rows`). First, which compliance between the motors and the handle ``kmax`` took
    (:meth:`BoundStudy.compliance`), when the study asks for it."""
    device, poses, got = _at_points(bound, values)
    if got is None:
        return ""
    compliance = compliance_line(bound.compliance())
    lines = [f"# {compliance}\n"] if compliance else []
    for index, options, how in bound.keys:
        label = bound.labels.get((index, options))
        if label not in got:
            continue
        named = index + (json.dumps(dict(options), sort_keys=True) if options else "")
        value = reduce(got[label], how, bound.center)
        head = (f"# {how} {named} over the study's points ({reduction_label(how, len(bound.points), bound.grid)}) = "
                f"{value:.6g} {bound.registry[index].unit}")
        k = reduced_at(got[label], how, bound.center)
        if k is None:
            lines.append(head + "\n")
            continue
        point = ", ".join(f"{x:.6g}" for x in bound.points[k])
        q = ",".join(repr(float(x)) for x in poses.q[k])
        lines.append(f"{head} at ({point}) m; the sheet there: hapticdesign spec --device THIS_FILE --q {q}\n")
    for row in spread_rows(bound, values):
        named, unit, *numbers = row
        shown = ", ".join(f"{how} {v}" for how, v in zip(SPREAD_COLUMNS, numbers) if v != "")
        lines.append(f"# {named} over the study's {bound.coarseness} ({unit}): {shown}\n")
    return "".join(lines)


def spread_rows(bound: BoundStudy, values: dict[str, float]) -> list[list]:
    """Each index of the study at the workspace's poses over the points, for a design: the index (with its options),
    its unit and :data:`SPREAD_COLUMNS` (the extremes' points as ``(x, y, z)`` in m; ``center`` blank for an even
    grid); none when the design does not reach every point."""
    _, _, got = _at_points(bound, values)
    if got is None:
        return []
    rows = []
    for r in bound.requests:
        s = spread(got[r.key], bound.center)
        named = r.index + (json.dumps(r.options, sort_keys=True) if r.options else "")
        rows.append([named, bound.registry[r.index].unit,
                     *("" if s[c] is None else f"{s[c]:.6g}" for c in ("center", "median", "mean", "min")),
                     _extreme(bound, s, "min"), f"{s['max']:.6g}", _extreme(bound, s, "max")])
    return rows


def _extreme(bound: BoundStudy, s: dict, how: str) -> str:
    """Where an extreme of :func:`~hapticdesign.analysis.metrics.indices.spread` is taken, and at how many points
    when it ties (a symmetric device's mirrored corners)."""
    ties = s[f"{how}_count"]
    return _point(bound.points[s[f"{how}_at"]]) + (f" (one of {ties} points)" if ties > 1 else "")


def _point(p: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in p) + ") m"


def pictures(bound: BoundStudy, values: dict[str, float]) -> list[tuple[bytes, str]]:
    """The selected design's picture at the workspace centre (at home when the centre is out of reach) and maps of
    its indices over the workspace points."""
    device, _, got = _at_points(bound, values)
    workspace = workspace_of(bound.study)
    if workspace is None:
        return [(render_png(device, home_pose(device), dpi=100), "The selected design at home")]
    try:
        q = reach_workspace(device, np.asarray(workspace.center, dtype=float)[None, :]).q[0]
        where = "at the workspace centre"
    except UserError:
        q = home_pose(device)
        where = "at home"
    out = [(render_png(device, q, dpi=100), f"The selected design {where}")]
    if got is not None:
        names = {r.key: f"{r.index} ({bound.registry[r.index].unit})" for r in bound.requests}
        maps = {names[key]: got[key] for key in names}
        out.append((index_maps(bound.points, maps, "The selected design's indices over the workspace"),
                    "The selected design's indices at the workspace points"))
    return out
