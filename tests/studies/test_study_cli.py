"""Command line of the studies: help, one-line errors with exit status 2, and the demo's equations."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import inverse_dynamics
from hapticdesign.analysis.dynamics.symbolic import derive
from hapticdesign.devices.registry import preset
from hapticdesign.interface.cli import app

pytestmark = pytest.mark.slow  # end to end: deselect with -m "not slow"

runner = CliRunner()


def test_demo_help():
    result = runner.invoke(app, ["demo", "--help"])
    assert result.exit_code == 0
    assert "quick form" in result.output and "--out" in result.output


def test_study_help_lists_both_studies():
    result = runner.invoke(app, ["study", "--help"])
    assert result.exit_code == 0
    assert "phantom" in result.output and "rcube" in result.output


def _one_line_error(args, text):
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and text in lines[0]


def test_bad_input_exits_2(tmp_path):
    a_file = tmp_path / "report"
    a_file.write_text("not a folder")
    _one_line_error(["study", "rcube", "--out", str(a_file)], "is a file")
    _one_line_error(["study", "phantom", "--workers", "0", "--out", str(tmp_path / "x")], "--workers")
    _one_line_error(["study", "rcube", "--scale", "huge", "--out", str(tmp_path / "y")], "unknown scale")
    _one_line_error(["demo", "--out", str(a_file)], "is a file")
    assert not (tmp_path / "x").exists() and not (tmp_path / "y").exists()


def test_missing_out_is_a_usage_error():
    assert runner.invoke(app, ["study", "phantom"]).exit_code == 2


def test_demo_prints_the_equations_of_motion():
    from hapticdesign.interface.commands.study import _print_equations

    lines: list[str] = []
    _print_equations(lines.append)
    text = "\n".join(lines)
    full = derive(preset("phantom-3dof"), "all")
    terms = sum(len(sp.Add.make_args(sp.expand(e))) for e in (*full.H, *full.C, *full.G))
    assert "H[1,1] =" in text and "G[2,1] =" in text
    assert f"{terms} terms" in text
    device = preset("phantom-3dof")
    line = next(x for x in lines if x.startswith("q = [0.3, -0.4, 0.7]"))
    printed = np.array([float(v) for v in line.split("tau = ")[1].split()[:3]])
    expected = inverse_dynamics(device, np.array([0.3, -0.4, 0.7]), np.full(3, 0.5), np.ones(3))
    assert np.allclose(printed, expected, rtol=1e-6, atol=0)
