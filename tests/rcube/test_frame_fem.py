"""Finite-element check of the VJM stiffness (seed 001 §5.2.5): PyNiteFEA beams against the VJM.

Oracles: Euler-Bernoulli closed forms for a cantilever, PyNiteFEA's own frame analysis, and the
closed-form chain positions of eq. 5.21-5.23.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from Pynite import FEModel3D
from typer.testing import CliRunner

from hapticdesign.analysis.rcube import frame_fem
from hapticdesign.analysis.rcube.design import final_design, steel_design
from hapticdesign.analysis.rcube.kinematics import chain_position, inverse_kinematics
from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness
from hapticdesign.interface.cli import app
from hapticdesign.model.rcube import RCubeGeometry, chain_mechanism

runner = CliRunner()

# Both models are linear Euler-Bernoulli frames with the same joints, so they must agree to
# round-off; 1e-8 is far below any modelling difference and far above double-precision noise.
ROUND_OFF = 1e-8


def _cantilever_compliance(E: float, G: float, A: float, I: float, J: float, L: float) -> np.ndarray:
    """Tip compliance of a tube clamped at the origin along +X, from six PyNite load cases."""
    fe = FEModel3D()
    fe.add_node("root", 0.0, 0.0, 0.0)
    fe.add_node("tip", L, 0.0, 0.0)
    fe.add_material("m", E, G, 0.3, 1000.0)
    fe.add_section("s", A, I, I, J)
    fe.add_member("tube", "root", "tip", "m", "s")
    fe.def_support("root", True, True, True, True, True, True)
    for d in frame_fem.LOAD_DIRECTIONS:
        fe.add_node_load("tip", d, 1.0, case=d)
        fe.add_load_combo(d, {d: 1.0})
    fe.analyze_linear()
    n = fe.nodes["tip"]
    return np.column_stack([[n.DX[d], n.DY[d], n.DZ[d], n.RX[d], n.RY[d], n.RZ[d]] for d in frame_fem.LOAD_DIRECTIONS])


def test_cantilever_tube_pynite_closed_form_and_vjm_link():
    link, L = final_design().links[2], 0.1218
    s, m = link.section, link.moduli
    C_fe = _cantilever_compliance(m.E_x, m.G_xy, s.area, s.second_moment, s.polar_moment, L)
    EI, GJ, EA = m.E_x * s.second_moment, m.G_xy * s.polar_moment, m.E_x * s.area
    closed = np.zeros((6, 6))
    closed[0, 0] = L / EA
    closed[1, 1] = closed[2, 2] = L**3 / (3 * EI)
    closed[3, 3] = L / GJ
    closed[4, 4] = closed[5, 5] = L / EI
    closed[1, 5] = closed[5, 1] = L**2 / (2 * EI)
    closed[2, 4] = closed[4, 2] = -L**2 / (2 * EI)
    scale = np.sqrt(np.outer(np.diag(closed), np.diag(closed)))
    assert np.allclose(C_fe / scale, closed / scale, atol=ROUND_OFF)
    assert np.allclose(link.compliance(L) / scale, closed / scale, atol=ROUND_OFF)


def test_frame_nodes_follow_the_chain_closed_forms():
    d = final_design()
    r = d.geometry.home + np.array([0.03, -0.045, 0.05])
    frame = frame_fem.frame_model(d, r)
    q = inverse_kinematics(d.geometry, r)
    assert np.allclose(frame.nodes["platform"], r, atol=1e-12)
    for i in range(3):
        assert np.allclose(chain_position(d.geometry, i, q[i]), frame.nodes["platform"], atol=1e-12)
        mech = chain_mechanism(d.geometry, i)
        for k, name in ((1, "tip1"), (2, "tip2")):
            assert np.allclose(frame.nodes[f"c{i}_tip{k}"], mech.frame_pose(q[i], name)[:3, 3], atol=1e-12)
        assert np.allclose(frame.nodes[f"c{i}_base"], mech.frame_pose(q[i], "link1")[:3, 3], atol=1e-12)
    assert len(frame.members) == 9 and sorted(frame.supports) == ["c0_base", "c1_base", "c2_base"]
    releases = sum((m.release_i is not None) + (m.release_j is not None) for m in frame.members)
    assert releases == 12  # four passive joints per chain (eq. 5.13-5.14)


@pytest.mark.parametrize("offset_mm", [(0, 0, 0), (55.85, -55.85, 55.85), (-40, 20, 60)])
def test_rcube_frame_matches_vjm(offset_mm):
    d = final_design()
    r = d.geometry.home + np.array(offset_mm) * 1e-3
    K_fe = frame_fem.fe_stiffness(d, r)
    K_vjm = cartesian_stiffness(d, r)
    scale = np.sqrt(np.outer(np.diag(K_vjm), np.diag(K_vjm)))
    assert np.max(np.abs(K_fe - K_vjm) / scale) < ROUND_OFF


def test_locked_passive_joints_match_eq_6_60():
    d = steel_design(RCubeGeometry(0.1117, 0.0741, 0.1218), 0.010, 0.006)
    r = d.geometry.home + np.array([0.02, 0.03, -0.04])
    K_fe = frame_fem.fe_stiffness(d, r, releases=False)
    K_vjm = cartesian_stiffness(d, r, passive=False)
    scale = np.sqrt(np.outer(np.diag(K_vjm), np.diag(K_vjm)))
    assert np.max(np.abs(K_fe - K_vjm) / scale) < ROUND_OFF
    # the passive joints must matter: the released frame is much softer than the locked one
    assert frame_fem.fe_stiffness(d, r)[0, 0] < 0.9 * K_fe[0, 0]


def test_agreement_within_the_goal_at_home():
    a = frame_fem.compare(final_design(), final_design().geometry.home)
    assert max(a.translational_difference, a.rotational_difference, a.deflection_difference) < 0.05
    # a 20 N load deflects along itself at home (the cubic symmetry of eq. 5.28)
    assert np.allclose(np.abs(a.deflection_fe[:, :3]), np.diag(np.diag(np.abs(a.deflection_fe[:, :3]))), atol=1e-12)


def test_seed_test_points_are_table_5_2():
    d = final_design()
    P = frame_fem.seed_test_positions(d)
    s = d.geometry.l1 * 0.5  # l1 sin 30 deg
    assert np.allclose(P[0] - d.geometry.home, [s, -s, s]) and np.allclose(P[8], d.geometry.home)
    assert len({tuple(x) for x in frame_fem.SEED_LOAD_SIGNS}) == 8


def test_cli_fem_json_and_figure(tmp_path):
    res = runner.invoke(app, ["rcube", "fem", "--position", "0.1117,0.1117,0.1117", "--position", "0.15,0.09,0.12",
                              "--json", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert len(data["poses"]) == 2 and data["max_difference"] < ROUND_OFF
    assert (tmp_path / "rcube_fem_vs_vjm.png").stat().st_size > 0


def test_cli_fem_unreachable_position_is_one_line_error():
    res = runner.invoke(app, ["rcube", "fem", "--position", "0.5,0.1,0.1"])
    assert res.exit_code == 2
    assert res.stderr.count("\n") == 1 and res.stderr.startswith("error:")
