"""Metric maps over planes of a workspace, saved as images (seed 001 §7.5, Figures 7.5-7.19), for the R-CUBE and
for any device (:func:`device_map`: the design indices of :mod:`.indices` point by point, issue 28)."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hapticdesign.analysis.configuration import Configuration, check_limits, configuration_of
from hapticdesign.analysis.metrics.indices import INDICES, Index, Request, evaluate_at, requests_of
from hapticdesign.analysis.metrics.indices.registry import require_evaluations
from hapticdesign.errors import UserError
from hapticdesign.files import save_figure
from hapticdesign.model.device import Device


def plane_grid(centre, half_width: float, n: int, normal_axis: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """An ``n x n`` grid ``(n, n, 3)`` on the plane through ``centre`` normal to ``normal_axis``,
    spanning ``+-half_width`` along the two other axes; returns the grid and the 1-D offsets."""
    if n < 2 or half_width <= 0.0:
        raise UserError("a map needs n >= 2 points per side and a positive half width")
    centre = np.asarray(centre, dtype=float)
    axes = [k for k in range(3) if k != normal_axis]
    offsets = np.linspace(-half_width, half_width, n)
    A, B = np.meshgrid(offsets, offsets, indexing="ij")
    grid = np.broadcast_to(centre, (n, n, 3)).copy()
    grid[..., axes[0]] += A
    grid[..., axes[1]] += B
    return grid, offsets


def evaluate_planes(
    evaluate: Callable[[np.ndarray], dict[str, np.ndarray]], centres, half_width: float, n: int, normal_axis: int = 2
) -> list[dict[str, np.ndarray]]:
    """``evaluate`` (positions ``(P, 3)`` to named metrics ``(P,)``) on each plane; maps ``(n, n)``."""
    out = []
    for c in centres:
        grid, _ = plane_grid(c, half_width, n, normal_axis)
        values = evaluate(grid.reshape(-1, 3))
        out.append({name: np.asarray(v, dtype=float).reshape(n, n) for name, v in values.items()})
    return out


ROBUST_PERCENTILES = (2.0, 98.0)
"""A map's colour scale runs between these percentiles of its values; the few beyond (near-singular points) are
marked in their own colours instead of flattening the rest into one colour."""
UNREACHED, ABOVE, BELOW = "#d0d0d0", "#e7298a", "#000000"


def robust_limits(values) -> tuple[float, float] | None:
    """The colour scale's limits: :data:`ROBUST_PERCENTILES` of the finite values (their whole range when the
    percentiles coincide; None when there is no finite value)."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    if finite.size == 0:
        return None
    low, high = (float(v) for v in np.percentile(finite, ROBUST_PERCENTILES))
    return (low, high) if high > low else (float(finite.min()), float(finite.max()))


def draw_map(fig, ax, values: np.ndarray, extent, label: str):
    """``values`` (first index along x) as a heat map on ``ax`` with a colour bar labelled ``label`` (name and
    unit): the scale from :func:`robust_limits`, values beyond it in :data:`ABOVE` / :data:`BELOW` (the colour
    bar's arrows), points not reached (NaN) in grey, each named with its count in a legend under the map."""
    from matplotlib.patches import Patch
    import matplotlib.pyplot as plt

    values = np.asarray(values, dtype=float)
    limits = robust_limits(values)
    low, high = limits if limits is not None else (0.0, 1.0)
    cmap = plt.get_cmap("viridis").with_extremes(bad=UNREACHED, over=ABOVE, under=BELOW)
    finite = values[np.isfinite(values)]
    above, below = int(np.sum(finite > high)), int(np.sum(finite < low))
    missing = int(np.sum(~np.isfinite(values)))
    image = ax.imshow(np.ma.masked_invalid(values).T, origin="lower", extent=extent, cmap=cmap, vmin=low, vmax=high,
                      interpolation="nearest")
    extend = {(False, False): "neither", (True, False): "max", (False, True): "min", (True, True): "both"}
    fig.colorbar(image, ax=ax, label=label, shrink=0.85, extend=extend[(above > 0, below > 0)])
    handles = [Patch(color=colour, label=f"{text} ({count})") for colour, text, count in (
        (UNREACHED, "not reached", missing), (ABOVE, f"above {ROBUST_PERCENTILES[1]:g} % of the values", above),
        (BELOW, f"below {100 - ROBUST_PERCENTILES[0]:g} % of the values", below)) if count]
    if handles:
        ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=len(handles),
                  frameon=False)
    return image


