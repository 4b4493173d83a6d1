"""Seed 001's R-CUBE synthesis as a study file (examples/studies/rcube-synthesis.yaml) through the generic path:
the same front as the specific path (:func:`hapticdesign.optimization.rcube.synthesis.synthesize`) on the same seed,
its shortest design the KKT-certified constrained minimum (:mod:`hapticdesign.optimization.rcube.shortest`, found
without NSGA-II), and the study file's new parts (formulas, runs, keep) refusing bad input in one line."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app
from hapticdesign.optimization.formula import formula
from hapticdesign.optimization.rcube.shortest import constrained_minimum
from hapticdesign.optimization.pymoo_run import NSGA_II
from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import load_study
from hapticdesign.optimization.study_outputs import front_csv
from hapticdesign.optimization.study_run import run_study
from hapticdesign.optimization.rcube.synthesis import BOUND_SETS, hypervolume, synthesize

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
STUDY = EXAMPLES / "studies" / "rcube-synthesis.yaml"
POPULATION, GENERATIONS, SEED = 24, 15, 1
"""The specific path's --quick synthesis size (hapticdesign.optimization.rcube.chain.Settings.quick)."""


def study_file(folder: Path, **changes) -> Path:
    """The example study with the device path made absolute and ``changes`` to its mapping (merged into
    ``algorithm``, in place of the others)."""
    data = yaml.safe_load(STUDY.read_text())
    data["device"] = str(EXAMPLES / "devices" / "rcube.yaml")
    for key, value in changes.items():
        data[key] = {**data[key], **value} if key == "algorithm" else value
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def run_generic(path: Path):
    study = load_study(path)
    bound = bind_study(study)
    evaluate = StudyEvaluator(bound)
    return study, run_study(study, SEED, evaluate, None, None, evaluate.constraints, algorithm=NSGA_II)


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    path = study_file(tmp_path_factory.mktemp("rcube"), algorithm={"population": POPULATION, "generations": GENERATIONS})
    study, generic = run_generic(path)
    specific = synthesize(BOUND_SETS, POPULATION, GENERATIONS, SEED)
    return study, generic, specific


def _generic_front(study, run) -> tuple[np.ndarray, np.ndarray]:
    """The generic front as the specific path holds it: rows (q_max, l2, l3) and (O1, O2, O3), by total length."""
    X = np.array([run.records[k].x for k in run.front])
    F = np.array([run.records[k].objectives for k in run.front])
    length = [study.spec.with_parameters(run.records[k].values)["l1"] + X[i, 1] + X[i, 2]
              for i, k in enumerate(run.front)]
    order = np.argsort(length)
    return X[order], F[order]


def test_the_study_gives_the_specific_paths_front_on_the_same_seed(both):
    study, generic, specific = both
    X, F = _generic_front(study, generic)
    assert len(X) == len(specific.front) > 0
    # the same designs and objectives; the generic path reads l1 = 0.06 / sin(q_max) back as q_max = asin(0.06 / l1),
    # so values agree to rounding
    np.testing.assert_allclose(X, specific.front.X, rtol=1e-9)
    np.testing.assert_allclose(F, specific.front.F, rtol=1e-9)
    assert hypervolume(F) == pytest.approx(specific.hypervolume, rel=1e-9)
    # every design of all three runs was evaluated once, as in the specific path (3 x population x generations)
    assert generic.evaluations == 3 * POPULATION * GENERATIONS


def test_the_studys_shortest_design_is_the_certified_constrained_minimum(both):
    study, generic, _ = both
    lengths = [sum(study.spec.with_parameters(generic.records[k].values)[n] for n in ("l1", "l2", "l3"))
               for k in generic.front]
    minimum = constrained_minimum(BOUND_SETS, starts=32, seed=SEED)
    assert minimum.certificate.strict_local_minimum
    assert min(lengths) == pytest.approx(minimum.total_length, abs=1e-9)
    start = study.spec.with_parameters(generic.start)
    assert start["l1"] + start["l2"] + start["l3"] == pytest.approx(minimum.total_length, abs=1e-9)
    # the numbers of docs/optimization.md: 112.6 + 74.1 + 121.7 = 308.4 mm at q_max 32.18 deg
    assert round(min(lengths) * 1e3, 1) == 308.4
    assert round(math.degrees(generic.start["q_max"]), 2) == 32.18


def test_objectives_are_computed_only_for_designs_that_meet_the_constraints(both):
    _, generic, specific = both
    with_objectives = [r for r in generic.records if np.all(np.isfinite(r.objectives))]
    assert all(r.feasible for r in with_objectives)
    assert len(with_objectives) == specific.evaluations  # the specific path counts its O2/O3 evaluations


