"""The device file's own design beside every study (issue 41 item 5) and a study without a feasible design that still
explains itself (item 6).

Oracles: the two-link arm's closed form (its Jacobian's singular values at a point ``r`` from the shoulder: isotropic,
``sigma_2 / sigma_1 = 1``, exactly at ``l2 / l1 = 1 / sqrt(2)`` and ``r = l1 / sqrt(2)``, and less for any other
forearm; Salisbury & Craig 1982), the published Phantom Premium 1.5 (Cavusoglu & Feygin 2001; its data sheet's capstan
ratios), hand-computed changes, and evaluations.csv read back against the report.
"""

from __future__ import annotations

import csv
import math
import re
from html import escape, unescape
from pathlib import Path
from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from hapticdesign.interface.cli import app
from hapticdesign.optimization import study_outputs
from hapticdesign.optimization.study_evaluation import bind_study
from hapticdesign.optimization.study_file import Choice, load_study
from hapticdesign.optimization.study_outputs import Selection, at_bounds, changes, pareto_figure
from hapticdesign.optimization.study_run import Record, StudyRun
from tests.optimization.test_study_run import ISOTROPY, L1, small_study, write_study

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()


def two_link_isotropy(l1: float, l2: float, r: float) -> float:
    """``sigma_min / sigma_max`` of the planar two-link arm's Jacobian with the hand ``r`` from the shoulder (link 1
    along x: the singular values do not depend on the shoulder angle)."""
    phi = math.acos((r**2 - l1**2 - l2**2) / (2.0 * l1 * l2))
    jacobian = np.array([[-l2 * math.sin(phi), -l2 * math.sin(phi)], [l1 + l2 * math.cos(phi), l2 * math.cos(phi)]])
    s = np.linalg.svd(jacobian, compute_uv=False)
    return float(s[-1] / s[0])


def _rows(html: str, caption: str) -> list[list[str]]:
    table = html[html.index(f"<caption>{escape(caption)}"):]
    body = table[table.index("<tbody>"):table.index("</tbody>")]
    return [[unescape(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row)] for row in body.split("</tr>") if "<td" in row]


def test_the_device_files_design_is_evaluated_and_the_selected_design_compared_with_it(tmp_path):
    """The arm's file states the isotropic forearm l2 = l1 / sqrt(2); the study searches 0.08 to 0.12 m, below it, and
    polishes: the best it finds is the upper bound, which loses isotropy against the file's design."""
    path = write_study(tmp_path, {"l2": [0.08, 0.12]}, [ISOTROPY], population=6, generations=3)
    data = yaml.safe_load(path.read_text())
    data["algorithm"]["polish"] = "all"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    res = runner.invoke(app, ["optimize", str(path), "--seed", "1", "--out", str(tmp_path / "out"), "--quiet"])
    assert res.exit_code == 0, res.output
    r = L1 / math.sqrt(2.0)  # the study's one workspace point
    grid = np.linspace(0.08, 0.12, 41)
    assert np.argmax([two_link_isotropy(L1, l2, r) for l2 in grid]) == len(grid) - 1  # the optimum: the upper bound
    best = two_link_isotropy(L1, 0.12, r)
    page = (tmp_path / "out" / "report.html").read_text()
    rows = {row[0]: row[1:] for row in _rows(page, "The selected design beside the device file's design")}
    assert rows["l2"][0] == "m" and rows["iso"][0] == "1"  # each quantity's unit
    rows = {name: row[1:] for name, row in rows.items()}
    assert float(rows["l2"][0]) == pytest.approx(L1 / math.sqrt(2.0), rel=1e-5)
    assert rows["l2"][1] == "0.12" and rows["l2"][3] == "at the upper bound 0.12 of its range"
    assert float(rows["iso"][0]) == pytest.approx(1.0, abs=1e-6)  # the file's design: isotropic
    assert float(rows["iso"][1]) == pytest.approx(best, rel=1e-6)
    assert rows["iso"][2] == f"{100.0 * (best - 1.0):+.3g} %" and rows["iso"][3] == "lost"
    assert "l2 = 0.141421 is outside the study's range [0.08, 0.12]" in unescape(page)
    selected = (tmp_path / "out" / "selected.yaml").read_text()
    assert "# At a bound: l2 = 0.12 at the upper bound 0.12 of its range\n" in selected
    assert f"iso 1 -> {best:.6g} ({100.0 * (best - 1.0):+.3g} %), lost" in selected
    assert yaml.safe_load(selected)["parameters"]["l2"] == pytest.approx(0.12, abs=1e-12)


def test_a_variable_the_device_file_does_not_fix_has_no_baseline_and_one_it_sets_alone_has(tmp_path):
    path = write_study(tmp_path, {"s": [0.1, 0.2]}, [ISOTROPY], population=4, generations=1)
    data = yaml.safe_load(path.read_text())
    for formula, expected in (("0.5 * s", None), ("s", L1 / math.sqrt(2.0))):
        data["parameters"] = {"l2": formula}
        path.write_text(yaml.safe_dump(data, sort_keys=False))
        values, note = bind_study(load_study(path)).baseline()
        if expected is None:
            assert values is None and note.startswith("device file arm.yaml states no value of variable s")
        else:
            assert values == {"s": pytest.approx(expected, rel=1e-15)}
            assert note == ""


def test_the_published_phantom_is_the_premium_redesigns_baseline():
    """Cavusoglu & Feygin's lengths and the data sheet's capstan ratios, the ratios through their identity formulas;
    the study's rod formulas and scaled friction give the file's own masses, inertias and friction there (no note)."""
    bound = bind_study(load_study(ROOT / "examples" / "studies" / "phantom-premium-redesign.yaml"))
    values, note = bound.baseline()
    assert values == {"l1": 0.215, "l2": 0.170, "l3": 0.0325, "ratio1": 13.3, "ratio2": 11.2, "ratio3": 11.2}
    assert note == ""


