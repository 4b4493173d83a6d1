"""Sections of the workspace the handle reaches, drawn in the spec sheet beside its workspace cube.

Each section is a plane through the home handle position: the three planes of the base axes for a spatial
device, the plane it moves in for a planar one. A square of ``3 a`` (``a`` the sheet's cube edge) in each plane
is sampled on a grid and walked in snake order; a point is reached when the inverse kinematics
(:func:`hapticdesign.analysis.configuration.handle_pose`) gets the handle there within the joint limits and
without a singularity, continued from the last point reached or, failing that, from home: the region of the
home branch the handle can reach. The cube's section (a square of edge ``a`` around home) is drawn on top.

:func:`quantity_png` maps the sheet's pose-dependent quantities (resolution, continuous force, largest apparent
mass, largest backdrive friction; :mod:`hapticdesign.studies.spec`) over the same sections, each computed at the
pose the inverse kinematics found there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hapticdesign.analysis.configuration import handle_pose
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.studies.spec import Report, no_progress

SECTION_POINTS = 15
"""Grid points per side of each section."""
SECTION_SPAN = 3.0
"""Side of each section in cube edges."""
AXES = "xyz"
SECTIONS_STEP = "workspace sections (grid lines)"
QUANTITIES_STEP = "quantities over the workspace (points reached)"


@dataclass(frozen=True)
class Section:
    """A plane through the home handle position: its axes (world unit vectors and names), grid offsets (m)
    from home along each, and which grid points the handle reaches (``reached[i, j]`` at ``u[i], v[j]``)."""

    names: tuple[str, str]
    axes: np.ndarray
    u: np.ndarray
    v: np.ndarray
    reached: np.ndarray
    poses: np.ndarray
    """Actuated coordinates at each grid point reached (``poses[i, j]``; NaN elsewhere)."""


def planes(basis: np.ndarray) -> list[tuple[tuple[str, str], np.ndarray]]:
    """The section planes: the base axes' planes for a spatial device, the plane of motion for a planar one (its
    axes in the base's order, x before y before z, each pointing along its base axis: an x-z plane, never "z-x")."""
    if basis.shape[1] == 3:
        return [((AXES[i], AXES[j]), np.eye(3)[[i, j]]) for i, j in ((0, 1), (0, 2), (1, 2))]
    axes = basis[:, :2].T.copy()
    dominant = [int(np.argmax(np.abs(axis))) for axis in axes]
    if dominant[0] > dominant[1]:
        axes, dominant = axes[::-1].copy(), dominant[::-1]
    names = []
    for axis, k in zip(axes, dominant):
        names.append(AXES[k] if abs(axis[k]) > 1.0 - 1e-9 else "u" if not names else "v")
        axis *= np.sign(axis[k])
    return [((names[0], names[1]), axes)]


def workspace_sections(device: Device, q: np.ndarray, home: np.ndarray, basis: np.ndarray, edge: float,
                       points: int = SECTION_POINTS, progress: Report = no_progress) -> list[Section]:
    """Sections of :func:`planes` (``basis``: the handle's directions of motion at home) around the handle's home
    position ``home`` (m), each ``SECTION_SPAN * edge`` wide; ``progress`` hears of each grid line walked
    (:data:`SECTIONS_STEP`)."""
    offsets = np.linspace(-0.5, 0.5, points) * SECTION_SPAN * edge
    out = []
    chosen = planes(basis)
    progress(SECTIONS_STEP, 0, len(chosen) * points)
    for names, axes in chosen:
        reached = np.zeros((points, points), dtype=bool)
        poses = np.full((points, points, len(q)), np.nan)
        last = np.asarray(q, dtype=float)
        for i in range(points):
            for j in (range(points) if i % 2 == 0 else range(points - 1, -1, -1)):
                target = home + offsets[i] * axes[0] + offsets[j] * axes[1]
                pose = _reach(device, target, last, q)
                if pose is not None:
                    reached[i, j], last = True, pose
                    poses[i, j] = pose
            progress(SECTIONS_STEP, len(out) * points + i + 1, len(chosen) * points)
        out.append(Section(names, axes, offsets, offsets.copy(), reached, poses))
    return out


def _reach(device: Device, target: np.ndarray, last: np.ndarray, home: np.ndarray) -> np.ndarray | None:
    """Actuated coordinates at ``target`` continued from ``last``, else from ``home``; None out of reach."""
    for start in (last, home) if last is not home else (home,):
        try:
            return handle_pose(device, target, start=start).q
        except UserError:
            continue
    return None


MIN_WIDTH = 6.0
"""Inches: a planar device's single panel is drawn this wide, so titles fit."""


def panel_width(panels: int) -> float:
    """Figure width (inches) for ``panels`` panels side by side."""
    return max(4.2 * panels, MIN_WIDTH)


