"""Analytic linearization (seed 000 eq. 3.12-3.27), realizable linear designs, the 6-DOF verdict."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.linearity.bounds import practical_bounds, within_bounds
from hapticdesign.analysis.linearity.conditions import linear_conditions, seed_conditions
from hapticdesign.analysis.linearity.linear_designs import find_linear_designs
from hapticdesign.analysis.linearity.verdict import decide_linearizable
from hapticdesign.model.inertia import check_body, BodyInertia, SEED_FIELDS
from tests.helpers.seed_linear_conditions import seed_equations

DEPENDENT = ("r2x", "r2y", "r2z", "r2ay", "r3x", "r3y", "r3z", "r3ax", "r3az", "Iyy2a", "Izz3a", "Ixy2", "Iyz2", "Ixy3", "Ixz3")


def _random_free(phantom3, rng):
    names = phantom3.inertial_names()
    p = dict(zip(names, rng.uniform(-0.01, 0.01, len(names))))
    for body in ("2", "2a", "3", "3a"):
        p[f"m{body}"] = rng.uniform(0.02, 0.3)
        for axis in "xyz":
            p[f"r{body}{axis}"] = rng.uniform(-0.2, 0.2)
    return p


@pytest.fixture(scope="module")
def conditions3(phantom3, form3):
    return linear_conditions(phantom3, form3)


def _vector(device, p):
    return np.array([p[n] for n in device.inertial_names()])


def test_counts_match_table_3_2(conditions3):
    assert len(conditions3.pivots) == 15
    assert len(conditions3.free) == 35


def test_seed_equations_make_ln_vanish_and_breaking_one_does_not(phantom3, form3):
    rng = np.random.default_rng(4)
    l2, l3a = phantom3.params["l2"], phantom3.params["l3a"]
    for _ in range(5):
        p = seed_equations(_random_free(phantom3, rng), l2, l3a)
        assert form3.ln_seed(_vector(phantom3, p)) < 1e-14
        for name in DEPENDENT:
            broken = dict(p)
            broken[name] += 1e-3
            assert form3.ln_seed(_vector(phantom3, broken)) > 1e-10


def test_symbolic_solution_equals_seed_equations(phantom3, conditions3):
    solved = seed_conditions(phantom3, conditions3)
    assert {s.name for s in solved.solution} == set(DEPENDENT)
    rng = np.random.default_rng(8)
    p = _random_free(phantom3, rng)
    expected = seed_equations(p, phantom3.params["l2"], phantom3.params["l3a"])
    values = {sp.Symbol(k, real=True): v for k, v in p.items() if k not in DEPENDENT}
    computed = {}
    for symbol, expr in solved.solution.items():
        computed[symbol.name] = float(expr.subs(values).subs({sp.Symbol(k, real=True): v for k, v in computed.items()}))
    for name in DEPENDENT:
        assert computed[name] == pytest.approx(expected[name], rel=1e-9, abs=1e-15)


def test_constant_inertia_matrix_eq_3_27(phantom3, conditions3):
    """H is constant on LN = 0 and its K33 = K23 entry matches eq. 3.27."""
    pi = phantom3.standard_parameters()
    k = conditions3.constant_h @ pi
    q = np.random.default_rng(2).uniform(-3, 3, (4, 3))
    assert np.allclose(mass_matrix(phantom3, q), k, rtol=1e-9, atol=1e-10)  # preset rounded to 1e-10
    p = phantom3.params
    l2, l3a = p["l2"], p["l3a"]
    k33 = (l2**2 * p["m3a"] * (p["Iyy3"] * p["m3"] + p["Iyy3a"] * p["m3"] + l3a**2 * p["m2a"] * (p["m2a"] + p["m3"]))
           + 2 * l2 * l3a**2 * p["m2a"] ** 2 * p["m3a"] * p["r2ax"]
           + l3a**2 * p["m2a"] ** 2 * p["r2ax"] ** 2 * (p["m3"] + p["m3a"])) / (l2**2 * p["m3"] * p["m3a"])
    assert k[2, 2] == pytest.approx(k33, rel=1e-9)
    assert k[1, 2] == pytest.approx(k33, rel=1e-9)


def test_found_linear_designs_are_realizable_and_bounded(phantom3, form3, conditions3):
    bounds = practical_bounds(phantom3)
    designs = find_linear_designs(phantom3, form3, conditions3, bounds, 3, seed=5)
    assert np.all(form3.ln_seed(designs) < 1e-12)
    assert not np.allclose(designs[0], designs[1])
    for design in designs:
        seed = design.reshape(-1, 10)
        assert within_bounds(seed, phantom3.body_names, bounds)
        for name, row in zip(phantom3.body_names, seed):
            report = check_body(name, BodyInertia(**dict(zip(SEED_FIELDS, row))))
            assert report.error is None and report.warning is None


def test_three_dof_is_linearizable(phantom3, form3):
    assert decide_linearizable(phantom3, form3).linear_possible


def test_six_dof_verdict_certificate(phantom6, form6):
    verdict = decide_linearizable(phantom6, form6)
    assert not verdict.linear_possible
    cert = verdict.certificate
    assert cert.min_eigenvalue() >= -1e-9
    assert sum(np.trace(z) for z in cert.blocks.values()) == pytest.approx(1.0, rel=1e-6)
    assert cert.residual < 1e-8
    assert ("6", 0) in verdict.exact
    # the exact certificate: on the null space, link 6's pseudo-inertia (1,1) entry (Jyy + Jzz - Jxx)/2 is 0
    null = form6.null_space()
    k = 10 * phantom6.body_names.index("6")
    row = np.zeros(form6.n_params)
    row[k + 4], row[k + 5], row[k + 6] = -0.5, 0.5, 0.5
    assert np.abs(row @ null).max() < 1e-12