def test_each_objective_is_gained_or_lost_in_its_sense():
    objectives = [SimpleNamespace(name="mass", sense="min"), SimpleNamespace(name="wall", sense="max"),
                  SimpleNamespace(name="iso", sense="max"), SimpleNamespace(name="zero", sense="min")]
    run = StudyRun(SimpleNamespace(objectives=objectives), 1, [], [],
                   baseline=Record(0, (0.0,), {"l1": 0.1}, (2.0, 4.0, 0.5, 0.0), (), "", "", 0.0))
    chosen = Record(1, (0.0,), {"l1": 0.2}, (1.5, 3.0, 0.5, 1.0), (), "", "", 0.0)
    found = {c.name: (c.percent, c.verdict) for c in changes(run, chosen)}
    assert found["mass"] == (pytest.approx(-25.0), "gained")  # 2 -> 1.5 kg, minimized
    assert found["wall"] == (pytest.approx(-25.0), "lost")  # 4 -> 3 N/m, maximized
    assert found["iso"] == (0.0, "same")
    assert math.isnan(found["zero"][0]) and found["zero"][1] == "lost"  # from 0: no percent
    assert str(changes(run, chosen)[0]) == "mass 2 -> 1.5 (-25 %), gained"


def test_variables_at_a_bound_are_flagged():
    spec = SimpleNamespace(variables={"a": (0.0, 1.0), "b": (0.0, 1.0), "c": (0.0, 1.0), "n": Choice(values=(8.0, 4.0, 16.0))})
    found = at_bounds(spec, {"a": 1.0 - 1e-7, "b": 0.5, "c": 0.0 + 1e-3, "n": 16.0})
    assert found == {"a": "at the upper bound 1 of its range", "n": "at the upper bound 16 of its range"}
    assert at_bounds(spec, {"a": 0.0, "b": 0.5, "c": 0.5, "n": 8.0}) == {"a": "at the lower bound 0 of its range"}


def test_the_pareto_figure_draws_the_device_files_design_within_its_axes(tmp_path, monkeypatch):
    objectives = [SimpleNamespace(name="isotropy", reduce="min", index="isotropy", sense="max"),
                  SimpleNamespace(name="mass", reduce="max", index="apparent_mass", sense="min")]
    front = [(0.9, 0.30), (0.8, 0.36), (0.7, 0.42)]
    records = [Record(1, (0.0,), {"l1": 0.1}, f, (), "", "", 0.0) for f in front]
    base = Record(0, (0.0,), {"l1": 0.1}, (0.5, 0.9), (), "", "", 0.0)  # far beyond the front
    run = StudyRun(SimpleNamespace(objectives=objectives, workspace=None), 1, records, [0, 1, 2], baseline=base)
    kept = []
    monkeypatch.setattr(plt, "close", kept.append)
    monkeypatch.setattr(study_outputs, "save_figure", lambda fig, path: path)
    pareto_figure(run, Selection(1, 1, "least RMS"), tmp_path)
    ax = kept[0].axes[0]
    assert ax.get_xlim()[0] < 0.5 < ax.get_xlim()[1] and ax.get_ylim()[0] < 0.9 < ax.get_ylim()[1]
    assert "device file's design" in [t.get_text() for t in ax.get_legend().get_texts()]
    marked = [c for c in ax.collections if c.get_label() == "device file's design"]
    assert np.array_equal(marked[0].get_offsets(), [[0.5, 0.9]])
    broken = Record(0, (0.0,), {"l1": 0.1}, (0.5, 0.9), (1.0,), "", "force = 1, not >= 1.4", 0.3)
    pareto_figure(StudyRun(run.spec, 1, records, [0, 1, 2], baseline=broken), None, tmp_path)
    assert "device file's design (not feasible)" in [t.get_text() for t in kept[1].axes[0].get_legend().get_texts()]


def test_a_study_without_a_feasible_design_writes_why_then_one_line(tmp_path):
    """No forearm meets l2 <= 0.05 m in 0.09 to 0.3 m: evaluations.csv holds every design, the report counts them
    under one reason and lists the closest (the shortest forearms, least over the bound), then exit 2, one line."""
    study = small_study(tmp_path)
    data = yaml.safe_load(study.read_text())
    data["constraints"] = [{"expression": "l2", "<=": 0.05}]
    study.write_text(yaml.safe_dump(data, sort_keys=False))
    out = tmp_path / "out"
    res = runner.invoke(app, ["optimize", str(study), "--seed", "1", "--out", str(out)])
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: no design of 32 meets the constraints; the closest (")
    assert str(out / "report.html") in lines[0] and "Traceback" not in res.output
    assert not (out / "front.csv").exists() and not (out / "selected.yaml").exists()
    rows = list(csv.DictReader((out / "evaluations.csv").open()))
    assert len(rows) == 32 and {r["feasible"] for r in rows} == {"no"}
    page = (out / "report.html").read_text()
    reasons = _rows(page, "Why designs were infeasible")
    assert reasons == [["l2 = #, not <= #", "32", reasons[0][2]]]
    shortest = sorted(rows, key=lambda r: (float(r["l2 [m]"]), int(r["evaluation"])))[:10]
    closest = _rows(page, "The 10 designs closest to feasible")
    assert [row[0] for row in closest] == [r["evaluation"] for r in shortest]
    assert "The device file's design is not feasible: l2 = 0.141421, not <= 0.05" in unescape(page)