def wrapped(title: str, fig) -> str:
    """``title`` broken into lines that fit the figure's width at 10 pt (about 0.085 inch per character)."""
    import textwrap

    width = max(20, int(fig.get_size_inches()[0] / 0.085))
    return "\n".join(textwrap.fill(line, width) for line in title.split("\n"))


def section_figure(sections: list[Section], edge: float, title: str):
    """A matplotlib figure: one panel per section, reached points filled, the cube's section outlined (mm)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap

    fig, axes = plt.subplots(1, len(sections), figsize=(panel_width(len(sections)), 4.2), squeeze=False,
                             constrained_layout=True)
    half = 500.0 * edge
    for ax, section in zip(axes[0], sections):
        step = 1000.0 * (section.u[1] - section.u[0])
        extent = (1000.0 * section.u[0] - step / 2, 1000.0 * section.u[-1] + step / 2,
                  1000.0 * section.v[0] - step / 2, 1000.0 * section.v[-1] + step / 2)
        ax.imshow(section.reached.T.astype(float), origin="lower", extent=extent, vmin=0.0, vmax=1.0,
                  cmap=ListedColormap(["#f4f4f6", "#9cc3e6"]), interpolation="nearest")
        ax.plot([-half, half, half, -half, -half], [-half, -half, half, half, -half], color="#c0392b", linewidth=1.5,
                label=f"workspace cube, {1000.0 * edge:.4g} mm")
        ax.plot([0.0], [0.0], marker="+", color="black", markersize=10, label="home")
        ax.set_xlabel(f"{section.names[0]} - home [mm]")
        ax.set_ylabel(f"{section.names[1]} - home [mm]")
        ax.set_title(f"{section.names[0]}-{section.names[1]} plane through home", fontsize=10)
        ax.set_aspect("equal")
    axes[0][0].legend(loc="lower left", fontsize=7)
    fig.suptitle(wrapped(title, fig), fontsize=10)
    return fig


def sheet_sections(device: Device, sheet: dict, points: int = SECTION_POINTS,
                   progress: Report = no_progress) -> tuple[list[Section], float]:
    """The sections around the sheet's pose (:func:`hapticdesign.studies.spec.spec_sheet` with its workspace
    cube) and the cube's edge (m)."""
    from hapticdesign.studies.spec import handle_at

    h = handle_at(device, sheet["q"])
    edge = sheet["workspace"]["cube"] / 1000.0
    if edge <= 0.0:
        raise UserError("the workspace cube is empty at this pose, so there is no section to draw around it")
    return workspace_sections(device, h.q, h.position, h.basis, edge, points, progress), edge


def workspace_png(device: Device, sections: list[Section], edge: float) -> bytes:
    """PNG of the reached sections (:func:`sheet_sections`)."""
    import matplotlib.pyplot as plt

    from hapticdesign.files import figure_bytes

    points = len(sections[0].u)
    fig = section_figure(sections, edge, f"{device.name[:60]}\nworkspace reached on the home branch "
                                         f"({points} x {points} points per plane)")
    png = figure_bytes(fig, "png", dpi=110)
    plt.close(fig)
    return png


QUANTITIES = (("resolution", "resolution", "mm"), ("force_continuous", "continuous force", "N"),
              ("apparent_mass", "largest apparent mass", "kg"), ("backdrive_friction", "largest backdrive friction",
                                                                 "N"))
"""The quantities :func:`quantity_maps` maps: key, label, unit."""


def quantity_at(device: Device, q: np.ndarray) -> dict[str, float | None]:
    """The sheet's pose-dependent quantities at actuated coordinates ``q`` (None where the file does not state
    what they need; resolution in mm, the largest apparent mass and backdrive friction)."""
    from hapticdesign.studies import spec

    h = spec.handle_at(device, q)
    step = spec.resolution(device, h)
    friction = spec.backdrive_friction(device, h)
    return {"resolution": None if step is None else 1000.0 * step,
            "force_continuous": spec.inscribed_force(device, h, "continuous"),
            "apparent_mass": spec.apparent_mass(device, h)[1],
            "backdrive_friction": None if friction is None else friction[1]}


def quantity_maps(device: Device, sections: list[Section], progress: Report = no_progress) -> dict[str, list[np.ndarray]]:
    """Each quantity of :data:`QUANTITIES` the file states, per section, on its grid (NaN where not reached);
    ``progress`` hears of each point reached (:data:`QUANTITIES_STEP`)."""
    maps: dict[str, list[np.ndarray]] = {}
    total, done = sum(int(section.reached.sum()) for section in sections), 0
    progress(QUANTITIES_STEP, 0, total)
    for k, section in enumerate(sections):
        grid = section.reached.shape
        for i, j in zip(*np.nonzero(section.reached)):
            for key, value in quantity_at(device, section.poses[i, j]).items():
                if value is not None:
                    maps.setdefault(key, [np.full(grid, np.nan) for _ in sections])[k][i, j] = value
            done += 1
            progress(QUANTITIES_STEP, done, total)
    return maps