def test_rcube_o1_is_the_tangent_of_the_travel_that_covers_the_cube(tmp_path):
    """O1 = tan q_max with sin q_max = h / l1 (eq. 6.24, 6.82): h / sqrt(l1^2 - h^2), written here, at a design that
    meets the constraints (so that its objectives are computed)."""
    bound = bind_study(load_study(study_file(tmp_path)))
    q = 0.5
    answer = StudyEvaluator(bound)([{"q_max": q, "l2": 0.1, "l3": 0.15}])[0]
    assert answer.reason == "" and all(np.isfinite(answer.reduced))
    l1 = 0.06 / math.sin(q)
    assert answer.reduced[0] == pytest.approx(0.06 / math.sqrt(l1 ** 2 - 0.06 ** 2), rel=1e-12)


def test_formulas_are_data_not_code():
    assert formula("0.06 / sin(q_max)").value({"q_max": math.pi / 6}) == pytest.approx(0.12)
    assert formula("-l1 ** 2 + 2*pi").value({"l1": 3.0}) == pytest.approx(-9.0 + 2 * math.pi)
    hostile = ("__import__('os').system('true')", "q.real", "x[0]", "open('f')", "'a'", "lambda: 1", "True",
               "-" * 900 + "1", "(" * 300 + "1" + ")" * 300, "9" * 999, "1e400", "1" * 1001)
    for text in hostile:
        with pytest.raises(UserError):
            formula(text)


@pytest.mark.parametrize("change, message", [
    ({"parameters": {"l1": "0.06 / sin(q)", "S": "l1"}}, "'q' in '0.06 / sin(q)' is not a variable"),
    ({"parameters": {"l1": "0.06 / sin(q_max)"}}, "S = l1"),
    ({"algorithm": {"runs": [{"l4": [0.0, 1.0]}]}}, "'l4' is not a continuous variable"),
    ({"keep": [{"formula": "l1 + lx", "<=": 0.4}]}, "'lx' in 'l1 + lx'"),
    ({"parameters": {"l1": "os.system(1)", "S": "l1"}}, "a call is one of sin"),
])
def test_bad_study_parts_are_one_line_errors(tmp_path, change, message):
    with pytest.raises(UserError, match=re.escape(message)) as caught:
        bind_study(load_study(study_file(tmp_path, **change)))
    assert "\n" not in str(caught.value)


class Interrupt(Exception):
    pass


def test_a_formula_that_gives_no_finite_length_leaves_no_design_and_writes_no_result(tmp_path):
    """Parameter indices build no device: a design whose formula gives l1 = inf (sin(q)^inf = 0) is refused as the
    device file would refuse it, so no design is feasible and nothing but the checkpoint is written."""
    path = study_file(tmp_path, parameters={"l1": "0.06 / sin(q_max) ** 10 ** 10", "S": "l1"},
                      objectives=[{"name": "O1", "index": "rcube_o1", "reduce": "max", "sense": "min"}], constraints=[],
                      keep=[], algorithm={"population": 8, "generations": 2, "runs": [], "start": None})
    result = CliRunner().invoke(app, ["optimize", str(path), "--out", str(tmp_path / "out"), "--quiet"])
    assert result.exit_code == 2 and len(result.output.strip().splitlines()) == 1, result.output
    assert not (tmp_path / "out" / "front.csv").exists() and not (tmp_path / "out" / "selected.yaml").exists()


def test_an_interrupted_run_of_several_runs_continues_from_its_checkpoint(tmp_path):
    """The three runs keep their generations apart in the checkpoint: stopped in the second run, the rerun
    evaluates only the generations not yet kept and ends with the same front as an uninterrupted run."""
    path = study_file(tmp_path, algorithm={"population": 8, "generations": 3, "start": {"minimize": "l1 + l2 + l3",
                                                                                        "starts": 4}})
    study = load_study(path)
    bound = bind_study(study)
    evaluate = StudyEvaluator(bound)
    whole = run_study(study, SEED, evaluate, None, None, evaluate.constraints, algorithm=NSGA_II)
    asked = []

    def counting(batch):
        asked.append(len(batch))
        return StudyEvaluator(bound)(batch)

    def stop(generation, total):
        if generation == 5:  # the second generation of the second run
            raise Interrupt

    with pytest.raises(Interrupt):
        run_study(study, SEED, counting, tmp_path / "out", stop, evaluate.constraints, algorithm=NSGA_II)
    assert len(asked) == 5
    resumed = run_study(study, SEED, counting, tmp_path / "out", None, evaluate.constraints, algorithm=NSGA_II)
    assert len(asked) == 5 + 4  # generations 3 of run 2 and 1-3 of run 3
    assert resumed.front == whole.front and front_csv(resumed) == front_csv(whole)
    np.testing.assert_array_equal([r.objectives for r in resumed.records], [r.objectives for r in whole.records])
