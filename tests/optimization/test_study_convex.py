"""Seed 000's LN minimization as study files through ``optimize`` (method convex; docs/optimization.md).

The designs are checked without the LN form that found them: LN by brute force over a grid of poses of the
dynamics model (exact for these trigonometric polynomials), LN = 0 by the seed's printed linearization
conditions (eq. 3.12-3.26), realizability by the pseudo-inertia's eigenvalues and the device file's own check,
the bounds by the study's numbers, and selected.yaml by loading it as a device file.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from hapticdesign.analysis.linearity.bounds import practical_bounds
from hapticdesign.analysis.linearity.form import device_form
from hapticdesign.analysis.linearity.linear_designs import LN_TOLERANCE
from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.devices.registry import preset
from hapticdesign.interface.cli import app
from hapticdesign.model.inertia import SEED_FIELDS, BodyInertia, check_body, pseudo_inertia, seed_parameter_name
from hapticdesign.optimization.study_file import load_study
from tests.helpers.ln_grid import brute_force_parts, torus_nodes
from tests.helpers.seed_linear_conditions import seed_equations

STUDIES = Path(__file__).resolve().parents[2] / "examples" / "studies"


def _optimize(study: Path, out: Path, *extra: str) -> dict:
    result = CliRunner().invoke(app, ["optimize", str(study), "--out", str(out), "--json", "--quiet", *extra])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def _checked_design(study_path: Path, out: Path, summary: dict):
    """The selected design as the device file selected.yaml: every variable within its bounds and at the
    front's value, every body rigid-body realizable (pseudo-inertia eigenvalues), the other parameters at the
    study's device file's values."""
    study = load_study(study_path)
    selected = load_device_file(out / "selected.yaml")
    original = load_device_file(study.device_path)
    values = summary["selected"]["variables"]
    assert summary["front"] == [{k: summary["selected"][k] for k in ("variables", "objectives")}]
    for name, (low, high) in study.spec.variables.items():
        assert low <= values[name] <= high
        assert selected.params[name] == values[name]
    for name in original.params:
        if name not in values:
            assert selected.params[name] == original.params[name]
    for body in selected.body_names:
        inertia = selected.body(body)
        row = np.array([getattr(inertia, f) for f in SEED_FIELDS])
        standard = selected.standard_parameters().reshape(-1, 10)[selected.body_names.index(body)]
        assert np.linalg.eigvalsh(pseudo_inertia(standard)).min() >= -1e-12 * np.abs(standard).max()
        report = check_body(body, BodyInertia(**dict(zip(SEED_FIELDS, row))))
        assert report.error is None and report.warning is None
    return selected


def _grid_ln(device) -> float:
    nodes = torus_nodes(device.n_dof, points=5)  # exact: the entries' squares are of degree 4 in each angle
    nodes[0] = (np.zeros(1), np.ones(1))  # q1 turns about gravity: LN does not depend on it
    return float(brute_force_parts(device, device.standard_parameters(), nodes).sum())


def test_three_dof_study_finds_a_realizable_linear_design(tmp_path):
    path = STUDIES / "phantom-3dof-linear.yaml"
    summary = _optimize(path, tmp_path)
    ln = summary["front"][0]["objectives"]["ln"]
    assert summary["evaluations"] == 1 and 0 <= summary["lower_bound"] <= ln < LN_TOLERANCE
    selected = _checked_design(path, tmp_path, summary)
    assert _grid_ln(selected) < LN_TOLERANCE
    # eq. 3.12-3.26 as printed: the dependent parameters follow from the free ones of the design
    p = {name: selected.params[name] for name in selected.inertial_names()}
    expected = seed_equations(p, selected.params["l2"], selected.params["l3a"])
    for name, value in expected.items():
        assert p[name] == pytest.approx(value, rel=1e-6, abs=1e-9), name
    # eq. 3.27: the mass matrix is the same at every pose (LN < 1e-12 bounds each entry's deviation by ~1e-6)
    poses = np.random.default_rng(5).uniform(-np.pi, np.pi, (50, 3))
    assert np.ptp(mass_matrix(selected, poses), axis=0).max() < 1e-6
    assert float(device_form(selected).ln(selected.standard_parameters())) == pytest.approx(ln, abs=1e-18)


def test_six_dof_study_reproduces_the_minimum_under_practical_bounds(tmp_path):
    path = STUDIES / "phantom-6dof-ln.yaml"
    study = load_study(path)
    # the study's variables are the practical bounds of eq. 3.29-3.32 and the gimbal's, every field of each link
    for body, b in practical_bounds(preset("phantom-6dof")).items():
        box = b.box()
        for f, low, high in zip(SEED_FIELDS, box.low, box.high):
            assert study.spec.variables[seed_parameter_name(f, body)] == (low, high)
    summary = _optimize(path, tmp_path)
    ln, lower = summary["front"][0]["objectives"]["ln"], summary["lower_bound"]
    assert f"{ln:.2e}" == "7.80e-13"  # README: the 6-DOF minimum under practical bounds
    assert 0 < lower <= ln <= lower * (1 + 1e-3)
    selected = _checked_design(path, tmp_path, summary)
    assert _grid_ln(selected) == pytest.approx(ln, rel=1e-6)


def _study(tmp_path: Path, **changes) -> Path:
    """A small convex study on the 3-DOF device file with ``changes`` to its mapping."""
    data = {"device": str((STUDIES.parent / "devices" / "phantom-3dof.yaml").resolve()),
            "variables": {"m2": [0.15, 0.3], "m3a": [0.15, 0.3]},
            "objectives": [{"index": "ln", "reduce": "max", "sense": "min"}],
            "algorithm": {"method": "convex"}}
    data.update(changes)
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("changes, message", [
    ({"objectives": [{"index": "ln", "reduce": "max", "sense": "min"},
                     {"name": "m", "index": "mass", "reduce": "max", "sense": "min"}]}, "several objectives"),
    ({"objectives": [{"index": "ln", "reduce": "max", "sense": "max"}]}, "max ln"),
    ({"objectives": [{"index": "mass", "reduce": "max", "sense": "min"}]}, "min mass"),
    ({"variables": {"m2": [0.15, 0.3], "l2": [0.2, 0.3]}}, "variable l2 is not an inertial parameter"),
    ({"variables": {"m2": {"values": [0.15, 0.2]}}}, "variable m2 is a discrete choice"),
    ({"constraints": [{"index": "isotropy", "reduce": "min", ">=": 0.1}]}, "constraint min_isotropy is an index"),
    ({"constraints": [{"expression": "m2 + Ixx2", "<=": 0.4}], "variables": {"m2": [0.15, 0.3], "Ixx2": [1e-3, 1e-2]}},
     "is not convex in the inertial parameters"),
    ({"variables": {"m2": [0.15, 0.3], "r2x": [-0.1, 0.1], "Iyy2": [1e-3, 1e-2]}},
     "Izz2 is fixed while r2x varies, which is not convex"),
    ({"variables": {"m2": [0.15, 0.3], "r2y": [-0.1, 0.1], "Ixx2": [1e-3, 1e-2], "Izz2": [1e-3, 1e-2]}},
     "Ixy2 is fixed while r2y varies"),
    ({"algorithm": {"method": "convex", "population": 10}},
     "algorithm.population: a setting of method nsga2, nsga3 and pso, not of method convex (its settings: realizability)"),
    ({"algorithm": {"method": "convex", "runs": [{"m2": [0.15, 0.2]}]}}, "algorithm.runs: a setting of method nsga2"),
    ({"parameters": {"m3": "2 * m2"}}, "`parameters` and `keep` are settings of method nsga2"),
    ({"keep": [{"formula": "m2", "<=": 0.2}]}, "`parameters` and `keep` are settings of method nsga2"),
    ({"algorithm": {"method": "nsga2", "realizability": "rigid-body"}}, "algorithm.realizability: a setting of method convex, not of method nsga2"),
    ({"algorithm": {"method": "nsga2"}}, "workspace: the region the handle must reach is required"),
])
def test_what_method_convex_cannot_do_is_refused_in_one_line(tmp_path, changes, message):
    result = CliRunner().invoke(app, ["optimize", str(_study(tmp_path, **changes)), "--quiet"])
    assert result.exit_code == 2, result.output
    assert message in result.output and len(result.output.strip().splitlines()) == 1, result.output


def test_affine_mass_constraint_binds_and_fixed_parameters_keep_their_values(tmp_path):
    """Masses of links 2 and 3a only, their sum at most 0.35 kg: LN is no longer 0 (the file's linear design has
    0.398 kg), the constraint binds, and every parameter that is not a variable keeps the file's value."""
    path = _study(tmp_path, constraints=[{"expression": "m2 + m3a", "<=": 0.35}])
    summary = _optimize(path, tmp_path / "out")
    values = summary["selected"]["variables"]
    assert values["m2"] + values["m3a"] == pytest.approx(0.35, rel=1e-6) and values["m2"] + values["m3a"] <= 0.35 * (1 + 1e-9)
    selected = load_device_file(tmp_path / "out" / "selected.yaml")
    original = load_device_file(STUDIES.parent / "devices" / "phantom-3dof.yaml")
    for name in original.inertial_names():
        if name not in values:
            assert selected.params[name] == original.params[name], name
    ln = summary["selected"]["objectives"]["ln"]
    assert ln > LN_TOLERANCE and summary["lower_bound"] <= ln * (1 + 1e-6)
    assert _grid_ln(selected) == pytest.approx(ln, rel=1e-6)
    # a one-dimensional check of the optimum along the binding constraint (m2 + m3a = 0.35) by brute force
    grid = np.linspace(0.15, 0.2, 201)
    form = device_form(original)
    trials = [form.ln(original.with_params({"m2": m, "m3a": 0.35 - m}).standard_parameters()) for m in grid]
    assert min(trials) >= ln * (1 - 1e-6)


def test_positive_definite_realizability_is_the_seeds_eq_3_28(tmp_path):
    """The 3-DOF study with the seed's weaker condition (eq. 3.28): LN = 0 again, every link's inertia about its
    mass centre positive definite (the triangle inequality is not asked)."""
    data = yaml.safe_load((STUDIES / "phantom-3dof-linear.yaml").read_text())
    data["device"] = str((STUDIES / data["device"]).resolve())
    data["algorithm"] = {"method": "convex", "realizability": "positive-definite"}
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(data))
    summary = _optimize(path, tmp_path / "out")
    assert summary["selected"]["objectives"]["ln"] < LN_TOLERANCE
    selected = load_device_file(tmp_path / "out" / "selected.yaml")
    for body in ("2", "2a", "3", "3a"):
        assert np.linalg.eigvalsh(selected.body(body).inertia_at_com).min() > 0
        assert check_body(body, selected.body(body)).error is None
    assert _grid_ln(selected) < LN_TOLERANCE
