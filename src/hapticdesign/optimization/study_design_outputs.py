"""What a study's output says of one design of a bound study (:mod:`.study_evaluation`): its device file (selected.yaml
and each front design's), where the study's indices are taken over the workspace points, their spread, and its
pictures (the report).

A design's device, poses at the workspace points and indices there are computed once for all of these
(:func:`_at_points`, the last design kept).
"""

from __future__ import annotations

import copy
import json
from collections.abc import Sequence
from functools import lru_cache

import numpy as np
import yaml

from hapticdesign.analysis.metrics.indices import evaluate_at, reduce, reduced_at, reduction_label, spread
from hapticdesign.analysis.view.figure import render_png
from hapticdesign.analysis.view.skeleton import home_pose
from hapticdesign.analysis.workspace import WorkspacePoses, reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.optimization.study_evaluation import BoundStudy, workspace_of
from hapticdesign.optimization.study_outputs import index_maps

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


def device_file_text(bound: BoundStudy, values: dict[str, float], comments: Sequence[str] = ()) -> str:
    """:func:`device_mapping` as YAML, headed by where it comes from, the ``comments`` lines (the device file's design
    beside it) and where the study evaluated it (:func:`where_evaluated`)."""
    shown = ", ".join(f"{k} = {v!r}" for k, v in values.items())
    names = (json.dumps(bound.study.path.name), json.dumps(bound.study.device_path.name))  # no line break in them
    header = f"# The design selected by study {names[0]} from device file {names[1]}:\n# {shown}\n"
    lines = "".join(f"# {' '.join(line.splitlines())}\n" for line in comments)  # a reason's line break stays a comment
    return (header + lines + where_evaluated(bound, values)
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
    (:func:`spread_rows`)."""
    device, poses, got = _at_points(bound, values)
    if got is None:
        return ""
    lines = []
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
