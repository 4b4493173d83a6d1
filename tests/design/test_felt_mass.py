"""Mass as felt (issue 41, item 3): the handle's apparent mass over a study's workspace by every reduction (at the
box's centre, median, mean, the extremes and where they are taken), with how coarse the grid is.

Oracle: the published Phantom Premium 1.5 in closed form, without the toolkit: the grid of the showcase study's box
built here (itertools over ``numpy.linspace``), each point's joints by the closed-form inverse kinematics
(tests/helpers/phantom_premium_ik.py), Cavusoglu & Feygin's mass matrix with the rotors' ``n^2 J_r`` and the handle
Jacobian differentiated by hand (tests/helpers/phantom_premium_mass.py), the apparent mass the largest eigenvalue of
``(J H^-1 J^T)^-1`` by NumPy, and its median, mean, largest and that point by NumPy.
"""

from __future__ import annotations

import copy
import importlib.util
import itertools
import json
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from hapticdesign.analysis.metrics.indices import reduce, reduced_at, reduction_label, spread
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app
from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import load_study
from hapticdesign.optimization.study_outputs import spread_rows, where_evaluated
from tests.helpers.phantom_premium_ik import closed_form
from tests.helpers.phantom_premium_mass import apparent_mass

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "examples" / "studies" / "phantom-premium-redesign.yaml"
DEVICE = ROOT / "examples" / "devices" / "phantom-premium.yaml"
PUBLISHED = {"l1": 0.215, "l2": 0.170, "l3": 0.0325, "ratio1": 13.3, "ratio2": 11.2, "ratio3": 11.2}
REDUCED = {"worst": "max", "median": "median", "mean": "mean", "centre": "center", "lightest": "min"}
runner = CliRunner()


def box() -> tuple[np.ndarray, np.ndarray]:
    """The showcase study's box: centre and size (m), read from the study file."""
    b = yaml.safe_load(STUDY.read_text())["workspace"]["box"]
    return np.array(b["center"], dtype=float), np.array(b["size"], dtype=float)


def oracle(points: np.ndarray) -> np.ndarray:
    """The closed-form apparent mass (kg) at each point."""
    return np.array([apparent_mass(closed_form(p)) for p in points])


def grid_points(grid: int, center: np.ndarray, size: np.ndarray) -> np.ndarray:
    offsets = np.linspace(-0.5, 0.5, grid)
    axes = [k for k in range(3) if size[k] > 0]
    out = []
    for o in itertools.product(offsets, repeat=len(axes)):
        p = center.copy()
        p[axes] += size[axes] * np.array(o)
        out.append(p)
    return np.array(out)


def felt_study(tmp_path: Path, grid: int) -> Path:
    """The showcase study asking the apparent mass by every reduction, on ``grid``."""
    data = copy.deepcopy(yaml.safe_load(STUDY.read_text()))
    data["device"] = str(DEVICE)
    data["workspace"]["grid"] = grid
    data["objectives"] = [{"name": n, "index": "apparent_mass", "reduce": how, "sense": "min"}
                          for n, how in REDUCED.items()]
    data["constraints"] = []
    path = tmp_path / f"felt-{grid}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.mark.parametrize("grid", [3, 5])
def test_a_study_reduces_the_published_phantoms_apparent_mass_as_the_closed_form(tmp_path, grid):
    center, size = box()
    points = grid_points(grid, center, size)
    masses = oracle(points)
    expected = {"worst": masses.max(), "median": np.median(masses), "mean": masses.mean(),
                "lightest": masses.min(), "centre": masses[np.flatnonzero(np.all(points == center, axis=1))[0]]}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the published be and df bodies' triangle-inequality note
        bound = bind_study(load_study(felt_study(tmp_path, grid)))
    answer = StudyEvaluator(bound)([PUBLISHED])[0]
    assert answer.reason == ""
    got = dict(zip(REDUCED, answer.reduced))
    for name in REDUCED:
        assert got[name] == pytest.approx(expected[name], rel=1e-9), name
    header = where_evaluated(bound, PUBLISHED)
    line, = [t for t in header.splitlines() if t.startswith("# max apparent_mass")]
    assert f"(max of {grid ** 3} points, grid {grid})" in line
    # the worst point named: one of the grid's, where the closed form takes its largest value (the device is
    # symmetric: four far corners tie)
    worst = _point_in(line)
    assert np.min(np.abs(points - worst).max(axis=1)) < 1e-6
    assert apparent_mass(closed_form(worst)) == pytest.approx(masses.max(), rel=1e-5)
    centre, = [t for t in header.splitlines() if t.startswith("# center apparent_mass")]
    np.testing.assert_allclose(_point_in(centre), center, atol=1e-6)
    row, = spread_rows(bound, PUBLISHED)
    assert row[-1] == line.split(" at ")[1].split(";")[0] + " (one of 4 points)"  # the far corners, mirrored in y, z
    assert [float(v) for v in row[2:5]] == pytest.approx([expected[k] for k in ("centre", "median", "mean")],
                                                         rel=1e-5)


def _point_in(line: str) -> np.ndarray:
    """The point ``at (x, y, z) m`` of a line of selected.yaml's header."""
    return np.array([float(x) for x in re.search(r" at \(([^)]*)\) m", line).group(1).split(",")])


