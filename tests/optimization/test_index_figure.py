"""The study report's "indices over the workspace" figure reads: for a solid workspace the z ticks clear of the colour
bars, for a planar one the panels apart, and an index the same at every point shown as one value, not a colour range
(issue 45 item 5).

Oracle: the drawn figure's own boxes in pixels (:func:`tests.helpers.figure_layout.layout_problems`)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from hapticdesign.optimization.study_outputs import index_figure
from tests.helpers.figure_layout import layout_problems


def _points(solid: bool) -> np.ndarray:
    axis = np.linspace(-0.04, 0.04, 5)
    if solid:
        return np.array([(x, y, 0.11 + z) for x in axis for y in axis for z in axis])
    return np.array([(x, 0.0, 0.11 + z) for x in axis for z in axis])


def _values(points: np.ndarray) -> dict[str, np.ndarray]:
    r = np.linalg.norm(points - points.mean(axis=0), axis=1)
    return {"isotropy (1)": 0.9 - r, "apparent_mass (kg)": 0.1 + 2.0 * r ** 2, "force (N)": np.full(len(r), 3.5)}


@pytest.mark.parametrize("solid", [True, False])
def test_the_index_panels_leave_room_for_their_ticks_and_bars(solid):
    points = _points(solid)
    fig = index_figure(points, _values(points), "The selected design's indices over the workspace")
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert len(panels) == 3
    assert layout_problems(fig, min_map_px=250.0, maps=panels) == []
    plt.close(fig)


def test_a_constant_index_has_no_colour_range():
    points = _points(True)
    fig = index_figure(points, _values(points), "indices")
    assert len(fig.axes) == 3 + 2  # two colour bars: the constant force has none
    assert fig.axes[-1].get_title() == "force (N)\n3.5 at every point"
    plt.close(fig)
