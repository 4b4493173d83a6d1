"""Maps show the data that matter: the colour scale from robust limits, outliers and unreached points marked
and named in a legend, the colour bar with its unit."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from hapticdesign.analysis.metrics.maps import ABOVE, draw_map, robust_limits  # noqa: E402


def test_a_few_near_singular_cells_do_not_set_the_scale():
    """An inside that varies from 1.0 to 2.0 beside three cells of 1e4 (near a singular pose) and two unreached
    points: the scale is the 2-98 % points of the values (NumPy's percentile), so the inside spans the colours."""
    values = np.linspace(1.0, 2.0, 400).reshape(20, 20)
    values[0, :3] = 1e4
    values[19, 18:] = np.nan
    fig, ax = plt.subplots()
    image = draw_map(fig, ax, values, (0, 1, 0, 1), "apparent mass [kg]")
    finite = values[np.isfinite(values)]
    assert image.get_clim() == pytest.approx(tuple(np.percentile(finite, [2, 98])))
    assert image.get_clim()[1] < 2.0  # without robust limits it was 1e4: the inside one colour
    assert image.cmap.get_over()[:3] == pytest.approx(matplotlib.colors.to_rgb(ABOVE))
    colour_bar = fig.axes[1]
    assert colour_bar.get_ylabel() == "apparent mass [kg]"
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    above = int(np.sum(finite > np.percentile(finite, 98)))
    below = int(np.sum(finite < np.percentile(finite, 2)))
    assert above >= 3 and below > 0
    assert legend == ["not reached (2)", f"above 98 % of the values ({above})", f"below 98 % of the values ({below})"]
    plt.close(fig)


def test_constant_values_keep_their_range():
    assert robust_limits(np.array([[3.0, 3.0], [3.0, np.nan]])) == (3.0, 3.0)
    assert robust_limits(np.array([np.nan])) is None
