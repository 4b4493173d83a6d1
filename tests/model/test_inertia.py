"""Inertial parameters (seed 000 Table 2.3) against bodies made of point masses, where every quantity is a sum."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.errors import UserError
from hapticdesign.model.inertia import BodyInertia, check_body, pseudo_inertia, require_consistent, standard_from_seed


def _cloud(seed: int, n: int = 40):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.01, 0.2, n), rng.normal([0.05, -0.02, 0.1], 0.04, (n, 3))


def _seed_body(masses, points) -> BodyInertia:
    """The seed's parameters of a point cloud: mass, mass centre, moments and (positive) products about it."""
    m = masses.sum()
    r = masses @ points / m
    d = points - r
    return BodyInertia(
        m, *r,
        Ixx=float(masses @ (d[:, 1] ** 2 + d[:, 2] ** 2)), Iyy=float(masses @ (d[:, 0] ** 2 + d[:, 2] ** 2)),
        Izz=float(masses @ (d[:, 0] ** 2 + d[:, 1] ** 2)), Ixy=float(masses @ (d[:, 0] * d[:, 1])),
        Ixz=float(masses @ (d[:, 0] * d[:, 2])), Iyz=float(masses @ (d[:, 1] * d[:, 2])))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_standard_parameters_are_the_sums_about_the_frame_origin(seed):
    masses, points = _cloud(seed)
    pi = _seed_body(masses, points).standard()
    j = sum(m * (p @ p * np.eye(3) - np.outer(p, p)) for m, p in zip(masses, points))
    expected = [masses.sum(), *(masses @ points), j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2]]
    np.testing.assert_allclose(pi, expected, rtol=1e-12, atol=1e-15)
    stacked = np.stack([[getattr(_seed_body(*_cloud(s)), f) for f in ("m", "rx", "ry", "rz", "Ixx", "Iyy", "Izz",
                                                                       "Ixy", "Ixz", "Iyz")] for s in (1, 2)])
    np.testing.assert_allclose(standard_from_seed(stacked)[0], _seed_body(*_cloud(1)).standard(), rtol=1e-15)


def test_pseudo_inertia_is_the_second_moment_of_the_mass():
    """Wensing et al. (2017): P = sum m [p; 1][p; 1]^T, positive semi-definite for every rigid body."""
    masses, points = _cloud(4)
    homogeneous = np.hstack([points, np.ones((len(masses), 1))])
    expected = (homogeneous * masses[:, None]).T @ homogeneous
    np.testing.assert_allclose(pseudo_inertia(_seed_body(masses, points).standard()), expected, rtol=1e-12, atol=1e-15)


def test_consistency_classes():
    masses, points = _cloud(5)
    report = check_body("b", _seed_body(masses, points))
    assert report.error is None and report.warning is None
    assert check_body("p", BodyInertia(0.3, 0.1)).error is None  # a point mass
    # principal moments 1, 1, 3 are positive definite but break the triangle inequality
    report = check_body("t", BodyInertia(1.0, Ixx=1.0, Iyy=1.0, Izz=3.0))
    assert report.error is None and "triangle inequality" in report.warning
    assert require_consistent([report], strict=False) == [report.warning]
    with pytest.raises(UserError):
        require_consistent([report], strict=True)
    assert "negative mass" in check_body("n", BodyInertia(-1.0)).error
    assert "finite" in check_body("x", BodyInertia(float("nan"))).error
    assert "massless" in check_body("z", BodyInertia(0.0, Ixx=1e-3)).error
    assert "positive definite" in check_body("s", BodyInertia(1.0, Ixx=1e-3, Iyy=1e-3, Izz=-1e-3)).error
