"""Physical consistency of inertial parameters (Wensing, Kim & Slotine 2017; seed 000 eq. 3.28)."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.dynamics.device import coriolis_centrifugal, gravity, mass_matrix
from hapticdesign.errors import PhysicalConsistencyWarning, UserError
from hapticdesign.model.inertia import BodyInertia, check_body, pseudo_inertia


def test_default_design_is_consistent_and_exactly_linear(phantom3):
    """The built-in default is eq. 3.33 made exact and realizable: H, G constant, C = 0."""
    assert phantom3.check(strict=True) == []
    rng = np.random.default_rng(0)
    qs = rng.uniform(-np.pi, np.pi, (50, 3))
    h = mass_matrix(phantom3, qs)
    assert np.abs(h - h[0]).max() <= 1e-9 * np.abs(h).max()
    assert np.abs(coriolis_centrifugal(phantom3, qs)).max() <= 1e-9
    assert np.abs(gravity(phantom3, qs)).max() <= 1e-9


def test_printed_eq_333_link2_breaks_triangle_inequality(phantom3):
    printed = phantom3.with_params({"Ixx2": 0.00982641})
    with pytest.warns(PhysicalConsistencyWarning, match="triangle"):
        printed.check()
    with pytest.raises(UserError, match="triangle"):
        printed.check(strict=True)


@pytest.mark.parametrize(
    "override, message",
    [
        ({"m2": -0.1}, "negative mass"),
        ({"m2": 0.0}, "massless body with non-zero inertia"),
        ({"Ixy2": 0.02}, "not positive definite"),
        ({"Izz3": -1e-3}, "not positive definite"),
    ],
)
def test_non_physical_bodies_are_errors(phantom3, override, message):
    with pytest.raises(UserError, match=message):
        phantom3.with_params(override).check()


def test_unknown_and_non_finite_parameters(phantom3):
    with pytest.raises(UserError, match="unknown parameter name 'M2'.*did you mean m2"):
        phantom3.with_params({"M2": 1.0})
    with pytest.raises(UserError, match="finite"):
        phantom3.with_params({"m2": float("nan")})


def test_pseudo_inertia_matches_triangle_inequality():
    """Pseudo-inertia PSD <=> m >= 0 and principal moments satisfy the triangle inequality."""
    rng = np.random.default_rng(1)
    for _ in range(200):
        principal = rng.uniform(0.1, 1.0, 3)
        rot = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        ic = rot @ np.diag(principal) @ rot.T
        body = BodyInertia(rng.uniform(0.1, 2), *rng.normal(size=3), ic[0, 0], ic[1, 1], ic[2, 2], -ic[0, 1], -ic[0, 2], -ic[1, 2])
        a, b, c = np.sort(principal)
        triangle = a + b >= c
        psd = np.linalg.eigvalsh(pseudo_inertia(body.standard()))[0] >= -1e-12
        assert triangle == psd
        assert (check_body("x", body).warning is None) == triangle
