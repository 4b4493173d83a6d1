"""Study runs on a planar two-link arm: known optima, a front against brute force, determinism, resume.

Oracles: the closed form of the two-link arm (isotropic exactly at ``l2 / l1 = 1 / sqrt(2)`` with the elbow at
135 degrees, i.e. at the distance ``l1 / sqrt(2)`` from the shoulder; Salisbury & Craig 1982), exhaustive
enumeration of a discrete design space, a dense grid's non-dominated set compared by pymoo's hypervolume
indicator, and the uninterrupted run (for resume).
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from pymoo.indicators.hv import HV
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from hapticdesign.optimization.pymoo_run import NSGA_II
from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import load_study
from hapticdesign.optimization.study_outputs import front_csv
from hapticdesign.optimization.study_run import run_study
from tests.helpers.planar_arm import planar_arm

L1 = 0.2
ANGLE = 0.7


def point(r: float) -> list[float]:
    """A point of the arm's plane (x-z) at distance ``r`` from the shoulder."""
    return [r * math.cos(ANGLE), 0.0, r * math.sin(ANGLE)]


def write_study(folder: Path, variables: dict, objectives: list, population: int, generations: int,
                center=None, size=(0.0, 0.0, 0.0), grid: int = 1, constraints=(), polish: str = "none") -> Path:
    """A study of the planar arm; ``polish: none`` stated by default: these tests test the raw search (a study file
    without it polishes the front's ends)."""
    (folder / "arm.yaml").write_text(yaml.safe_dump(planar_arm(L1)))
    study = {"device": "arm.yaml", "variables": variables,
             "workspace": {"box": {"center": center or point(L1 / math.sqrt(2.0)), "size": list(size)}, "grid": grid},
             "objectives": objectives, "constraints": list(constraints),
             "algorithm": {"method": "nsga2", "population": population, "generations": generations, "polish": polish}}
    (folder / "study.yaml").write_text(yaml.safe_dump(study, sort_keys=False))
    return folder / "study.yaml"


ISOTROPY = {"name": "iso", "index": "isotropy", "reduce": "min", "sense": "max"}
MASS = {"name": "mass", "index": "apparent_mass", "reduce": "mean", "sense": "min"}


def best(run, k: int = 0):
    return run.records[run.front[0]]


def test_single_objective_finds_the_isotropic_two_link_arm(tmp_path):
    path = write_study(tmp_path, {"l2": [0.08, 0.3]}, [ISOTROPY], population=12, generations=40)
    study = load_study(path)
    run = run_study(study, 3, StudyEvaluator(bind_study(study)), algorithm=NSGA_II)
    top = best(run)
    assert len(run.front) == 1
    assert top.values["l2"] == pytest.approx(L1 / math.sqrt(2.0), rel=1e-3)  # 0.14 mm of 141 mm
    assert top.objectives[0] == pytest.approx(1.0, abs=1e-3)


def test_single_objective_over_choices_finds_the_brute_force_optimum(tmp_path):
    l2_values = [0.09, 0.11, 0.13, 0.15, 0.17, 0.19]
    ratios = [5.0, 8.0, 11.2, 13.3, 20.0]
    variables = {"l2": {"values": l2_values}, "actuators.q1.gear_ratio": {"values": ratios}}
    path = write_study(tmp_path, variables, [MASS], population=8, generations=8,
                       center=point(0.15), size=(0.02, 0.0, 0.02), grid=2)
    study = load_study(path)
    bound = bind_study(study)
    designs = [{"l2": a, "actuators.q1.gear_ratio": b} for a, b in itertools.product(l2_values, ratios)]
    masses = [answer.reduced[0] for answer in StudyEvaluator(bound)(designs)]
    run = run_study(study, 5, StudyEvaluator(bound), algorithm=NSGA_II)
    assert best(run).values == designs[int(np.argmin(masses))]
    assert best(run).objectives[0] == min(masses)
    assert run.evaluations < len(designs) * 2


def test_two_objective_front_against_a_brute_force_front(tmp_path):
    variables = {"l2": [0.09, 0.3], "actuators.q2.gear_ratio": [4.0, 20.0]}
    path = write_study(tmp_path, variables, [ISOTROPY, MASS], population=16, generations=12,
                       center=point(0.15), size=(0.02, 0.0, 0.02), grid=2)
    study = load_study(path)
    bound = bind_study(study)
    grid = [{"l2": a, "actuators.q2.gear_ratio": b}
            for a, b in itertools.product(np.linspace(0.09, 0.3, 15), np.linspace(4.0, 20.0, 8))]
    answers = [a for a in StudyEvaluator(bound)(grid) if not a.reason]
    brute = np.array([[-a.reduced[0], a.reduced[1]] for a in answers])  # minimized: -isotropy, mass
    brute = brute[NonDominatedSorting().do(brute, only_non_dominated_front=True)]
    run = run_study(study, 11, StudyEvaluator(bound), algorithm=NSGA_II)
    found = np.array([[-run.records[k].objectives[0], run.records[k].objectives[1]] for k in run.front])
    reference = np.max(np.vstack([brute, found]), axis=0) + 0.05 * np.ptp(np.vstack([brute, found]), axis=0)
    hv_brute, hv_found = HV(ref_point=reference)(brute), HV(ref_point=reference)(found)
    assert hv_found >= 0.97 * hv_brute, (hv_found, hv_brute)


def small_study(tmp_path) -> Path:
    variables = {"l2": [0.09, 0.3], "actuators.q2.gear_ratio": {"values": [4.0, 8.0, 16.0]}}
    return write_study(tmp_path, variables, [ISOTROPY, MASS], population=8, generations=4,
                       center=point(0.15), size=(0.02, 0.0, 0.02), grid=2,
                       constraints=[{"expression": "l2", "<=": 0.25}])


