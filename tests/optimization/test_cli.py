"""``hapticdesign rcube optimize | synthesize | cross-section | plies`` contracts."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app
from hapticdesign.optimization.rcube.constraints import constraint_values
from hapticdesign.optimization.rcube.cross_section import ratio_for_upper_limit

runner = CliRunner()


def run(*args):
    return runner.invoke(app, ["rcube", *args])


def test_optimize_quick_json_and_files(tmp_path):
    res = run("optimize", "--seed", "1", "--quick", "--json", "--out", str(tmp_path))
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    sel = summary["selected"]
    assert set(sel) >= {"l1", "l2", "l3", "q_max_deg"} and summary["front_size"] >= 1
    q = np.radians(sel["q_max_deg"])
    assert sel["l1"] == pytest.approx(0.06 / np.sin(q))
    assert np.all(constraint_values([[q, sel["l2"], sel["l3"]]]) <= 0.0)
    assert 0.7 < summary["ratio"] < 0.8
    keys = {"l1", "l2", "l3", "q_max", "total_length"}
    shortest, minimum = summary["shortest"], summary["constrained_minimum"]
    assert set(shortest) == set(minimum) == keys
    for d in (shortest, minimum):  # metres and radians: l1 = 60 mm / sin q_max (eq. 6.24)
        assert d["l1"] == pytest.approx(0.06 / np.sin(d["q_max"]))
        assert d["total_length"] == pytest.approx(d["l1"] + d["l2"] + d["l3"])
        assert np.all(constraint_values([[d["q_max"], d["l2"], d["l3"]]]) <= 0.0)
    assert minimum["total_length"] <= shortest["total_length"] < minimum["total_length"] + 0.0005
    assert summary["constrained_minimum_certificate"]["strict_local_minimum"] is True
    for name in ("table_7_2_front.csv", "table_7_3_post_evaluation.csv", "table_7_5_weighted_rms.csv",
                 "cross_section_front.csv", "table_7_6_7_plies.csv", "table_7_8_final_design.csv",
                 "figure_7_1_frequency_vs_manipulability.png", "figure_7_3_weighted_rms.svg",
                 "figure_7_4_cross_section.png", "pareto_front_synthesis.svg", "summary.json", "report.html",
                 "plotly.min.js"):
        assert (tmp_path / name).exists(), name
    rows = (tmp_path / "table_7_2_front.csv").read_text().strip().splitlines()
    assert len(rows) == summary["front_size"] + 1
    assert json.loads((tmp_path / "summary.json").read_text()) == summary


def test_steps_alone_json():
    res = run("cross-section", "--quick", "--json")
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["exact_ratio"] == pytest.approx(ratio_for_upper_limit(0.9), abs=0.9 / 200000)
    res = run("synthesize", "--quick", "--json", "--seed", "2")
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["front_size"] >= 1 and "q_max_deg" in out["selected"]
    res = run("plies", "--quick", "--json", "--ratio", "0.75", "--max-deflection", "0.01")
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["CF1_mm"] <= 10.0 and np.allclose(np.array(out["d_mm"]) / np.array(out["D_mm"]), 0.75)


@pytest.mark.parametrize("args", [
    ("synthesize", "--bounds", "0.5,0.4;0.001,0.1;0.001,0.15"),
    ("synthesize", "--population", "0"),
    ("optimize", "--quick", "--bounds", "0.07,1.5;0.001,0.02;0.001,0.02"),
    ("cross-section", "--lower", "0.8", "--upper", "0.2"),
    ("plies", "--ratio", "1.5"),
    ("synthesize", "--side", "-0.1"),
])
def test_bad_input_exit_2(args):
    """One error line, last; a run found infeasible only after its search (``optimize --quick`` with these bounds)
    may have logged its progress before (in a pipe, after 2 s of work), never anything else."""
    res = run(*args)
    assert res.exit_code == 2, res.output
    *before, last = res.stderr.splitlines()
    assert last.startswith("error: ") and res.stderr.endswith("\n")
    assert all(re.match(r"synthesis: \d+ (of|in all)", line) for line in before), before
