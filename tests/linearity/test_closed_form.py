"""Closed-form LN in the seed's design variables (seed 000 Appendix B.1 / B.2)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.linearity.closed_form import closed_form
from hapticdesign.analysis.linearity.form import PARTS, linearity_form
from hapticdesign.analysis.linearity.region import parse_region
from hapticdesign.errors import UserError
from tests.helpers.appendix_b import appendix_b1_gravity


@pytest.fixture(scope="module")
def closed3(phantom3, form3):
    return closed_form(phantom3, form3, symbolic_gravity=True)


@pytest.fixture(scope="module")
def closed6(phantom6, form6):
    return closed_form(phantom6, form6)


def _symbol(closed, name):
    return next(s for s in closed.gens if s.name == name)


@pytest.mark.parametrize(
    ("name", "coefficient"),
    [("Ixx2", 0.75), ("Ixx3", 1.375), ("Ixy2", 3.0), ("Ixy3", 5.0), ("Ixz3", 5.5)],
)
def test_appendix_b1_coefficients_of_the_poly(closed3, name, coefficient):
    poly = closed3.polynomial()
    assert poly.coeff_monomial(_symbol(closed3, name) ** 2) == coefficient


def test_appendix_b2_coefficients_of_the_poly(closed6):
    poly = closed6.polynomial()
    s = {n: _symbol(closed6, n) for n in ("Ixx4", "Ixx5", "Ixx6", "Iyy5")}
    assert poly.coeff_monomial(s["Ixx4"] ** 2) == 6.15625
    assert poly.coeff_monomial(s["Ixx4"] * s["Ixx5"]) == 5.46875
    # printed by the seed to six significant digits
    assert float(poly.coeff_monomial(s["Ixx5"] ** 2)) == pytest.approx(11.6934, abs=5e-5)
    assert float(poly.coeff_monomial(s["Ixx6"] ** 2)) == pytest.approx(22.665, abs=5e-4)
    assert float(poly.coeff_monomial(s["Iyy5"] ** 2)) == pytest.approx(13.9062, abs=5e-5)


def test_appendix_b1_gravity_polynomial_term_by_term(closed3, phantom3):
    """Same monomials (g symbolic, lengths numeric) and the same coefficient for each."""
    p = {s.name: s for s in closed3.gens}
    seed = sp.Poly(sp.expand(appendix_b1_gravity(p, sp.Rational("0.215"), sp.Rational("0.0325"), p["g"])), *closed3.gens)
    expected = {m: float(c) for m, c in seed.as_dict().items()}
    ours = closed3.terms("G")
    assert set(ours) == set(expected)
    for monom, coeff in expected.items():
        assert ours[monom] == pytest.approx(coeff, rel=1e-12)
    assert phantom3.params["l2"] == 0.215 and phantom3.params["l3a"] == 0.0325


@pytest.mark.parametrize("dof", ["3", "6"])
def test_polynomial_equals_numeric_ln_at_random_designs(request, dof):
    device, form = request.getfixturevalue(f"phantom{dof}"), request.getfixturevalue(f"form{dof}")
    closed = request.getfixturevalue(f"closed{dof}")
    rng = np.random.default_rng(21)
    names = device.inertial_names()
    for _ in range(3):
        x = rng.uniform(-0.3, 0.3, len(names))
        values = {**dict(zip(names, x)), "g": device.params["g"]}
        parts = form.parts_seed(x)
        for name, value in zip(PARTS, parts):
            assert closed.evaluate(values, name) == pytest.approx(value, rel=1e-11)
        assert closed.evaluate(values) == pytest.approx(parts.sum(), rel=1e-11)


def test_python_export_runs_and_matches(closed6, phantom6, form6):
    namespace: dict = {}
    exec(closed6.export("python"), namespace)
    x = np.random.default_rng(5).uniform(-0.2, 0.2, form6.n_params)
    design = dict(zip(phantom6.inertial_names(), x))
    assert namespace["linearity_number"](**design) == pytest.approx(float(form6.ln_seed(x)), rel=1e-11)


def test_latex_export_has_every_term(closed3):
    text = closed3.export("latex")
    assert text.startswith(r"\mathrm{LN} = ")
    assert "+ 0.75 I_{xx2}^{2}" in text and "+ 5.5 I_{xz3}^{2}" in text
    assert 1 + text.count(" + ") + text.count(" - ") == len(closed3.terms())


def test_box_region_closed_form(phantom3):
    form = linearity_form(dynamics_of(phantom3), parse_region("q2=-0.5:0.7,q3=0.2:1.9", 3))
    closed = closed_form(phantom3, form)
    x = np.random.default_rng(9).uniform(-0.3, 0.3, form.n_params)
    assert closed.evaluate(dict(zip(phantom3.inertial_names(), x))) == pytest.approx(float(form.ln_seed(x)), rel=1e-10)


def test_bad_export_requests(closed3):
    with pytest.raises(UserError):
        closed3.export("pdf")
    with pytest.raises(UserError):
        closed3.terms("Q")
    with pytest.raises(UserError):
        closed3.evaluate({"m2": 0.1})