def test_same_seed_same_front_other_seed_other_designs(tmp_path):
    study = load_study(small_study(tmp_path))
    evaluate = StudyEvaluator(bind_study(study))
    a, b, c = (run_study(study, seed, evaluate, algorithm=NSGA_II) for seed in (2, 2, 3))
    assert front_csv(a) == front_csv(b)
    assert [r.x for r in a.records] == [r.x for r in b.records]
    assert [r.x for r in a.records] != [r.x for r in c.records]


class Interrupt(Exception):
    pass


def test_an_interrupted_run_continues_from_its_checkpoint_and_ends_with_the_same_front(tmp_path):
    study = load_study(small_study(tmp_path))
    bound = bind_study(study)
    whole = run_study(study, 4, StudyEvaluator(bound), algorithm=NSGA_II)
    asked = []

    def counting(batch):
        asked.append(len(batch))
        return StudyEvaluator(bound)(batch)

    def stop_after_two(generation, total):
        if generation == 2:
            raise Interrupt

    with pytest.raises(Interrupt):
        run_study(study, 4, counting, tmp_path / "out", stop_after_two, algorithm=NSGA_II)
    first = len(asked)
    resumed = run_study(study, 4, counting, tmp_path / "out", algorithm=NSGA_II)
    assert first == 2 and len(asked) == first + 2  # generations 3 and 4 only
    assert front_csv(resumed) == front_csv(whole)
    assert [r.objectives for r in resumed.records] == [r.objectives for r in whole.records]


def _reasons_blanked(data: dict) -> None:
    """The infeasible designs' reasons emptied: they would read as valid designs whose answers are NaN."""
    data["reasons"] = ["" for _ in data["reasons"]]


def _reasons_reworded(data: dict) -> None:
    """Every infeasible design's reason replaced by another text (the valid designs' empty ones kept)."""
    data["reasons"] = [reason and "the handle cannot reach any point" for reason in data["reasons"]]


@pytest.mark.parametrize("alter", [_reasons_blanked, _reasons_reworded])
def test_a_checkpoint_whose_reasons_were_edited_is_not_trusted(tmp_path, alter):
    """A generation's file with infeasible designs (the evaluator's own reasons, for an arm too short for the
    workspace) loads back as saved; with its reasons edited (values, designs and checksum untouched) it fails the
    checksum: ``load`` returns None and warns that the file is not trusted."""
    from hapticdesign.errors import RunWarning
    from hapticdesign.optimization.study_run import Checkpoint

    study = load_study(small_study(tmp_path))
    designs = [{"l2": 0.15, "actuators.q2.gear_ratio": 4.0}, {"l2": 0.02, "actuators.q2.gear_ratio": 8.0},
               {"l2": 0.2, "actuators.q2.gear_ratio": 16.0}, {"l2": 0.03, "actuators.q2.gear_ratio": 4.0}]
    answers = StudyEvaluator(bind_study(study))(designs)
    assert [bool(a.reason) for a in answers] == [False, True, False, True]  # l1 - l2 > 0.15 m: out of reach
    X = np.array([[d["l2"], float(k)] for d, k in zip(designs, (0, 1, 2, 0))])
    checkpoint = Checkpoint(tmp_path / "out", study, 5)
    checkpoint.save(1, X, answers)
    loaded = checkpoint.load(1, X)
    assert [a.reason for a in loaded] == [a.reason for a in answers]
    path = tmp_path / "out" / "generation-0001.json"
    data = json.loads(path.read_text())
    alter(data)
    assert data["reasons"] != [a.reason for a in answers]
    path.write_text(json.dumps(data))
    with pytest.warns(RunWarning, match="checksum does not match"):
        assert checkpoint.load(1, X) is None


def test_when_no_design_reaches_the_workspace_the_closest_is_the_one_reaching_the_most_points(tmp_path):
    """Four workspace points on the base's x axis at 0.30, 0.33, 0.36 and 0.39 m from the shoulder; the forearm
    ``l2`` is 0.12, 0.15 or 0.18 m, so by the two-link closed form (``r <= l1 + l2``) a design reaches 1, 2 or 3 of
    them and none the whole workspace. The empty front's message names, among the last generation's designs, one
    whose closed-form count is the largest there, and states that count (the generation holds designs of different
    counts, so the design reaching the fewest would be another)."""
    from hapticdesign.optimization.study_methods import CLOSEST_CANDIDATES, METHODS
    from tests.helpers.planar_arm import points_reached

    xs = (0.30, 0.33, 0.36, 0.39)
    path = write_study(tmp_path, {"l2": {"values": [0.12, 0.15, 0.18]}}, [ISOTROPY], population=8, generations=2,
                       center=[sum(xs) / 4, 0.0, 0.0], size=(xs[-1] - xs[0], 0.0, 0.0), grid=4)
    study = load_study(path)
    bound = bind_study(study)
    assert np.allclose(sorted(p[0] for p in bound.points), xs) and len(bound.points) == 4
    run = run_study(study, 1, StudyEvaluator(bound), algorithm=NSGA_II)
    assert all(r.invalid for r in run.records)
    last = [r for r in run.records if r.generation == run.records[-1].generation][:CLOSEST_CANDIDATES]
    counts = {r.values["l2"]: points_reached(L1, r.values["l2"], [(x, 0.0, 0.0) for x in xs]) for r in last}
    assert len(set(counts.values())) > 1, counts
    most = max(counts.values())
    (closest,) = [l2 for l2, n in counts.items() if n == most]
    message = str(METHODS["nsga2"].empty_front(run, bound))
    assert f"the closest (l2 = {closest:.6g}) reaches {most} of 4 points" in message, message
