"""The study's methods as a table (nsga2, nsga3, pso, convex), polishing the front, and ``hapticdesign.optimize``.

Oracles: pymoo's own NSGA-III run on the same problem with the same seed; the planar two-link arm's closed form
(isotropy is the ratio of the singular values of its 2x2 Jacobian, whose ``J^T J`` has trace ``r^2 + l2^2`` and
determinant ``(l1 l2 sin q2)^2`` at a point at distance ``r``, ``cos q2 = (r^2 - l1^2 - l2^2) / (2 l1 l2)``),
maximized along ``l1 + l2 = S`` by SciPy's bounded scalar minimization; the uninterrupted run (for resume); the
command's ``--json`` (for the Python door).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from pymoo.algorithms.moo.nsga3 import NSGA3
from pymoo.core.problem import Problem
from pymoo.optimize import minimize
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting
from pymoo.util.ref_dirs import get_reference_directions
from scipy.optimize import minimize_scalar
from typer.testing import CliRunner

import hapticdesign as hd
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app
from hapticdesign.optimization.study_evaluation import STUDY_LIMIT, StudyEvaluator, bind_study, require_study_workload
from hapticdesign.optimization.study_file import load_study, study_from_mapping
from hapticdesign.optimization.study_methods import METHODS, method_of
from hapticdesign.optimization.study_outputs import evaluations_csv, front_csv
from tests.helpers.planar_arm import planar_arm
from tests.optimization.test_study_run import ISOTROPY, MASS, point, small_study, write_study

R = 0.2 / math.sqrt(2.0)
"""Distance of the workspace point from the shoulder (m)."""
S = 0.3
"""The bound on the total length l1 + l2 (m): below the isotropic arm's sqrt(2) R + R, so the optimum lies on it."""


