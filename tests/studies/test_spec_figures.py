"""The spec sheet's "Quantities over the workspace" figure reads: maps a reader can see, one colour bar per quantity,
nothing cut or overlapping (issue 45 item 5: maps about 40 px wide in a 1260 x 1440 figure, huge colour bars,
clipped legends, ticks running into each other).

Oracle: the drawn figure's own boxes in pixels (matplotlib's window extents), checked by
:func:`tests.helpers.figure_layout.layout_problems`."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from hapticdesign.studies.spec_maps import MAP_INCHES, Section, quantity_figure
from tests.helpers.figure_layout import layout_problems

POINTS = 15


def _sections(planes: int, edge: float) -> list[Section]:
    """Sections of a device that reaches a disc of 1.2 cube edges around home (grey corners)."""
    offsets = np.linspace(-0.5, 0.5, POINTS) * 3.0 * edge
    u, v = np.meshgrid(offsets, offsets, indexing="ij")
    reached = np.hypot(u, v) < 1.2 * edge
    names = [("x", "y"), ("x", "z"), ("y", "z")][:planes]
    return [Section(n, np.eye(3)[:2], offsets, offsets.copy(), reached, np.zeros((POINTS, POINTS, 3)))
            for n in names]


def _maps(sections: list[Section]) -> dict[str, list[np.ndarray]]:
    """Four quantities: a smooth one, a constant, one with a near-singular spike, one of large values."""
    out: dict[str, list[np.ndarray]] = {}
    for k, s in enumerate(sections):
        u, v = np.meshgrid(s.u, s.v, indexing="ij")
        smooth = 0.03 + 0.2 * (u ** 2 + v ** 2) + 0.01 * k
        spike = 0.05 + 0.1 * np.abs(u)
        spike[POINTS // 2, POINTS // 2 + 1] = 40.0
        for key, grid in (("resolution", smooth), ("force_continuous", np.full_like(u, 3.25)),
                          ("apparent_mass", spike), ("backdrive_friction", 1000.0 + 2e4 * np.abs(v))):
            out.setdefault(key, []).append(np.where(s.reached, grid, np.nan))
    return out


@pytest.mark.parametrize("planes, edge", [(3, 0.0927), (1, 0.2), (3, 0.147)])
def test_the_quantity_maps_are_wide_one_bar_a_row_and_nothing_overlaps(planes, edge):
    sections = _sections(planes, edge)
    fig = quantity_figure("falcon", sections, edge, _maps(sections))
    maps = [ax for ax in fig.axes if ax.images]
    assert len(maps) == 4 * planes
    bars = [ax for ax in fig.axes if not ax.images]
    assert len(bars) == 4  # one colour bar per quantity, not per map
    assert layout_problems(fig, min_map_px=0.7 * MAP_INCHES * fig.dpi, maps=maps) == []
    for bar in bars:  # a bar no wider than a tenth of a map
        assert bar.get_window_extent().width < 0.1 * maps[0].get_window_extent().width
    plt.close(fig)


def test_a_constant_quantity_says_so_instead_of_a_colour_range():
    sections = _sections(3, 0.1)
    fig = quantity_figure("falcon", sections, 0.1, _maps(sections))
    labels = [ax.get_ylabel() for ax in fig.axes if not ax.images]
    assert labels[1] == "continuous force [N]: 3.25 at every point"
    assert [t.get_text() for t in fig.axes[-3].get_yticklabels()] == ["3.25"]
    assert labels[0] == "resolution [mm]"
    plt.close(fig)


def test_the_checker_sees_the_old_layout_as_broken():
    """The checker itself: per-map colour bars and legends under 40-px maps (the figure before issue 45) fail it."""
    from hapticdesign.analysis.metrics.maps import draw_map

    sections = _sections(3, 0.0927)
    maps = _maps(sections)
    fig, axes = plt.subplots(4, 3, figsize=(12.6, 14.4), squeeze=False, constrained_layout=True)
    for r, key in enumerate(maps):
        for ax, section, values in zip(axes[r], sections, maps[key]):
            draw_map(fig, ax, values, (-139, 139, -139, 139), f"{key} [unit]")
            ax.set_title(f"{key}, x-y plane", fontsize=9)
    assert layout_problems(fig, min_map_px=0.7 * MAP_INCHES * 100, maps=list(axes.ravel()))
    plt.close(fig)
