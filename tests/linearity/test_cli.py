"""Command line: ``ln``, ``linearize``, ``designs`` (JSON contract, CSV contract, exit status 2)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app

runner = CliRunner()


def test_ln_json_default_is_linear():
    result = runner.invoke(app, ["ln", "--preset", "phantom-3dof", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert set(data["parts"]) == {"H", "C", "G"}
    assert data["ln"] < 1e-15


def test_ln_json_for_an_appendix_c_design(tmp_path, appendix_c):
    design = next(d for d in appendix_c if d["level"] == 2.0)
    path = tmp_path / "p.json"
    path.write_text(json.dumps(design["params"]))
    result = runner.invoke(app, ["ln", "--preset", "phantom-3dof", "--params", str(path), "--json"])
    assert result.exit_code == 0
    data = json.loads(result.stdout)
    assert data["ln"] == pytest.approx(design["ln"], rel=5e-9)
    assert data["ln"] == pytest.approx(sum(data["parts"].values()), rel=1e-12)


@pytest.mark.parametrize(
    "args",
    [["--region", "q2=1:0"], ["--region", "q2=0:0"], ["--region", "bad"], ["--preset", "nope"]],
)
def test_ln_bad_input_exit_2(args):
    result = runner.invoke(app, ["ln", *args])
    assert result.exit_code == 2
    assert "error:" in result.stderr


def test_ln_wrong_weight_shape(tmp_path):
    path = tmp_path / "w.json"
    path.write_text(json.dumps({"H": [[1, 1], [1, 1]]}))
    result = runner.invoke(app, ["ln", "--weights", str(path)])
    assert result.exit_code == 2
    assert "shape" in result.stderr


def test_designs_csv_contract(tmp_path):
    out = tmp_path / "d.csv"
    result = runner.invoke(app, ["designs", "--levels", "0,0.01,1", "--count", "2", "--seed", "3", "--out", str(out)])
    assert result.exit_code == 0, result.output
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 6
    from hapticdesign.devices.registry import preset

    names = preset("phantom-3dof").inertial_names()
    assert list(rows[0])[:5] == ["level", "ln", "ln_H", "ln_C", "ln_G"] and list(rows[0])[5:] == names
    for row in rows:
        level, ln = float(row["level"]), float(row["ln"])
        assert ln < 1e-12 if level == 0 else level <= ln <= level * (1 + 1e-6)


@pytest.mark.parametrize(
    "args", [["--levels", "0,-1"], ["--levels", "x"], ["--method", "nope"], ["--realizability", "x"], ["--count", "0"]]
)
def test_designs_bad_input_exit_2(tmp_path, args):
    result = runner.invoke(app, ["designs", "--out", str(tmp_path / "d.csv"), *args])
    assert result.exit_code == 2


def test_designs_infeasible_bounds_exit_2(tmp_path):
    result = runner.invoke(app, ["designs", "--levels", "1000", "--count", "1", "--out", str(tmp_path / "d.csv")])
    assert result.exit_code == 2


def test_linearize_find_writes_linear_designs(tmp_path):
    out = tmp_path / "lin.csv"
    result = runner.invoke(app, ["linearize", "--preset", "phantom-3dof", "--find", "2", "--seed", "4", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "free parameters (35" in result.stdout
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 2 and all(float(r["ln"]) < 1e-12 for r in rows)
    assert np.isfinite([float(v) for v in rows[0].values()]).all()


@pytest.mark.parametrize(
    "args",
    [
        ["--format", "latex"],
        ["--part", "G"],
        ["--symbolic-gravity"],
        ["--symbolic", "--json"],
        ["--symbolic", "--format", "pdf"],
        ["--symbolic", "--part", "Q"],
        ["--symbolic", "--region", "q3=2:1"],
    ],
)
def test_ln_symbolic_bad_input_exit_2(args):
    result = runner.invoke(app, ["ln", "--preset", "phantom-3dof", *args])
    assert result.exit_code == 2
    assert result.stderr.startswith("error:") and result.stderr.count("\n") == 1


@pytest.mark.parametrize("weights", [{"X": 1}, {"G": -1}, {"C": "a"}, {"H": [[1, 2], [3]]}])
def test_ln_bad_weights_exit_2(tmp_path, weights):
    path = tmp_path / "w.json"
    path.write_text(json.dumps(weights))
    result = runner.invoke(app, ["ln", "--preset", "phantom-3dof", "--weights", str(path)])
    assert result.exit_code == 2
    assert "error:" in result.stderr


def test_ln_symbolic_python_export_matches_numeric_ln(tmp_path, appendix_c):
    result = runner.invoke(app, ["ln", "--preset", "phantom-3dof", "--symbolic", "--format", "python"])
    assert result.exit_code == 0, result.output
    namespace: dict = {}
    exec(result.stdout, namespace)
    design = next(d for d in appendix_c if d["level"] == 2.0)
    path = tmp_path / "p.json"
    path.write_text(json.dumps(design["params"]))
    numeric = json.loads(runner.invoke(app, ["ln", "--preset", "phantom-3dof", "--params", str(path), "--json"]).stdout)
    from hapticdesign.devices.registry import preset

    values = {**preset("phantom-3dof").params, **design["params"]}
    assert namespace["linearity_number"](**values) == pytest.approx(numeric["ln"], rel=1e-11)


def test_ln_symbolic_latex_gravity_part():
    result = runner.invoke(app, ["ln", "--preset", "phantom-3dof", "--symbolic", "--format", "latex", "--part", "G",
                                 "--symbolic-gravity"])
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith(r"\mathrm{LN}_G = 0.5 m_{2}^{2} r_{2x}^{2} g^{2}")


@pytest.mark.parametrize("args", [["--find", "-1"], ["--realizability", "x"], ["--preset", "nope"]])
def test_linearize_bad_input_exit_2(args):
    result = runner.invoke(app, ["linearize", *args])
    assert result.exit_code == 2
    assert "error:" in result.stderr


FIVE_BAR = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"


@pytest.mark.parametrize("command", [["linearize"], ["designs", "--count", "1"]])
def test_closed_loop_device_is_refused_in_one_line(command, tmp_path):
    """The shipped five-bar declares a loop (``loops:`` in its file): the LN = 0 conditions of eq. 3.12-3.27
    need a tree's exact basis, so the command says why in one line and exits 2 (no traceback, no file)."""
    out = tmp_path / "d.csv"
    result = runner.invoke(app, [*command, "--device", str(FIVE_BAR), "--out", str(out)])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {command[0]} needs a tree device")
    assert "closed loops" in lines[0] and not out.exists()