def quantity_png(device: Device, sections: list[Section], edge: float, progress: Report = no_progress) -> bytes | None:
    """PNG of :func:`quantity_maps` (:func:`quantity_figure`; None when no quantity applies)."""
    import matplotlib.pyplot as plt

    from hapticdesign.files import figure_bytes

    fig = quantity_figure(device.name, sections, edge, quantity_maps(device, sections, progress))
    if fig is None:
        return None
    png = figure_bytes(fig, "png", dpi=100)
    plt.close(fig)
    return png


MAP_INCHES = 3.3
"""Width and height of one map of :func:`quantity_figure` (inches)."""


def quantity_figure(name: str, sections: list[Section], edge: float, maps: dict[str, list[np.ndarray]]):
    """A matplotlib figure of ``maps`` (:func:`quantity_maps`): one row per quantity, one map per section, each row on
    one colour scale (its colour bar at the row's end: a quantity reads the same across the planes) between the
    :data:`~hapticdesign.analysis.metrics.maps.ROBUST_PERCENTILES` of its values, the few beyond in the bar's end
    colours; a quantity the same at every point reached is drawn in one colour and says so instead of a scale. One
    legend under the figure names the colours that are not values. None when no quantity applies."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch
    from matplotlib.ticker import MaxNLocator

    from hapticdesign.analysis.metrics.maps import ABOVE, BELOW, ROBUST_PERCENTILES, UNREACHED, robust_limits
    from hapticdesign.simulation.figures import colour_scale

    rows = [(key, label, unit) for key, label, unit in QUANTITIES if key in maps]
    if not rows:
        return None
    columns = len(sections)
    fig, axes = plt.subplots(len(rows), columns, figsize=(MAP_INCHES * columns + 1.6, MAP_INCHES * len(rows) + 1.0),
                             squeeze=False, layout="constrained")
    half = 500.0 * edge
    beyond = False
    for r, (key, label, unit) in enumerate(rows):
        values = np.concatenate([m.ravel() for m in maps[key]])
        low, high, constant = colour_scale(values)  # a constant: one tick at its value
        if constant is None:
            low, high = robust_limits(values) or (low, high)
        finite = values[np.isfinite(values)]
        above, below = bool(np.any(finite > high)), bool(np.any(finite < low))
        beyond = beyond or above or below
        cmap = plt.get_cmap("viridis").with_extremes(bad=UNREACHED, over=ABOVE, under=BELOW)
        for ax, section, grid in zip(axes[r], sections, maps[key]):
            step = 1000.0 * (section.u[1] - section.u[0])
            extent = (1000.0 * section.u[0] - step / 2, 1000.0 * section.u[-1] + step / 2,
                      1000.0 * section.v[0] - step / 2, 1000.0 * section.v[-1] + step / 2)
            image = ax.imshow(np.ma.masked_invalid(grid).T, origin="lower", extent=extent, cmap=cmap, vmin=low,
                              vmax=high, interpolation="nearest")
            ax.plot([-half, half, half, -half, -half], [-half, -half, half, half, -half], color="#c0392b",
                    linewidth=1.0)
            ax.set_xlabel(f"{section.names[0]} - home [mm]", fontsize=8)
            ax.set_ylabel(f"{section.names[1]} - home [mm]", fontsize=8)
            ax.set_title(f"{label}, {section.names[0]}-{section.names[1]} plane", fontsize=9)
            ax.xaxis.set_major_locator(MaxNLocator(5))
            ax.yaxis.set_major_locator(MaxNLocator(5))
            ax.tick_params(labelsize=7)
            ax.set_aspect("equal")
        extend = {(False, False): "neither", (True, False): "max", (False, True): "min", (True, True): "both"}
        bar = fig.colorbar(image, ax=list(axes[r]), shrink=0.9, aspect=25, extend=extend[(above, below)])
        bar.ax.tick_params(labelsize=7)
        if constant is not None:
            value = constant[0]
            bar.set_ticks([value])
            bar.set_label(f"{label} [{unit}]: {value:.4g} at every point", fontsize=8)
        else:
            bar.set_label(f"{label} [{unit}]", fontsize=8)
    handles = [Patch(color=UNREACHED, label="not reached"), Patch(color="#c0392b", label="workspace cube")]
    if beyond:
        handles += [Patch(color=ABOVE, label=f"the highest {100 - ROBUST_PERCENTILES[1]:g} % of a row's values"),
                    Patch(color=BELOW, label=f"the lowest {ROBUST_PERCENTILES[0]:g} %")]
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 2 * columns), fontsize=8,
               frameon=False)
    fig.suptitle(wrapped(f"{name[:60]}: the sheet's quantities over the workspace reached", fig), fontsize=10)
    return fig
