"""Exact symbolic equations (seed 000 Appendix A) agree with the numeric model and the seed's print."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from hapticdesign.analysis.dynamics.device import coriolis_centrifugal, gravity, mass_matrix
from hapticdesign.analysis.dynamics.symbolic import derive, export


@pytest.mark.parametrize("name", ["phantom3", "phantom6"])
def test_symbolic_matches_numeric(name, request):
    device = request.getfixturevalue(name)
    eqs = derive(device, "all")
    rng = np.random.default_rng(0)
    values = {p: device.params[str(p)] * rng.uniform(0.5, 1.5) + rng.uniform(-1e-3, 1e-3) for p in eqs.parameters}
    dev = device.with_params({str(k): v for k, v in values.items()})
    q = rng.uniform(-np.pi, np.pi, len(eqs.theta))
    sub = {**values, **dict(zip(eqs.theta, q))}
    h = np.array(eqs.H.xreplace(sub).evalf(), dtype=float)
    c = np.array(eqs.C.xreplace(sub).evalf(), dtype=float)
    g = np.array(eqs.G.xreplace(sub).evalf(), dtype=float).ravel()
    assert np.allclose(h, mass_matrix(dev, q), rtol=1e-10, atol=1e-14)
    assert np.allclose(c, coriolis_centrifugal(dev, q), rtol=1e-10, atol=1e-14)
    assert np.allclose(g, gravity(dev, q), rtol=1e-10, atol=1e-12)


def test_appendix_a1_term(phantom3):
    """Coefficient of theta3'^2 in tau_1 as printed in Appendix A.1 (seed 000)."""
    eqs = derive(phantom3, "all")
    s = {n: sp.Symbol(n, real=True) for n in "Ixy3 Ixy3a m3a r3ax r3ay m3 r3x r3y Iyz3 Iyz3a l3a m2a r2az r3az r3z".split()}
    t2, t3 = eqs.theta[1], eqs.theta[2]
    printed = (
        (-s["Ixy3"] - s["Ixy3a"] - s["m3a"] * s["r3ax"] * s["r3ay"] - s["m3"] * s["r3x"] * s["r3y"]) * sp.cos(t2 + t3)
        + (
            s["Iyz3"] + s["Iyz3a"] - s["l3a"] * s["m2a"] * s["r2az"] + s["l3a"] * s["m3a"] * s["r3ay"]
            + s["m3a"] * s["r3ay"] * s["r3az"] + s["m3"] * s["r3y"] * s["r3z"]
        ) * sp.sin(t2 + t3)
    )
    col = eqs.C.shape[1] - 1  # the (3,3) column
    assert sp.expand(sp.expand_trig(printed) - eqs.C[0, col]) == 0


def test_partial_symbolic_and_exports(phantom3):
    eqs = derive(phantom3, "m2,r2x")
    assert {str(p) for p in eqs.parameters} == {"m2", "r2x"}
    g2 = eqs.G[1]
    assert sp.Symbol("m2", real=True) in g2.free_symbols
    latex = export(eqs, "latex", "G")
    assert latex.startswith("G_{1} = ")
    namespace: dict = {}
    exec(export(eqs, "python", "all"), namespace)
    q = np.array([0.2, -0.4, 0.9])
    tau, h, c, g = namespace["equations"](*q, 0, 0, 0, 0, 0, 0, 0.156, -0.0915576923)
    assert np.allclose(np.array(h, dtype=float), mass_matrix(phantom3, q), rtol=1e-12)
    assert np.allclose(np.array(g, dtype=float).ravel(), gravity(phantom3, q), atol=1e-12)
