"""Exact LN (seed 000 eq. 3.1-3.4) against the seed's Appendix B/C and brute-force averaging."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.linearity.form import linearity_form
from hapticdesign.analysis.linearity.region import parse_region
from hapticdesign.analysis.linearity.weights import Weights
from hapticdesign.errors import UserError
from tests.helpers.appendix_b import appendix_b1_gravity
from tests.helpers.ln_grid import brute_force_parts as _brute_force_parts, torus_nodes as _torus_nodes


def _seed_vector(device, values):
    names = device.inertial_names()
    out = np.zeros(len(names))
    for key, value in values.items():
        out[names.index(key)] = value
    return out


def test_appendix_c_zero_designs(form3, phantom3, appendix_c):
    for design in (d for d in appendix_c if d["level"] == 0.0):
        assert form3.ln_seed(_seed_vector(phantom3, design["params"])) < 1e-16


def test_appendix_c_level_two_designs_reproduce(form3, phantom3, appendix_c):
    """Four of the five printed LN = 2 designs reproduce to about 2e-9 relative (an independent
    implementation found the same)."""
    designs = [d for d in appendix_c if d["level"] == 2.0]
    values = form3.ln_seed(np.array([_seed_vector(phantom3, d["params"]) for d in designs]))
    printed = np.array([d["ln"] for d in designs])
    close = np.abs(values / printed - 1) < 5e-9
    assert close.sum() == 4


def test_default_preset_is_linear(form3, phantom3):
    assert form3.ln(phantom3.standard_parameters()) < 1e-15


@pytest.mark.parametrize(
    ("name", "coefficient"),
    [("Ixx2", 0.75), ("Ixx3", 1.375), ("Ixy2", 3.0), ("Ixy3", 5.0), ("Ixz3", 5.5)],
)
def test_appendix_b1_square_coefficients(form3, phantom3, name, coefficient):
    """With one variable at 1 and all others 0, LN is that variable's squared coefficient (App. B.1)."""
    assert form3.ln_seed(_seed_vector(phantom3, {name: 1.0})) == pytest.approx(coefficient, rel=1e-12)


@pytest.mark.parametrize(
    ("name", "coefficient"),
    [("Ixx4", 6.15625), ("Ixx5", 11.6934), ("Ixx6", 22.665), ("Iyy5", 13.9062)],
)
def test_appendix_b2_square_coefficients(form6, phantom6, name, coefficient):
    assert form6.ln_seed(_seed_vector(phantom6, {name: 1.0})) == pytest.approx(coefficient, abs=6e-5)


def test_appendix_b2_cross_coefficient(form6, phantom6):
    both = form6.ln_seed(_seed_vector(phantom6, {"Ixx4": 1.0, "Ixx5": 1.0}))
    single = form6.ln_seed(_seed_vector(phantom6, {"Ixx4": 1.0})) + form6.ln_seed(_seed_vector(phantom6, {"Ixx5": 1.0}))
    assert both - single == pytest.approx(5.46875, rel=1e-12)


def test_appendix_b1_gravity_polynomial(form3, phantom3):
    rng = np.random.default_rng(3)
    names = phantom3.inertial_names()
    for _ in range(5):
        x = rng.uniform(-0.3, 0.3, len(names))
        p = dict(zip(names, x))
        expected = appendix_b1_gravity(p, phantom3.params["l2"], phantom3.params["l3a"], phantom3.params["g"])
        assert form3.parts_seed(x)[2] == pytest.approx(expected, rel=1e-11)


def _random_standard(device, rng, count):
    """Random seed-variable designs (masses 0.02-0.3 kg, |r| <= 0.25 m, inertias +-0.01) in standard form."""
    from hapticdesign.model.inertia import standard_from_seed

    seeds = np.concatenate(
        [rng.uniform(0.02, 0.3, (count, len(device.body_names), 1)), rng.uniform(-0.25, 0.25, (count, len(device.body_names), 3)),
         rng.uniform(-0.01, 0.01, (count, len(device.body_names), 6))],
        axis=-1,
    )
    return standard_from_seed(seeds).reshape(count, -1)


@pytest.mark.parametrize("fixture", ["3", "6"])
def test_exact_ln_matches_grid_average(request, fixture):
    device = request.getfixturevalue(f"phantom{fixture}")
    form = request.getfixturevalue(f"form{fixture}")
    rng = np.random.default_rng(11)
    for pi in _random_standard(device, rng, 2):
        nodes = _torus_nodes(device.n_dof)
        nodes[0] = (np.array([rng.uniform(0, 2 * np.pi)]), np.ones(1))
        assert form.parts(pi) == pytest.approx(_brute_force_parts(device, pi, nodes), rel=1e-10, abs=1e-14)


def test_weighted_ln_matches_grid_average(phantom3):
    rng = np.random.default_rng(5)
    n = phantom3.n_dof
    weights = Weights(rng.uniform(0, 2, (n, n)), rng.uniform(0, 2, (n, n * (n + 1) // 2)), rng.uniform(0, 2, n))
    form = linearity_form(dynamics_of(phantom3), weights=weights)
    pi = _random_standard(phantom3, rng, 1)[0]
    nodes = _torus_nodes(n)
    assert form.parts(pi) == pytest.approx(_brute_force_parts(phantom3, pi, nodes, weights), rel=1e-10)


def _gauss_nodes(lo, hi, points=16):
    x, w = np.polynomial.legendre.leggauss(points)
    return 0.5 * (hi - lo) * x + 0.5 * (hi + lo), 0.5 * w


@pytest.mark.parametrize("fixture", ["3", "6"])
def test_box_region_matches_fine_quadrature(request, fixture):
    device = request.getfixturevalue(f"phantom{fixture}")
    region = parse_region("q2=-0.5:0.7,q3=0.2:1.9", device.n_dof)
    form = linearity_form(dynamics_of(device), region)
    rng = np.random.default_rng(7)
    pi = _random_standard(device, rng, 1)[0]
    nodes = _torus_nodes(device.n_dof, points=5)
    nodes[0] = (np.zeros(1), np.ones(1))
    nodes[1] = _gauss_nodes(-0.5, 0.7)
    nodes[2] = _gauss_nodes(0.2, 1.9)
    assert form.parts(pi) == pytest.approx(_brute_force_parts(device, pi, nodes), rel=1e-10)


def test_box_of_full_turns_equals_torus(phantom3, form3):
    form = linearity_form(dynamics_of(phantom3), parse_region("q2=-3:9.566370614359172,q3=1:7.283185307179586", 3))
    pi = _random_standard(phantom3, np.random.default_rng(1), 1)[0]
    assert form.parts(pi) == pytest.approx(form3.parts(pi), rel=1e-12)


def test_batched_equals_single(form6, phantom6):
    pis = _random_standard(phantom6, np.random.default_rng(2), 4)
    batched = form6.ln(pis)
    assert batched == pytest.approx([form6.ln(p) for p in pis], rel=1e-13)


def test_forms_are_positive_semidefinite(form6):
    for q in form6.Q:
        assert np.linalg.eigvalsh(q).min() >= -1e-12 * np.abs(q).max()


@pytest.mark.parametrize("text", ["q2=1:0", "q2=0:0", "q9=0:1", "q2=a:1", "q2=0:1,q2=1:2", "nonsense"])
def test_bad_regions(text):
    with pytest.raises(UserError):
        parse_region(text, 3)


def test_wrong_weight_shape(phantom3):
    with pytest.raises(UserError):
        linearity_form(dynamics_of(phantom3), weights=Weights(np.ones((2, 2)), np.ones((3, 6)), np.ones(3)))
