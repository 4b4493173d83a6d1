"""The exact equations for reading: the design's round-off dropped, numbers to 6 significant digits."""

import numpy as np

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.dynamics.symbolic import derive, export, rounded
from hapticdesign.devices.registry import preset


def test_the_linear_phantoms_mass_matrix_reads_as_the_constant_it_is():
    """Seed 000's 3-DOF Phantom design is fully linear: H is constant (§3.1). Its exact form with the seed's
    9-digit values substituted carries terms like 17*sin(theta3)/31250000000000; dropped below 1e-8 of the
    largest entry, H is constant and equals the compiled model's H at any pose to 6 digits."""
    device = preset("phantom-3dof")
    exact = derive(device, "none")
    assert "31250000000000" in export(exact, "text", "H")
    shown = rounded(exact, relative=1e-8)
    assert not shown.H.free_symbols
    text = export(shown, "text", "H")
    assert "/" not in text and len(text) < 300
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, 3)
    np.testing.assert_allclose(np.array(shown.H, dtype=float), mass_matrix(device, q), rtol=1e-5, atol=1e-12)


def test_rounding_keeps_real_terms():
    """A design that is not linear keeps its pose-dependent terms (the 6-digit numbers of the exact ones)."""
    device = preset("phantom-3dof").with_params({"m3": 0.2, "r3x": 0.02})
    exact, shown = derive(device, "none"), rounded(derive(device, "none"))
    theta = exact.theta
    assert shown.H[1, 1].free_symbols == exact.H[1, 1].free_symbols != set()
    at = {t: v for t, v in zip(theta, (0.3, -0.4, 0.7))}
    assert abs(float(shown.H[1, 2].subs(at)) / float(exact.H[1, 2].subs(at)) - 1) < 1e-5