def test_grid_5_holds_grid_3s_points_so_its_worst_is_at_least_grid_3s():
    center, size = box()
    coarse, fine = (oracle(grid_points(g, center, size)) for g in (3, 5))
    assert fine.max() >= coarse.max()
    assert set(map(tuple, grid_points(3, center, size).round(12))) <= set(map(tuple, grid_points(5, center, size).round(12)))


def test_maps_states_the_spread_and_the_worst_point_of_a_plane(tmp_path):
    center, size = box()
    plane = np.array([0.0, size[1], size[2]])
    args = ["maps", "--device", str(DEVICE), "--center", ",".join(str(float(x)) for x in center),
            "--size", ",".join(str(float(x)) for x in plane), "--grid", "5", "--index", "apparent_mass", "--out",
            str(tmp_path), "--json"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    got = json.loads(result.stdout)["spread"]["apparent_mass"]
    points = grid_points(5, center, plane)
    masses = oracle(points)
    assert got["points"] == 25 and got["grid"] == 5
    assert got["center"] == pytest.approx(apparent_mass(closed_form(center)), rel=1e-9)
    assert got["median"] == pytest.approx(np.median(masses), rel=1e-9)
    assert got["mean"] == pytest.approx(masses.mean(), rel=1e-9)
    assert got["max"] == pytest.approx(masses.max(), rel=1e-9)
    for how, value in (("max", masses.max()), ("min", masses.min())):  # a grid point taking the extreme (ties)
        assert np.min(np.abs(points - got[f"{how}_at"]).max(axis=1)) < 1e-12
        assert apparent_mass(closed_form(np.array(got[f"{how}_at"]))) == pytest.approx(value, rel=1e-9)
        assert got[f"{how}_count"] == np.count_nonzero(np.isclose(masses, value, rtol=1e-7, atol=0))
    text = runner.invoke(app, args[:-1])
    assert "over 25 of 25 points, grid 5" in text.stdout


def test_the_reductions_by_hand():
    v = np.array([3.0, 1.0, 4.0, 1.5, 9.0, 2.0])
    assert reduce(v, "median") == 2.5  # the mean of the two middle values, 2 and 3
    assert reduce(v, "center", 2) == 4.0
    assert reduced_at(v, "max") == 4 and reduced_at(v, "min") == 1 and reduced_at(v, "mean") is None
    assert spread(v, None) == {"min": 1.0, "max": 9.0, "mean": 20.5 / 6, "median": 2.5, "center": None,
                               "min_at": 1, "max_at": 4, "min_count": 1, "max_count": 1}
    assert spread(np.array([2.0, 5.0, 1.0, 5.0 * (1 + 1e-12)]))["max_count"] == 2
    assert reduction_label("max", 27, 3) == "max of 27 points, grid 3"
    with pytest.raises(UserError, match="^unknown reduction 'worst' \\(use min, max, mean, median, center\\)$"):
        reduce(v, "worst")
    with pytest.raises(UserError, match="an odd grid"):
        reduce(v, "center")


@pytest.mark.parametrize("change, message", [
    (lambda d: d["objectives"][0].update(reduce="worst"), "objectives[0].reduce: unknown reduction 'worst'"),
    (lambda d: d["workspace"].update(grid=4), "workspace.grid: reduce center (apparent_mass) needs the box's centre"),
])
def test_a_bad_reduction_is_one_line_and_exit_2(tmp_path, change, message):
    data = yaml.safe_load(felt_study(tmp_path, 3).read_text())
    change(data)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    result = runner.invoke(app, ["optimize", str(path), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert message in result.output and "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1


def test_the_docs_table_is_a_fresh_runs_and_the_closed_forms():
    """docs/indices.md's grid 3 against grid 5 table equals docs/scripts/felt_mass.py's output now, whose numbers
    the closed form gives (g, to the table's 0.1 g)."""
    spec = importlib.util.spec_from_file_location("felt_mass", ROOT / "docs" / "scripts" / "felt_mass.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    fresh = script.table()
    doc = (ROOT / "docs" / "indices.md").read_text()
    assert doc[doc.index(script.BEGIN) + len(script.BEGIN):doc.index(script.END)].strip() == fresh
    center, size = box()
    for grid, row in zip((3, 5), fresh.splitlines()[2:4]):
        masses = 1000 * oracle(grid_points(grid, center, size))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[0] == f"{grid ** 3} points, grid {grid}"
        centre = 1000 * apparent_mass(closed_form(center))
        assert [float(c) for c in cells[1:4]] == pytest.approx([centre, np.median(masses), masses.mean()], abs=0.051)
        assert float(cells[5].split()[0]) == pytest.approx(masses.max(), abs=0.051)


def test_a_studys_report_and_selected_design_state_the_grid_and_the_spread(tmp_path):
    data = yaml.safe_load(felt_study(tmp_path, 3).read_text())
    data["algorithm"] = {"method": "nsga2", "population": 4, "generations": 1}
    path = tmp_path / "tiny.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    result = runner.invoke(app, ["optimize", str(path), "--seed", "1", "--out", str(tmp_path / "out"), "--quiet"])
    assert result.exit_code == 0, result.output
    report = (tmp_path / "out" / "report.html").read_text()
    assert "max of 27 points, grid 3" in report and "median of 27 points, grid 3" in report
    assert "indices over the workspace (27 points, grid 3)" in report
    header = (tmp_path / "out" / "selected.yaml").read_text()
    assert "# apparent_mass over the study's 27 points, grid 3 (kg): center " in header
