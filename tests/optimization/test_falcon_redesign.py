"""The Falcon redesign of docs/optimization.md (examples/studies/falcon-redesign.yaml; issue 45 item 7).

Oracles: the committed front (docs/figures/optimization/falcon-redesign/front.csv, written by
docs/scripts/falcon_redesign.py) re-evaluated on this machine; the published Falcon's own geometry, which does not
reach Novint's 4-inch cube (its largest cube is 90.0 mm); the moving mass of falcon.yaml's bodies (176 g)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import load_study
from hapticdesign.optimization.study_outputs import without_unit

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "examples" / "studies" / "falcon-redesign.yaml"
FRONT = ROOT / "docs" / "figures" / "optimization" / "falcon-redesign" / "front.csv"
PUBLISHED = {"a": 0.060, "b": 0.1025, "ratio": 0.110 / 0.01425, "rod": 1.0}


@pytest.fixture(scope="module")
def bound():
    return bind_study(load_study(STUDY))


def test_the_published_falcon_misses_novints_cube(bound):
    """The published geometry (rod = 1: falcon.yaml's masses) reaches a 90.0 mm cube, not the study's 101.6 mm; the
    device file fixes no `rod`, so the report has no device file's design and says why."""
    values, why = bound.baseline()
    assert values is None and "states no value of variable rod" in why
    answer = StudyEvaluator(bound)([PUBLISHED])[0]
    assert answer.reason.startswith("the handle cannot reach")
    assert bound.space.base.reference == "falcon"


def test_the_moving_mass_at_the_published_design_is_falcon_yamls(bound):
    """The study's `mass` constraint bound, 0.176 kg, is the published file's bodies (3 x 30 g + 3 x 12 g + 50 g)."""
    from hapticdesign.analysis.metrics.indices import INDICES, HandleStates
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.devices.loading import load_device

    device = load_device(ROOT / "examples" / "devices" / "falcon.yaml")
    states = HandleStates(device, configuration_of(device).full(configuration_of(device).home)[None])
    assert float(INDICES["mass"].values(states, {})[0]) == pytest.approx(0.176, abs=1e-12)


def test_the_documented_front_holds_on_this_machine(bound):
    with open(FRONT, newline="") as handle:
        rows = [{without_unit(k): v for k, v in row.items()} for row in csv.DictReader(handle)]
    names = list(bound.study.spec.variables)
    assert len(rows) == 22
    answers = StudyEvaluator(bound)([{name: float(row[name]) for name in names} for row in rows])
    for row, answer in zip(rows, answers):
        assert answer.reason == ""
        stated = [float(v) for k, v in row.items() if k not in ("design", "polished", *names)]
        np.testing.assert_allclose(answer.reduced, stated, rtol=1e-9, err_msg=row["design"])
        assert stated[2] <= 0.176 and stated[3] >= 8.9 - 1e-9