def save_map(path: Path, values: np.ndarray, offsets: np.ndarray, title: str, labels: tuple[str, str],
             offsets_y: np.ndarray | None = None, unit: str = "") -> Path:
    """One metric map as a PNG heat map (matplotlib Agg backend, :func:`draw_map`); ``offsets`` along the first
    axis (and the second unless ``offsets_y`` is given), m from the centre; ``unit`` of the values for the colour
    bar."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    second = offsets if offsets_y is None else offsets_y
    extent = (offsets[0] * 1e3, offsets[-1] * 1e3, second[0] * 1e3, second[-1] * 1e3)
    fig, ax = plt.subplots(figsize=(4.8, 4.4), dpi=100)
    draw_map(fig, ax, values, extent, f"{title.split(',')[0]} [{unit or '-'}]")
    ax.set_title(title)
    ax.set_xlabel(f"{labels[0]} (mm from centre)")
    ax.set_ylabel(f"{labels[1]} (mm from centre)")
    fig.tight_layout()
    path = save_figure(fig, path)
    plt.close(fig)
    return path


@dataclass(frozen=True)
class DeviceMap:
    """Design indices point by point: values per request key (P,) (NaN where the handle does not reach the point),
    whether each point is reached, and why not (one line per point, None where reached)."""

    points: np.ndarray
    values: dict[str, np.ndarray]
    reached: np.ndarray
    reasons: list[str | None]


def _reach(device: Device, space: Configuration, point: np.ndarray, frame: str | None,
           start: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The pose of ``point`` from the last point reached, or else straight from home (the one meaning of reached,
    :func:`~hapticdesign.analysis.workspace.reach_workspace`)."""
    try:
        q_a, q = space.reach(point[None], frame, start)
        check_limits(device, q_a, point[None])
    except UserError:
        if start is None:
            raise
        q_a, q = space.reach(point[None], frame)
        check_limits(device, q_a, point[None])
    return q_a, q


REACH_STEP = "reaching the map's points (inverse kinematics)"
INDICES_STEP = "design indices at the points reached"


def device_map(device: Device, points: np.ndarray, requests: Iterable[str | Request], frame: str | None = None,
               registry: Mapping[str, Index] = INDICES,
               progress: Callable[[str, int, int | None], None] | None = None) -> DeviceMap:
    """The indices ``requests`` at each of ``points`` (P, 3) that the handle reaches: in order, each from the last
    point reached, or else straight from home (from home at first and after a point out of reach), by the project's
    inverse kinematics
    (:meth:`~hapticdesign.analysis.configuration.Configuration.reach`, within the joint limits); a point the
    handle does not reach is NaN with its reason, and the map goes on. ``progress(step, done, total)`` hears of each
    point (:data:`REACH_STEP`) and of the indices' one batch (:data:`INDICES_STEP`)."""
    report = progress or (lambda step, done, total: None)
    checked = requests_of(requests, registry)
    points = np.asarray(points, dtype=float)
    require_evaluations(f"a map of {len(points)} points", len(points), [r.index for r in checked], registry)
    space = configuration_of(device)
    full, reasons, start = [], [], None
    report(REACH_STEP, 0, len(points))
    for k, point in enumerate(points, start=1):
        try:
            q_a, q = _reach(device, space, point, frame, start)
        except UserError as exc:
            reasons.append(str(exc))
            start = None
            report(REACH_STEP, k, len(points))
            continue
        reasons.append(None)
        full.append(q[0])
        start = q[0]
        report(REACH_STEP, k, len(points))
    reached = np.array([r is None for r in reasons], dtype=bool)
    values = {r.key: np.full(len(points), np.nan) for r in checked}
    if full:
        report(INDICES_STEP, 0, None)
        found = evaluate_at(device, np.array(full), checked, frame, registry).values
        report(INDICES_STEP, 1, 1)
        for key, v in found.items():
            values[key][reached] = v
    return DeviceMap(points, values, reached, reasons)
