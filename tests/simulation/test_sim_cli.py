"""The rendering commands' new options from the command line: --resolution and --error-percent."""

from __future__ import annotations

import json
from pathlib import Path
import math

import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.interface.cli import app

runner = CliRunner()


def _closed_form(j: float, b: float, t: float, c: float) -> float:
    """K* written out independently of the engine (derivation in docs/simulation.md)."""
    a = math.exp(-b * t / j)
    return b * b * (1 - a) * (1 - a * c) / (j * (1 - a) * (1 - a * c) - t * a * b * (1 - c))


def test_resolution_gives_a_real_value_below_one():
    result = runner.invoke(app, ["impedance-range", "--device", "examples/devices/pantograph-2dof.yaml",
                                 "--settings", "seed", "--resolution", "0.02", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert 0 < out["k_max"] < 1 and out["resolution"] == 0.02 and 0 < out["k_min"] <= out["k_max"]
    assert out["first_unstable_k"] == pytest.approx(out["k_max"] + 0.02)
    assert out["criterion"] != "stable"


def test_error_percent_reports_the_closed_form():
    result = runner.invoke(app, ["stability-boundary", "--inertia", "0.04", "--damping", "0.5", "--period", "0.001",
                                 "--settings", "seed", "--error-percent", "1", "--samples", "2000", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    expected = _closed_form(0.04, 0.5, 1e-3, 0.99)
    assert out["k_max_closed_form"] == pytest.approx(expected, rel=1e-9)
    assert out["k_max_exact"] == pytest.approx(expected, rel=1e-8)
    assert out["k_max_simulated"] == pytest.approx(expected, rel=5e-3)
    assert out["k_max_exact"] - 0.5 ** 2 / 0.04 == pytest.approx(0.01 * 0.5 / 1e-3, rel=0.02)


def test_over_estimated_inertia_reports_zero_not_a_negative_closed_form():
    """E = -5 % at J = 0.039, b = 0.5, T = 1 ms: a c = 1.05 exp(-0.0128) > 1, no spring is stable (the
    written-out K* is negative there); the exact limit and the closed form are both 0."""
    assert _closed_form(0.039, 0.5, 1e-3, 1.05) < 0
    result = runner.invoke(app, ["stability-boundary", "--inertia", "0.039", "--damping", "0.5", "--period", "0.001",
                                 "--settings", "seed", "--error-percent", "-5", "--samples", "400", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["k_max_exact"] == 0.0 and out["k_max_closed_form"] == 0.0
    assert out["closed_form_bound"] == "no stable spring"


@pytest.mark.parametrize("args, message", [
    (["stability-boundary", "--inertia", "0.04", "--damping", "0.5", "--period", "0.001", "--error-percent", "1"],
     "needs --compensation full"),
    (["impedance-range", "--resolution", "-1"], "resolution must be a positive number, got -1.0 (--resolution)"),
    (["impedance-range", "--resolution", "500"], "above the stiffness limit 200 (--resolution, --k-limit)"),
])
def test_bad_settings_are_one_line_errors(args, message):
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert message in result.output and len(result.output.strip().splitlines()) == 1


def test_zwidth_of_a_device_joint_at_a_pose():
    """Joint 1 of the Phantom at a pose with the other joints held: J = H11(q); compensated, K = b^2 / J."""
    import numpy as np

    from hapticdesign.devices.registry import preset

    device = preset("phantom-3dof")
    result = runner.invoke(app, ["zwidth", "--preset", "phantom-3dof", "--q", "0,0.5,0.3", "--compensation", "full",
                                 "--b-values", "0", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    h11 = mass_matrix(device, np.array([0.0, 0.5, 0.3]))[0, 0]
    assert out["loop"]["inertia"] == pytest.approx(h11, rel=1e-12)
    assert out["K"][0] == pytest.approx(0.5 ** 2 / h11, rel=1e-8)
    assert out["passivity_K"] is None


def test_zwidth_chart_and_analytic_method(tmp_path):
    result = runner.invoke(app, ["zwidth", "--inertia", "0.039", "--damping", "0.5", "--velocity", "difference",
                                 "--delay", "1", "--points", "5", "--out", str(tmp_path), "--json"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "zwidth.png").stat().st_size > 1000 and (tmp_path / "zwidth.svg").exists()
    result = runner.invoke(app, ["impedance-range", "--method", "analytic", "--json"])
    out = json.loads(result.stdout)
    assert out["method"] == "analytic" and out["analytic_exact"] is True and out["k_max"] == 6.0


PRISMATIC = Path(__file__).with_name("slider.yaml")


def test_a_prismatic_wall_is_labelled_in_newtons(tmp_path):
    """A 0.5 kg slider with 2 N s/m: compensated, the limit is b^2 / m = 8 N/m, reported in N/m."""
    path = PRISMATIC
    result = runner.invoke(app, ["impedance-range", "--device", str(path), "--method", "analytic", "--resolution",
                                 "0.25", "--true-boundary", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["units"]["k_max"] == "N/m"
    dyn = json.loads(runner.invoke(app, ["dynamics", "--device", str(path), "--q", "0.1", "--json"]).stdout)
    assert dyn["units"]["joints"][0]["effort"] == "N" and dyn["H"] == [[0.5]]
    zw = json.loads(runner.invoke(app, ["zwidth", "--device", str(path), "--compensation", "full", "--delay", "0",
                                        "--b-values", "0", "--json"]).stdout)
    assert zw["K"][0] == pytest.approx(2.0 ** 2 / 0.5, rel=1e-8)


def test_transparency_analytic_method():
    """``transparency --method analytic``: the simulated estimate (a 5 % modelling error, type 1: exact) and the
    steady-state bandwidth beside it; encoder quantization is refused in one line."""
    args = ["transparency", "--error-percent", "5", "--f1", "5", "--json"]
    simulated = json.loads(runner.invoke(app, args).stdout)
    result = runner.invoke(app, [*args, "--method", "analytic"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["bandwidth_hz"] == pytest.approx(simulated["bandwidth_hz"], abs=1e-6)
    assert out["analytic_exact"] is True
    full_sweep = json.loads(runner.invoke(app, ["transparency", "--error-percent", "5", "--json", "--method",
                                                "analytic"]).stdout)
    # the steady state does not depend on the excitation (the estimate does: the chirp ends slower)
    assert out["steady_bandwidth_hz"] == pytest.approx(full_sweep["steady_bandwidth_hz"], rel=1e-12)
    assert abs(out["bandwidth_hz"] - full_sweep["bandwidth_hz"]) > 0.1
    assert "steady_bandwidth_hz" not in simulated
    refused = runner.invoke(app, ["transparency", "--method", "analytic", "--counts", "4096"])
    assert refused.exit_code == 2 and "quantization" in refused.output and "Traceback" not in refused.output
