"""Command ``maps``: design indices of any device over a plane of its workspace, as figures and a CSV (issue 28).

The engine is :func:`hapticdesign.analysis.metrics.maps.device_map` with the one registry of design indices
(:data:`hapticdesign.analysis.metrics.indices.INDICES`, docs/indices.md).
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import note, parse_vector, print_json, progress_bar, user_errors
from hapticdesign.interface.options import DEVICE, JSON_OUT, PARAMS, PRESET, QUIET, STRICT

AXES = "xyz"


def maps(
    out: Path = typer.Option(..., "--out", help="Folder for map_<index>.png per index and maps.csv."),
    size: str = typer.Option(..., "--size", help="The plane's size along x,y,z (m): two non-zero, e.g. 0.06,0,0.06."),
    center: Optional[str] = typer.Option(None, "--center", help="The plane's centre x,y,z (m, base frame); default "
                                         "the handle at home."),
    grid: int = typer.Option(11, "--grid", help="Points per side of the plane (edges included)."),
    index: str = typer.Option("isotropy,apparent_mass", "--index", help="Comma-separated design indices "
                              "(docs/indices.md), e.g. isotropy,apparent_mass,force,kmax, or one of --indices."),
    indices: Optional[Path] = typer.Option(None, "--indices", help="A Python file of your own design indices "
                                           "(decorated with @hapticdesign.index) that --index may name. Its code "
                                           "RUNS, as 'python FILE' would."),
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
) -> None:
    """Maps of design indices over a workspace plane of any device (seed 001 ch. 4 metrics, §7.5): isotropy, apparent
    mass, force, stiffness, kmax, ..., each point reached from home by inverse kinematics; points out of reach are
    left blank."""
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.analysis.metrics.maps import device_map
    from hapticdesign.analysis.workspace import Workspace
    from hapticdesign.analysis.metrics.indices import (INDICES, compliance_line, drive_compliance, options_line,
                                                       options_used, requests_of)

    with user_errors(strict=strict, quiet=quiet):
        from hapticdesign.devices.loading import resolve_device

        from hapticdesign.interface.commands.optimize_adapter import index_module

        dev = resolve_device(preset, device, params, strict=strict)
        registry = INDICES.with_indices(index_module(indices)) if indices is not None else INDICES
        sizes = parse_vector(size, 3, "size")
        plane = [k for k in range(3) if sizes[k] != 0.0]
        if len(plane) != 2:
            raise UserError("--size: give exactly two non-zero sizes (the plane of the map), e.g. 0.06,0,0.06")
        space = configuration_of(dev)
        middle = space.position_and_jacobian(space.full(space.home))[0] if center is None else parse_vector(
            center, 3, "center")
        names = [name.strip() for name in index.split(",") if name.strip()]
        if not names:
            raise UserError(f"--index: give at least one design index (docs/indices.md), got {index[:60]!r}")
        workspace = Workspace(tuple(middle), tuple(abs(sizes)), grid)
        points = workspace.points()
        with progress_bar(not (quiet or json_out)) as report:
            found = device_map(dev, points, names, registry=registry, progress=report)
        used = options_used(requests_of(names, registry), registry)
        compliance = drive_compliance(dev, names, registry)
        files = _write(out, found, names, plane, {k: registry[k].unit for k in names})
        spreads = {k: _spread(found, k, workspace.center_index, grid) for k in names}
        note(f"wrote {len(files)} files to {out} ({int(found.reached.sum())} of {len(points)} points reached)",
             quiet or json_out)
        if json_out:
            print_json({"device": dev.name, "out": str(out), "files": files, "points": len(points),
                        "reached": int(found.reached.sum()),
                        "range": {k: [_finite(v, min), _finite(v, max)] for k, v in found.values.items()},
                        "spread": spreads, "units": {k: registry[k].unit for k in names}, "options": used,
                        **({"compliance": compliance} if compliance else {})})
            return
        for key, values in found.values.items():
            low, high = _finite(values, min), _finite(values, max)
            span = "no point reached" if low is None else f"{low:.6g} to {high:.6g} {registry[key].unit}"
            typer.echo(f"{key}: {span}" + (f" ({options_line(used[key])})" if key in used else "")
                       + _spread_line(spreads[key], len(points)))
        if compliance:
            typer.echo(compliance_line(compliance))


def _spread(found, key: str, center: int | None, grid: int) -> dict | None:
    """The index ``key`` over the points reached by every reduction
    (:func:`~hapticdesign.analysis.metrics.indices.spread`; ``center`` None when the centre is not reached), the
    extremes' points (``min_at``, ``max_at``: x, y, z in m) and how many points tie for them (``min_count``,
    ``max_count``), how many points it is over and the grid; None when no point is reached."""
    from hapticdesign.analysis.metrics.indices import spread

    reached = found.reached.nonzero()[0]
    if not len(reached):
        return None
    kept = [int(k) for k in reached]
    got = spread(found.values[key][reached], kept.index(center) if center in kept else None)
    for at in ("min_at", "max_at"):
        got[at] = [float(x) for x in found.points[reached[got[at]]]]
    return {**got, "points": len(reached), "grid": grid}


def _spread_line(got: dict | None, total: int) -> str:
    """:func:`_spread` in words: ``; over 121 of 121 points, grid 11: center ..., median ..., mean ...; min at (x, y,
    z) m, max at (...) m``."""
    if got is None:
        return ""
    center = "" if got["center"] is None else f"center {got['center']:.6g}, "
    at = {k: "(" + ", ".join(f"{x:.6g}" for x in got[f"{k}_at"]) + ") m"
          + (f" (one of {got[f'{k}_count']} points)" if got[f"{k}_count"] > 1 else "") for k in ("min", "max")}
    return (f"; over {got['points']} of {total} points, grid {got['grid']}: {center}median {got['median']:.6g}, mean "
            f"{got['mean']:.6g}; min at {at['min']}, max at {at['max']}")


def _finite(values, how) -> float | None:
    """The smallest or largest value at the points reached (None when none is)."""
    kept = [float(v) for v in values if v == v]
    return how(kept) if kept else None


def _write(out: Path, found, names: list[str], plane: list[int], units: dict[str, str]) -> list[str]:
    """map_<index>.png per index (the grid in its two axes, its unit by name in ``units``) and maps.csv (every point,
    its values or why not)."""
    import numpy as np

    from hapticdesign.analysis.metrics.maps import save_map
    from hapticdesign.files import write_atomically
    from hapticdesign.interface.report.tables import csv_text
    from hapticdesign.studies.steps import Table

    points = found.points
    first, second = plane
    xs, ys = np.unique(points[:, first]), np.unique(points[:, second])
    files = []
    for key in names:
        grid = np.full((len(xs), len(ys)), np.nan)
        grid[np.searchsorted(xs, points[:, first]), np.searchsorted(ys, points[:, second])] = found.values[key]
        path = save_map(Path(out) / f"map_{key}.png", grid, xs - xs.mean(), f"{key}", (AXES[first], AXES[second]),
                        ys - ys.mean(), unit=units[key])
        files.append(str(path))
    rows = [[*p, bool(r), *(found.values[k][i] for k in names), reason or ""]
            for i, (p, r, reason) in enumerate(zip(points, found.reached, found.reasons))]
    table = Table("maps", "design indices over the plane", ["x (m)", "y (m)", "z (m)", "reached", *names, "reason"],
                  rows)
    write_atomically(Path(out) / "maps.csv", csv_text(table))
    files.append(str(Path(out) / "maps.csv"))
    return files


def register(app: typer.Typer) -> None:
    app.command("maps")(maps)
