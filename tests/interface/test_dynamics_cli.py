"""The ``dynamics`` and ``eom`` commands: JSON contract and one-line errors with exit status 2."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import gravity, mass_matrix
from hapticdesign.interface.cli import app

runner = CliRunner()


def test_dynamics_json_contract(phantom3):
    result = runner.invoke(app, ["dynamics", "--preset", "phantom-3dof", "--q", "0.1,0.2,0.3", "--qd", "1,2,3", "--qdd", "0.5,0,-1", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    q, qd, qdd = np.array([0.1, 0.2, 0.3]), np.array([1.0, 2, 3]), np.array([0.5, 0, -1])
    assert np.allclose(out["H"], mass_matrix(phantom3, q))
    assert np.array(out["C"]).shape == (3, 6)
    assert np.array(out["C_cvt"]).shape == (3, 3)
    assert np.allclose(out["tau"], mass_matrix(phantom3, q) @ qdd + np.array(out["C_cvt"]) @ qd + np.array(out["G"]), atol=1e-12)


def test_dynamics_params_file_and_zero_tau(tmp_path, phantom3):
    f = tmp_path / "p.yaml"
    f.write_text("m2: 0.2\nr2x: -0.05\n")
    result = runner.invoke(app, ["dynamics", "--params", str(f), "--q", "0,0.4,0.1", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    dev = phantom3.with_params({"m2": 0.2, "r2x": -0.05})
    assert np.allclose(out["G"], gravity(dev, np.array([0, 0.4, 0.1])))
    assert np.allclose(out["tau"], out["G"])


def test_seed_design_warns_and_strict_refuses(tmp_path):
    f = tmp_path / "p.json"
    f.write_text(json.dumps({"Ixx2": 0.00982641}))
    ok = runner.invoke(app, ["dynamics", "--params", str(f), "--q", "0,0,0", "--json"])
    assert ok.exit_code == 0
    assert ok.stderr.count("\n") == 1 and "triangle" in ok.stderr
    strict = runner.invoke(app, ["dynamics", "--params", str(f), "--q", "0,0,0", "--strict"])
    assert strict.exit_code == 2 and "triangle" in strict.stderr


@pytest.mark.parametrize(
    "content, suffix, args, message",
    [
        ('{"m9": 1}', ".json", [], "unknown parameter name 'm9'"),
        ('{"m2": -1}', ".json", [], "negative mass"),
        ('{"m2": 0}', ".json", [], "massless body"),
        ('{"Iyy3": -0.01}', ".json", [], "not positive definite"),
        ("{nope", ".json", [], "malformed JSON"),
        ("m2 = [1", ".toml", [], "malformed TOML"),
        ("m2: abc", ".yaml", [], "must be a number"),
        (None, ".json", [], "cannot read"),
        ("{}", ".json", ["--q", "0.1,0.2"], "expected 3 values"),
        ("{}", ".json", ["--q", "0.1,nan,0"], "finite"),
        ("{}", ".json", ["--q", "0,0,0", "--qd", "a,b,c"], "comma-separated numbers"),
        ("{}", ".txt", [], "unknown file type"),
    ],
)
def test_bad_input_is_one_line_exit_2(tmp_path, content, suffix, args, message):
    f = tmp_path / f"p{suffix}"
    if content is not None:
        f.write_text(content)
    cmd = ["dynamics", "--params", str(f)] + (args or ["--q", "0,0,0"])
    result = runner.invoke(app, cmd)
    assert result.exit_code == 2
    assert message in result.stderr
    assert result.stderr.strip().count("\n") == 0
    assert "Traceback" not in result.output


def test_unknown_preset():
    result = runner.invoke(app, ["dynamics", "--preset", "phantom-9dof", "--q", "0"])
    assert result.exit_code == 2 and "unknown preset" in result.stderr


def test_eom_latex_and_python():
    latex = runner.invoke(app, ["eom", "--preset", "phantom-3dof", "--symbolic", "inertial", "--part", "H", "--format", "latex"])
    assert latex.exit_code == 0 and "H_{1,1} = " in latex.stdout
    source = runner.invoke(app, ["eom", "--symbolic", "none", "--format", "python", "--part", "G"])
    assert source.exit_code == 0
    namespace: dict = {}
    exec(source.stdout, namespace)
    g = namespace["equations"](0.1, 0.2, 0.3, 0, 0, 0, 0, 0, 0)
    assert np.abs(np.array(g, dtype=float)).max() < 1e-9
    bad = runner.invoke(app, ["eom", "--symbolic", "m2,zz"])
    assert bad.exit_code == 2 and "unknown parameter name 'zz'" in bad.stderr


def test_eom_says_what_it_derives_unless_quiet(tmp_path):
    """The symbolic derivation takes seconds on six joints: a line on stderr says so first; --quiet silences it and
    the equations written are the same."""
    loud = runner.invoke(app, ["eom", "--preset", "phantom-3dof", "--symbolic", "m2,l2", "--format", "python",
                               "--out", str(tmp_path / "a.py")])
    quiet = runner.invoke(app, ["eom", "--preset", "phantom-3dof", "--symbolic", "m2,l2", "--format", "python",
                                "--out", str(tmp_path / "b.py"), "--quiet"])
    assert loud.exit_code == quiet.exit_code == 0
    assert loud.stderr.startswith("eom: deriving the exact H, C and G of phantom-3dof (3 joints)")
    assert quiet.stderr == "" and (tmp_path / "a.py").read_text() == (tmp_path / "b.py").read_text()
