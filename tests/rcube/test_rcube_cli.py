"""``hapticdesign rcube`` command contracts."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from hapticdesign.analysis.rcube.kinematics import chain_position
from hapticdesign.interface.cli import app
from hapticdesign.model.rcube import RCubeGeometry

runner = CliRunner()


def run(*args):
    return runner.invoke(app, ["rcube", *args])


def test_ik_json_contract_and_fk_round_trip():
    res = run("ik", "--l1", "0.12", "--l2", "0.08", "--l3", "0.13", "--position", "0.13,0.1,0.14", "--json")
    assert res.exit_code == 0, res.output
    q = np.array(json.loads(res.stdout)["q"])
    assert q.shape == (3, 3)
    g = RCubeGeometry(0.12, 0.08, 0.13)
    for i in range(3):
        assert np.allclose(chain_position(g, i, q[i]), [0.13, 0.1, 0.14], atol=1e-12)
    res = run("fk", "--q1", str(q[0, 0]), "--q2", str(q[1, 0]), "--q3", str(q[2, 0]),
              "--l1", "0.12", "--l2", "0.08", "--l3", "0.13", "--json")
    assert res.exit_code == 0, res.output
    assert np.allclose(json.loads(res.stdout)["position"], [0.13, 0.1, 0.14], atol=1e-12)


def test_stiffness_mass_metrics_json():
    K = np.array(json.loads(run("stiffness", "--json").stdout)["K_C"])
    assert K.shape == (6, 6) and np.allclose(K, K.T, atol=1e-6 * np.abs(K).max())
    M = np.array(json.loads(run("mass", "--json").stdout)["M_C"])
    assert M.shape == (3, 3) and np.all(np.linalg.eigvalsh(M) > 0)
    res = run("metrics", "--json", "--position", "0.12,0.1,0.13")
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["metrics"]["condition_number"] >= 1.0


def test_maps_write_pngs(tmp_path):
    res = run("maps", "--out", str(tmp_path), "--n", "3")
    assert res.exit_code == 0, res.output
    assert len(list(tmp_path.glob("*.png"))) == 48


def test_bad_input_exits_2_with_one_line():
    cases = [
        ("ik", "--position", "1,1,1"),
        ("ik", "--position", "0.1117,0.1117,0.1117", "--l2", "0.02", "--l3", "0.02"),
        ("fk", "--q1", "0", "--q2", "0", "--q3", "0", "--l1", "-0.1"),
        ("stiffness", "--outer", "0.01,0.01,0.01", "--inner", "0.02,0.005,0.005"),
        ("stiffness", "--outer", "0,0.01,0.01"),
        ("stiffness", "--plies", "1,1,1,1;1,-2,1,1;1,1,1,1"),
        ("ik", "--position", "0.1117,0.1117,0.1117", "--sigma", "2"),
        ("mass", "--position", "0.2234,0.1117,0.1117"),
    ]
    for args in cases:
        res = run(*args)
        assert res.exit_code == 2, (args, res.output)
        assert res.stderr.count("\n") == 1 and res.stderr.startswith("error:"), (args, res.stderr)


def test_stiffness_with_joint_stiffness_adds_the_bearing_compliance(tmp_path):
    """Translational bearings of stiffness k at the five joints of a chain, in series with the links:
    each adds I/k to the chain's translational compliance (locked passive joints, eq. 5.119), so
    K_C* = sum_i ((K_Ci*)^-1 + diag(5/k, 5/k, 5/k, 0, 0, 0))^-1."""
    from hapticdesign.analysis.rcube.design import final_design
    from hapticdesign.analysis.rcube.stiffness import chain_stiffness_matrices

    k = 3e5
    res = run("stiffness", "--locked", "--joint-translational", str(k), "--json")
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    d = final_design()
    extra = np.diag([5 / k] * 3 + [0.0] * 3)
    expected = sum(np.linalg.inv(np.linalg.inv(K) + extra) for K in chain_stiffness_matrices(d, d.geometry.home, passive=False))
    assert np.allclose(out["K_C"], expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())
    share = np.array(out["joint_compliance_share"])
    assert np.all((share > 0) & (share < 1))
    design_file = tmp_path / "d.yaml"
    design_file.write_text(f"joints: {{translational: {k}}}\n")
    res = run("stiffness", "--locked", "--design", str(design_file), "--json")
    assert np.allclose(json.loads(res.stdout)["K_C"], out["K_C"], rtol=1e-12)
    res = run("stiffness", "--joint-stiffness", "-5")
    assert res.exit_code == 2 and res.stderr.startswith("error:") and res.stderr.count("\n") == 1


def test_geometry_options_keep_the_design_file_and_sigma_has_no_sentinel(tmp_path):
    """A design file's sigma = +1 stays unless --sigma is given; --sigma -1 given explicitly wins over it;
    --outer keeps each link's bending rule. The branch shows in the elbow angle: sign(sin q_i3) = sigma (eq. 5.42)."""
    from hapticdesign.analysis.rcube.design_io import load_design
    from hapticdesign.interface.commands.rcube import _design

    path = tmp_path / "d.yaml"
    path.write_text("l2: 0.08\nsigma: 1\n")
    assert _design(path, None, None, None, None, None).geometry.sigma == 1
    assert _design(path, None, None, None, None, -1).geometry.sigma == -1
    changed = _design(path, 0.12, None, None, 0.11, None)
    assert (changed.geometry.l1, changed.geometry.l2, changed.geometry.S, changed.geometry.sigma) == (0.12, 0.08, 0.11, 1)
    assert changed.links == load_design(path).links
    for sigma in (-1, 1):
        res = run("ik", "--design", str(path), "--sigma", str(sigma), "--position", "0.12,0.1,0.13", "--json")
        assert res.exit_code == 0, res.output
        q = np.array(json.loads(res.stdout)["q"])
        assert np.all(np.sign(np.sin(q[:, 2])) == sigma)
    from hapticdesign.analysis.rcube.design import seed_final_design
    from hapticdesign.interface.commands.rcube import _override_links

    outer = _override_links(seed_final_design(), "0.04,0.04,0.04", None, None, None)
    assert all(link.section.D == 0.04 and link.bending == "eq. 4.59" for link in outer.links)
