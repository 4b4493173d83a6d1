"""Manufacturing-tolerance Monte Carlo of the R-CUBE (seed 001 ch. 8).

Oracles: the nominal VJM (zero tolerance), reach intervals counted by hand on the grid (eq. 5.30),
translation invariance, PyNiteFEA for a perturbed design, SciPy for segment distances, and NumPy
statistics of the per-sample values.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import minimize
from typer.testing import CliRunner

from hapticdesign.analysis.rcube import frame_fem
from hapticdesign.analysis.rcube import tolerance as tol
from hapticdesign.analysis.rcube.design import final_design, uniform_design
from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness
from hapticdesign.analysis.stiffness.materials import isotropic
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app
from hapticdesign.model.rcube import RCubeGeometry

runner = CliRunner()


def _rel(A, B):
    return np.max(np.abs(A - B)) / np.max(np.abs(B))


def test_zero_tolerance_gives_the_nominal_mechanism():
    d = final_design()
    results = tol.monte_carlo(d, tol.Tolerances(), 3, seed=5, grid=5)
    K0 = cartesian_stiffness(d, d.geometry.home)
    for r in results:
        assert _rel(r.K_C, K0) < 1e-12
        assert r.coverage == 1.0 and not r.singular_inside


def test_same_seed_same_numbers_other_seed_other_numbers():
    d, t = final_design(), tol.Tolerances((3e-4, 3e-4, 5e-4), 3e-4)
    a = [r.K_C for r in tol.monte_carlo(d, t, 4, seed=11, grid=3)]
    b = [r.K_C for r in tol.monte_carlo(d, t, 4, seed=11, grid=3)]
    c = [r.K_C for r in tol.monte_carlo(d, t, 4, seed=12, grid=3)]
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    assert not all(np.array_equal(x, y) for x, y in zip(a, c))


# A design whose active links bind the 160 mm cube: l1 = 70 mm, passive links long enough everywhere.
SHORT = uniform_design(RCubeGeometry(0.070, 0.25, 0.15, offset=0.2), 0.01, 0.006, isotropic(200e9))
SIDE, GRID = 0.16, 33  # grid coordinates -80, -75, ..., 80 mm around home


def _kept(reach: float) -> int:
    """Grid coordinates strictly inside the active reach |r_a - S| < l1 (eq. 5.30)."""
    axis = np.linspace(-SIDE / 2, SIDE / 2, GRID)
    return int(np.sum(np.abs(axis) < reach - 1e-12))


@pytest.mark.parametrize("delta", [-0.0005, 0.0075])
def test_l1_error_changes_the_reach_by_the_computed_amount(delta):
    lengths = np.zeros((3, 3))
    lengths[0, 0] = delta  # chain 1's l1 only: its reach limits x, the nominal l1 limits y and z
    r = tol.evaluate_sample(SHORT, lengths, np.zeros((3, 3)), SIDE, GRID)
    assert r.coverage == pytest.approx(_kept(0.070 + delta) * _kept(0.070) ** 2 / GRID**3, abs=1e-15)
    lengths[:, 0] = delta  # every chain: the cube shrinks or grows along all three axes
    r = tol.evaluate_sample(SHORT, lengths, np.zeros((3, 3)), SIDE, GRID)
    assert r.coverage == pytest.approx((_kept(0.070 + delta) / GRID) ** 3, abs=1e-15)


def test_base_offset_along_the_axis_moves_the_reach_interval():
    base = np.zeros((3, 3))
    base[1, 1] = 0.012  # chain 2's actuated joint 12 mm further along y: y in (S + 12 - 70, S + 12 + 70) mm
    r = tol.evaluate_sample(SHORT, np.zeros((3, 3)), base, SIDE, GRID)
    axis = np.linspace(-SIDE / 2, SIDE / 2, GRID)
    kept = np.sum(np.abs(axis - 0.012) < 0.070 - 1e-12)
    assert r.coverage == pytest.approx(kept * _kept(0.070) ** 2 / GRID**3, abs=1e-15)


def test_common_base_shift_is_a_translation_of_the_whole_mechanism():
    d = final_design()
    e = np.array([0.004, -0.003, 0.005])
    r = tol.evaluate_sample(d, np.zeros((3, 3)), np.tile(e, (3, 1)), 0.12, 3)
    assert _rel(r.K_C, cartesian_stiffness(d, d.geometry.home - e)) < 1e-10


def test_common_length_errors_against_pynite_frame():
    d = final_design()
    dl = np.array([4e-4, -3e-4, 5e-4])
    r = tol.evaluate_sample(d, np.tile(dl, (3, 1)), np.zeros((3, 3)), 0.12, 3)
    g = d.geometry
    perturbed = d.with_geometry(RCubeGeometry(g.l1 + dl[0], g.l2 + dl[1], g.l3 + dl[2], offset=g.S))
    K_fe = frame_fem.fe_stiffness(perturbed, g.home)
    assert _rel(r.K_C, K_fe) < 1e-8
    assert _rel(r.K_C, cartesian_stiffness(d, g.home)) > 1e-3  # the errors do change K_C


def test_segment_distance_against_scipy():
    rng = np.random.default_rng(7)
    P = rng.normal(size=(40, 4, 3))
    P[0, 3] = P[0, 2] + 2.0 * (P[0, 1] - P[0, 0])  # parallel pair
    P[1, 2:] = P[1, :2] + np.array([0.0, 0.0, 0.5])  # parallel, offset copy
    got = tol.segment_distance(P[:, 0], P[:, 1], P[:, 2], P[:, 3])
    for k in range(len(P)):
        f = lambda st: np.linalg.norm(P[k, 0] + st[0] * (P[k, 1] - P[k, 0]) - P[k, 2] - st[1] * (P[k, 3] - P[k, 2]))
        best = min(minimize(f, x0, bounds=[(0, 1), (0, 1)], method="L-BFGS-B", options={"ftol": 1e-15, "gtol": 1e-12}).fun
                   for x0 in ([0.5, 0.5], [0, 0], [1, 1], [0, 1], [1, 0]))
        assert got[k] == pytest.approx(best, abs=1e-7)


def test_clearance_is_axis_distance_minus_the_radii():
    d = final_design()
    thin = uniform_design(d.geometry, 0.010, 0.006)
    fat = uniform_design(d.geometry, 0.016, 0.010)
    c_thin = tol.evaluate_sample(thin, *tol.nominal_errors(), 0.12, 5).min_clearance
    c_fat = tol.evaluate_sample(fat, *tol.nominal_errors(), 0.12, 5).min_clearance
    assert c_fat + 0.016 == pytest.approx(c_thin + 0.010, abs=1e-15)  # equal tubes: gap = distance - 2 R
    huge = uniform_design(d.geometry, 0.2, 0.1)
    assert tol.evaluate_sample(huge, *tol.nominal_errors(), 0.12, 3).min_clearance < 0.0


def test_summary_statistics_match_numpy():
    d = final_design()
    results = tol.monte_carlo(d, tol.Tolerances((5e-4, 5e-4, 5e-4), 5e-4), 5, seed=2, grid=3)
    s = tol.summary(results[0], results)
    kxx = np.array([r.K_C[0, 0] for r in results])
    assert s["K_C_diagonal"]["Kxx"]["mean"] == pytest.approx(np.mean(kxx), rel=1e-14)
    assert s["K_C_diagonal"]["Kxx"]["std"] == pytest.approx(np.std(kxx, ddof=1), rel=1e-12)
    defl = [max(np.linalg.norm(np.linalg.solve(r.K_C, np.r_[20.0 * np.eye(3)[k], np.zeros(3)])[:3]) for k in range(3))
            for r in results]
    assert s["deflection_worst_axis"]["max"] == pytest.approx(max(defl), rel=1e-12)
    assert s["samples_colliding"] == sum(r.min_clearance < 0 for r in results)


def test_iso_2768_medium_and_file_tolerances(tmp_path):
    assert tol.iso2768_medium(0.0741) == 0.3e-3 and tol.iso2768_medium(0.1218) == 0.5e-3
    f = tmp_path / "design.yaml"
    f.write_text("l1: 0.1117\nl2: 0.0741\nl3: 0.1218\ntolerances: {l1: 1.0e-4, joint_offset: 2.0e-4}\n")
    t = tol.tolerances_from_file(f, final_design())
    assert t.lengths == (1e-4, 0.3e-3, 0.5e-3) and t.joint_offset == 2e-4
    with pytest.raises(UserError):
        tol.Tolerances((-1e-4, 0.0, 0.0), 0.0)


def test_budget_refuses_large_runs_unless_allowed():
    with pytest.raises(UserError):
        tol.check_budget(10**6, 7)
    assert tol.check_budget(10**6, 7, allow=True) > tol.DEFAULT_MAX_SECONDS


def test_cli_tolerance_json_is_reproducible_and_refuses_large_runs(tmp_path):
    args = ["rcube", "tolerance", "--samples", "3", "--seed", "4", "--grid", "3", "--json"]
    a = runner.invoke(app, args + ["--out", str(tmp_path)])
    b = runner.invoke(app, args)
    assert a.exit_code == 0, a.output
    da, db = json.loads(a.stdout), json.loads(b.stdout)
    assert da["K_C_diagonal"] == db["K_C_diagonal"] and da["samples"] == 3
    assert (tmp_path / "rcube_tolerance.png").stat().st_size > 0
    res = runner.invoke(app, ["rcube", "tolerance", "--samples", "1000000"])
    assert res.exit_code == 2 and res.stderr.count("\n") == 1 and "--allow-long" in res.stderr