def closed_form_isotropy(l1: float, l2: float, r: float = R) -> float:
    """sigma_min / sigma_max of the planar two-link arm's Jacobian at a point at distance ``r`` (module docstring)."""
    c = (r * r - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    trace, det = r * r + l2 * l2, (l1 * l2) ** 2 * (1.0 - c * c)
    root = math.sqrt(trace * trace - 4.0 * det)
    return math.sqrt((trace - root) / (trace + root))


def best_isotropy_on_the_length_bound() -> float:
    """The closed form's maximum along l1 + l2 = S, over the lengths that reach the point (|l1 - l2| <= R)."""
    low, high = (S - R) / 2 + 1e-9, (S + R) / 2 - 1e-9
    found = minimize_scalar(lambda l1: -closed_form_isotropy(l1, S - l1), bounds=(low, high), method="bounded",
                            options={"xatol": 1e-12})
    assert -found.fun >= max(closed_form_isotropy(l1, S - l1) for l1 in np.linspace(low, high, 2001))  # the global one
    return -found.fun


def length_study(folder: Path, method: str = "nsga2", polish: str | None = "ends", objectives=(ISOTROPY,),
                 population: int = 8, generations: int = 4) -> Path:
    """Both link lengths vary, the handle must reach one point at distance R, the total length is bounded by S;
    ``polish`` None leaves ``algorithm.polish`` out of the file (its default)."""
    (folder / "arm.yaml").write_text(yaml.safe_dump(planar_arm(0.2)))
    study = {"device": "arm.yaml", "variables": {"l1": [0.1, 0.3], "l2": [0.05, 0.3]},
             "workspace": {"box": {"center": point(R), "size": [0.0, 0.0, 0.0]}, "grid": 1},
             "objectives": list(objectives), "constraints": [{"expression": "l1 + l2", "<=": S}],
             "algorithm": {"method": method, "population": population, "generations": generations,
                           **({} if polish is None else {"polish": polish})}}
    (folder / "study.yaml").write_text(yaml.safe_dump(study, sort_keys=False))
    return folder / "study.yaml"


def run_of(path: Path, seed: int = 1, out: Path | None = None, evaluate=None):
    study = load_study(path)
    bound = bind_study(study)
    return method_of(study.spec).run(bound, seed, evaluate, out)


def test_the_closed_form_is_the_registry_isotropy(tmp_path):
    bound = bind_study(load_study(length_study(tmp_path)))
    for l1, l2 in [(0.17, 0.12), (0.2, 0.09), (0.15, 0.1)]:
        assert StudyEvaluator(bound)([{"l1": l1, "l2": l2}])[0].reduced[0] == pytest.approx(
            closed_form_isotropy(l1, l2), rel=1e-9)


@pytest.mark.parametrize("method", ["nsga2", "pso"])
def test_polishing_reaches_the_closed_form_optimum_the_search_alone_misses(tmp_path, method):
    optimum = best_isotropy_on_the_length_bound()
    (tmp_path / "raw").mkdir()
    raw = run_of(length_study(tmp_path / "raw", method, polish="none"))
    polished = run_of(length_study(tmp_path, method, polish="ends"))
    raw_best, best = raw.records[raw.front[0]], polished.records[polished.front[0]]
    assert raw_best.objectives[0] < optimum * (1 - 1e-3)  # the search alone stops short by more than 0.1 %
    assert best.polished and best.feasible
    assert best.objectives[0] == pytest.approx(optimum, rel=1e-6)
    assert best.values["l1"] + best.values["l2"] <= S
    assert polished.evaluations > len(polished.records) == len(raw.records) + 1


@pytest.mark.parametrize("method", ["nsga2", "pso"])
def test_a_study_file_without_polish_reaches_the_closed_form_optimum(tmp_path, method):
    """Issue 45: the front's ends are the optima by default; the raw search of the same file stops short."""
    optimum = best_isotropy_on_the_length_bound()
    path = length_study(tmp_path, method, polish=None)
    assert "polish" not in yaml.safe_load(path.read_text())["algorithm"]
    run = run_of(path)
    best = max(run.front, key=lambda k: run.records[k].objectives[0])
    assert run.records[best].objectives[0] == pytest.approx(optimum, rel=1e-3)
    assert run.records[best].values["l1"] + run.records[best].values["l2"] == pytest.approx(S, rel=1e-3)  # on the bound
    assert "Polished (polish: ends, the default: each objective's best front design refined by SLSQP" in (
        METHODS[method].describe(run))
    (tmp_path / "raw").mkdir()
    raw = run_of(length_study(tmp_path / "raw", method, polish="none"))
    assert max(raw.records[k].objectives[0] for k in raw.front) < optimum * (1 - 1e-3)
    assert "Not polished (polish: none)" in METHODS[method].describe(raw)


def test_ends_of_a_two_objective_front_are_polished_and_marked(tmp_path):
    run = run_of(length_study(tmp_path, objectives=(ISOTROPY, MASS)), seed=3)
    polished = [k for k in run.front if run.records[k].polished]
    assert polished, "no end improved"
    iso = max(run.records[k].objectives[0] for k in run.front)
    assert iso == pytest.approx(best_isotropy_on_the_length_bound(), rel=1e-6)
    header, *rows = front_csv(run).splitlines()
    assert header.endswith(",polished")
    assert sum(row.endswith(",yes") for row in rows) == len(polished)
    assert sum(line.endswith(",yes") for line in evaluations_csv(run).splitlines()[1:]) == sum(
        r.polished for r in run.records)
    numbers = ", ".join(str(n) for n, k in enumerate(run.front, start=1) if run.records[k].polished)
    assert (f"Polished (polish: ends: each objective's best front design refined by SLSQP under the constraints): "
            f"front designs {numbers};") in (
        METHODS["nsga2"].describe(run))


def test_polishing_holds_the_discrete_choices(tmp_path):
    (tmp_path / "plain").mkdir()
    plain = run_of(small_study(tmp_path / "plain"), 2)  # l2 continuous, the elbow's gear ratio one of 4, 8, 16
    path = small_study(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["algorithm"]["polish"] = "ends"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    run = run_of(path, 2)
    assert run.records[:len(plain.records)] == plain.records
    polished = run.records[len(plain.records):]
    iso_end = max(plain.front, key=lambda k: plain.records[k].objectives[0])
    mass_end = min(plain.front, key=lambda k: plain.records[k].objectives[1])
    assert polished and all(r.polished for r in polished)
    assert {r.values["actuators.q2.gear_ratio"] for r in polished} <= {
        plain.records[k].values["actuators.q2.gear_ratio"] for k in (iso_end, mass_end)}


def test_polishing_every_front_design_dominates_each_design_it_replaces(tmp_path):
    unpolished = run_of(length_study(tmp_path, objectives=(ISOTROPY, MASS), polish="none"), seed=5)
    run = run_of(length_study(tmp_path, objectives=(ISOTROPY, MASS), polish="all"), seed=5)
    assert run.records[:len(unpolished.records)] == unpolished.records
    before = np.array([[-r.objectives[0], r.objectives[1]] for r in (unpolished.records[k] for k in unpolished.front)])
    for r in run.records[len(unpolished.records):]:
        assert r.polished and r.feasible
        F = np.array([-r.objectives[0], r.objectives[1]])
        assert np.any(np.all(F <= before, axis=1) & np.any(F < before, axis=1))  # dominates a design of the old front


class Interrupt(Exception):
    pass


def test_polishing_resumes_from_the_checkpoint_with_the_same_bytes(tmp_path):
    path = length_study(tmp_path, objectives=(ISOTROPY, MASS))
    bound = bind_study(load_study(path))
    whole = run_of(path, 3)
    asked = []

    def stopping(batch):
        asked.append(len(batch))
        if len(asked) == 7:  # four generations, then three batches of the polishing
            raise Interrupt
        return StudyEvaluator(bound)(batch)

    with pytest.raises(Interrupt):
        run_of(path, 3, tmp_path / "out", stopping)
    resumed = run_of(path, 3, tmp_path / "out", lambda batch: asked.append(len(batch)) or StudyEvaluator(bound)(batch))
    assert asked[7] == asked[6]  # the stopped batch is asked again first, then only the batches after it
    assert sum(asked) == whole.evaluations + asked[6] and len(asked) > 8
    assert front_csv(resumed) == front_csv(whole) and evaluations_csv(resumed) == evaluations_csv(whole)
    replayed = run_of(path, 3, tmp_path / "out", lambda batch: pytest.fail("a finished run asked for designs"))
    assert front_csv(replayed) == front_csv(whole)


def test_nsga3_is_pymoos_nsga3_on_the_same_problem_with_the_same_seed(tmp_path):
    variables = {"l2": [0.09, 0.3], "actuators.q2.gear_ratio": [4.0, 20.0]}
    path = write_study(tmp_path, variables, [ISOTROPY, MASS], population=8, generations=5, center=point(0.15),
                       size=(0.02, 0.0, 0.02), grid=2)
    data = yaml.safe_load(path.read_text())
    data["algorithm"] = {"method": "nsga3", "population": 8, "generations": 5, "front": "final", "polish": "none"}
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    bound = bind_study(load_study(path))
    evaluated = []

    class Same(Problem):  # the study as its documented encoding: F = (-isotropy, mass), G = (no values)
        def __init__(self):
            super().__init__(n_var=2, n_obj=2, n_ieq_constr=1, xl=np.array([0.09, 4.0]), xu=np.array([0.3, 20.0]))

        def _evaluate(self, X, out, *args, **kwargs):
            evaluated.extend(map(tuple, X))
            answers = StudyEvaluator(bound)([{"l2": a, "actuators.q2.gear_ratio": b} for a, b in X])
            out["F"] = np.array([[-a.reduced[0], a.reduced[1]] if not a.reason else [0.0, 0.0] for a in answers])
            out["G"] = np.array([[1.0 if a.reason else 0.0] for a in answers])

    reference = minimize(Same(), NSGA3(get_reference_directions("das-dennis", 2, n_partitions=7), pop_size=8),
                         ("n_gen", 5), seed=4)
    run = run_of(path, 4)
    assert [r.x for r in run.records] == [tuple(map(float, x)) for x in evaluated]
    F = reference.pop.get("F")
    ok = reference.pop.get("G")[:, 0] <= 0.0
    first = NonDominatedSorting().do(F[ok], only_non_dominated_front=True)
    assert sorted(map(tuple, np.round(reference.pop.get("X")[ok][first], 15))) == sorted(
        tuple(np.round(run.records[k].x, 15)) for k in run.front)


DOCUMENTED_METHODS = {"nsga2": ("NSGA-II", True), "nsga3": ("NSGA-III", True), "pso": ("Particle swarm", True),
                      "convex": (None, False)}
"""The methods docs/optimization.md names (its table of methods), each with the algorithm it names and whether it keeps
a checkpoint (the population searches do; convex is one program), written here from the page."""


def test_every_documented_method_is_reachable_from_a_study_file():
    """The methods table of docs/optimization.md (the first cells of its rows, read from the page) is
    :data:`DOCUMENTED_METHODS`, and each name in a study file's ``algorithm`` gives a method of that name, the
    algorithm the page names and the checkpointing it states; without a ``method``, ``nsga2`` (the page's default)."""
    import re

    page = (Path(__file__).resolve().parents[2] / "docs" / "optimization.md").read_text(encoding="utf-8")
    table = page.split("| method | what it is | its own settings |", 1)[1].split("\n\n", 1)[0]
    rows = re.findall(r"^\| `([a-z0-9]+)`(?: \(default\))? \| ", table, flags=re.M)
    assert set(rows) == set(DOCUMENTED_METHODS) == set(METHODS)
    assert re.search(r"^\| `nsga2` \(default\) \|", table, flags=re.M)
    base = {"device": "arm.yaml", "variables": {"l2": [0.1, 0.2]}, "objectives": [ISOTROPY],
            "workspace": {"box": {"center": [0.1, 0.0, 0.1], "size": [0.0, 0.0, 0.0]}}}
    for name, (title, checkpointed) in DOCUMENTED_METHODS.items():
        spec = study_from_mapping({**base, "algorithm": {"method": name}})
        method = method_of(spec)
        assert method.name == name == spec.algorithm.method
        assert getattr(method, "title", None) == title and method.checkpointed is checkpointed
        assert type(spec.algorithm) is method.settings  # the record carries the settings the file is read into
    assert method_of(study_from_mapping(base)).name == "nsga2"


@pytest.mark.parametrize("algorithm, message", [
    ({"method": "nsga2", "partitions": 4}, "algorithm.partitions: a setting of method nsga3, not of method nsga2"),
    ({"method": "pso", "realizability": "rigid-body"}, "algorithm.realizability: a setting of method convex, not of "
                                                       "method pso"),
    ({"method": "convex", "polish": "ends"}, "algorithm.polish: a setting of method nsga2, nsga3 and pso, not of "
                                             "method convex"),
    ({"method": "nsga2", "polish": "middle"}, "algorithm.polish: Input should be 'none', 'ends' or 'all'"),
    ({"method": "annealing"}, "algorithm.method: unknown method 'annealing'; choose one of nsga2, nsga3, pso, convex"),
])
def test_a_setting_of_another_method_is_refused_in_one_line(algorithm, message):
    data = {"device": "arm.yaml", "variables": {"l2": [0.1, 0.2]}, "objectives": [ISOTROPY],
            "workspace": {"box": {"center": [0.1, 0.0, 0.1], "size": [0.0, 0.0, 0.0]}}, "algorithm": algorithm}
    with pytest.raises(UserError) as caught:
        study_from_mapping(data)
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_what_a_method_cannot_do_is_refused_in_one_line(tmp_path):
    with pytest.raises(UserError, match="objectives: method pso minimizes one objective, not 2"):
        load_study(length_study(tmp_path, "pso", objectives=(ISOTROPY, MASS)))
    path = length_study(tmp_path, "nsga3", objectives=(ISOTROPY, MASS), population=4)
    data = yaml.safe_load(path.read_text())
    data["algorithm"]["partitions"] = 6
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(UserError, match="^method nsga3: 7 reference directions \\(6 partitions of 2 objectives\\) need "
                                        "a population of at least 7, got 4$"):
        run_of(path)
    path = write_study(tmp_path, {"l2": {"values": [0.1, 0.14]}}, [ISOTROPY], 4, 2, center=point(0.12))
    data = yaml.safe_load(path.read_text())
    data["algorithm"]["method"] = "pso"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(UserError, match="discrete choices need a genetic method \\(nsga2, nsga3\\), not pso"):
        run_of(path)


def test_the_python_door_is_the_command(tmp_path, capsys):
    study = small_study(tmp_path)
    result = hd.optimize(study, seed=2, out=tmp_path / "api", quiet=True)
    assert capsys.readouterr() == ("", "")  # nothing printed
    done = CliRunner().invoke(app, ["optimize", str(study), "--seed", "2", "--out", str(tmp_path / "cli"), "--json"])
    assert done.exit_code == 0, done.output
    summary = json.loads(done.stdout)
    assert result.front == summary["front"] and result.summary == summary
    assert result.front[0].keys() == {"variables", "objectives"}
    assert result.method is METHODS["nsga2"] and result.study.path == study
    assert len(result.records) == summary["evaluations"]
    designs = [f"designs/design-{n}.yaml" for n in range(1, len(result.front) + 1)]  # each front design's device file
    assert [p.relative_to(tmp_path / "api").as_posix() for p in result.files] == [
        "front.csv", "evaluations.csv", "pareto.png", "pareto.svg", "selected.yaml", "study.json", *designs,
        "plotly.min.js", "report.html"]
    for name in ("front.csv", "evaluations.csv", "selected.yaml"):
        assert (tmp_path / "api" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    with pytest.raises(UserError, match="the seed must be at least 0"):
        hd.optimize(study, seed=-1)
    with pytest.raises(UserError, match="no objective named 'speed'"):
        hd.optimize(study, seed=2, weights={"speed": 1.0})


def test_the_python_door_shows_its_progress_on_stderr_unless_quiet(tmp_path, capsys, monkeypatch):
    """Without ``progress`` or ``quiet`` the generations go to stderr (in a log, as here, a line each tenth once the
    work has run ``LOG_AFTER`` seconds, 0 here); stdout stays empty; ``progress`` given replaces the lines."""
    monkeypatch.setattr("hapticdesign.interface.common.LOG_AFTER", 0.0)
    study = small_study(tmp_path)
    hd.optimize(study, seed=2)
    out, err = capsys.readouterr()
    generations = yaml.safe_load(study.read_text())["algorithm"]["generations"]
    assert out == "" and f"generations: {generations} of {generations}" in err.splitlines(), err
    seen = []
    hd.optimize(study, seed=2, progress=lambda done, total: seen.append((done, total)))
    assert capsys.readouterr() == ("", "") and seen[-1] == (generations, generations)


def test_the_polishing_counts_in_the_workload_limit(tmp_path):
    variables = {"l2": [0.09, 0.3], "actuators.q2.gear_ratio": [4.0, 20.0]}
    path = write_study(tmp_path, variables, [ISOTROPY, MASS], population=40, generations=60, center=point(0.15),
                       size=(0.04, 0.0, 0.04), grid=5)
    data = yaml.safe_load(path.read_text())
    data["algorithm"]["polish"] = "ends"  # (2400 + 2 ends x 100 batches x 3 designs) x 25 points = 75 000
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    require_study_workload(load_study(path))
    data["algorithm"]["polish"] = "all"  # (2400 + 40 x 100 x 3) x 25 = 360 000
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(UserError, match="a study of 14400 designs .* x 25 workspace points .*above the limit of"):
        require_study_workload(load_study(path))
    assert 75_000 <= STUDY_LIMIT < 360_000


def test_the_python_door_loads_on_first_use():
    code = ("import sys, hapticdesign as hd; assert 'pymoo' not in sys.modules; f = hd.optimize; "
            "assert 'pymoo' in sys.modules and 'optimize' in dir(hd); print(f.__module__)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                          env={**os.environ, "PYTHONPATH": str(Path(hd.__file__).parents[1])})
    assert done.stdout.strip() == "hapticdesign.interface.commands.optimize_adapter"
