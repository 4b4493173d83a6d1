"""The Pareto figure's axes come from the front's own range, not from every feasible design."""

from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pytest

from hapticdesign.optimization import study_outputs
from hapticdesign.optimization.study_outputs import Selection, pareto_figure
from hapticdesign.optimization.study_run import Record, StudyRun


def _record(f: tuple[float, float]) -> Record:
    return Record(1, (0.0,), {"l1": 0.1}, f, (), "", "", 0.0)


def test_the_front_fills_the_axes_and_the_far_designs_are_counted(tmp_path, monkeypatch):
    """A front in 0.30-0.48 kg beside feasible designs up to 1.6 kg (the issue's five-bar figure, whose axis ran
    0-1.6 kg): the mass axis spans the front with 8 % of its range on each side."""
    front = [(0.9, 0.30), (0.8, 0.36), (0.7, 0.42), (0.6, 0.48)]
    far = [(0.2, 1.6), (0.1, 1.2), (0.75, 0.45)]
    objectives = [SimpleNamespace(name="isotropy", reduce="min", index="isotropy", sense="max"),
                  SimpleNamespace(name="mass", reduce="max", index="apparent_mass", sense="min")]
    run = StudyRun(SimpleNamespace(objectives=objectives, workspace=None), 1, [_record(f) for f in front + far], [0, 1, 2, 3])
    kept = []
    monkeypatch.setattr(plt, "close", kept.append)
    monkeypatch.setattr(study_outputs, "save_figure", lambda fig, path: path)
    pareto_figure(run, Selection(1, 1, "least RMS"), tmp_path)
    ax = kept[0].axes[0]
    assert ax.get_ylim() == pytest.approx((0.30 - 0.08 * 0.18, 0.48 + 0.08 * 0.18))
    assert ax.get_xlim() == pytest.approx((0.6 - 0.08 * 0.3, 0.9 + 0.08 * 0.3))
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0] == "feasible designs (2 beyond the axes)"
    assert study_outputs.front_limits(np.array([2.0, 2.0])) == pytest.approx((1.9, 2.1))


def test_a_narrow_front_of_long_numbers_and_long_labels_stays_readable(tmp_path, monkeypatch):
    """The Falcon redesign's front (issue 45): walls 1340.4-1342.0 N/m, whose ticks ran into each other, and axis
    labels longer than the axes, which left the figure; checked in pixels (tests/helpers/figure_layout.py)."""
    from tests.helpers.figure_layout import layout_problems

    front = [(1340.4 + 0.05 * k, 0.106 + 0.001 * k) for k in range(30)]
    objectives = [SimpleNamespace(name="wall", reduce="min", index="kmax", sense="max"),
                  SimpleNamespace(name="mass", reduce="median", index="apparent_mass", sense="min")]
    box = SimpleNamespace(box=SimpleNamespace(center=(0.0, 0.0, 0.11), size=(0.1016,) * 3), grid=3)
    run = StudyRun(SimpleNamespace(objectives=objectives, workspace=box), 1, [_record(f) for f in front],
                   list(range(30)))
    kept = []
    monkeypatch.setattr(plt, "close", kept.append)
    monkeypatch.setattr(study_outputs, "save_figure", lambda fig, path: path)
    pareto_figure(run, Selection(1, 1, "least RMS"), tmp_path)
    assert layout_problems(kept[0]) == []
