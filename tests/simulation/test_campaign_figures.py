"""Campaign figures show the data that matter: a spread below a tenth of the value is drawn flat, not as a trend."""

from types import SimpleNamespace

import numpy as np
import pytest

from hapticdesign.simulation import figures


@pytest.fixture
def drawn(monkeypatch):
    """The figures a function draws, kept open instead of saved."""
    kept = []
    monkeypatch.setattr(figures, "_save", lambda fig, path: kept.append(fig))
    return kept


def _campaign(values: dict[float, list[float]]):
    designs, cases = [], {}
    for level, column in values.items():
        for i, value in enumerate(column):
            d = SimpleNamespace(name=f"{level}-{i}", level=level)
            designs.append(d)
            for sim_type in (1, 2):
                cases[(d.name, "transparency", sim_type)] = {"value": value}
    return designs, cases


def test_a_bandwidth_spread_of_0_6_percent_is_drawn_on_an_axis_of_10_percent(drawn, tmp_path):
    """The issue's beeswarm: 1.266-1.275 Hz filled the axis; now the axis spans 10 % of the mean (0.127 Hz)
    around the values and the title says so."""
    designs, cases = _campaign({0.0: [1.266, 1.27, 1.275], 1.0: [1.268, 1.271, 1.274]})
    figures.beeswarm(designs, cases, "transparency", tmp_path / "b")
    ax = drawn[0].axes[0]
    low, high = ax.get_ylim()
    mean = np.mean([1.266, 1.27, 1.275, 1.268, 1.271, 1.274])
    assert high - low == pytest.approx(0.1 * mean)
    assert low < 1.266 and high > 1.275 and (low + high) / 2 == pytest.approx((1.266 + 1.275) / 2)
    assert "axis spans 10 % of the mean" in ax.get_title()
    figures.type_comparison(designs, cases, "transparency", tmp_path / "c")
    panel = drawn[1].axes[0]
    assert np.diff(panel.get_ylim())[0] == pytest.approx(0.1 * np.mean([1.266, 1.27, 1.275]))


def test_a_real_spread_keeps_matplotlibs_axis(drawn, tmp_path):
    designs, cases = _campaign({0.0: [1.0, 2.0, 3.0]})
    figures.beeswarm(designs, cases, "transparency", tmp_path / "b")
    ax = drawn[0].axes[0]
    low, high = ax.get_ylim()
    assert low <= 1.0 and high >= 3.0 and high - low < 2.5
    assert "axis spans" not in ax.get_title()
    assert figures.value_limits([np.nan]) is None
