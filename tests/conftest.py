"""Shared fixtures: presets and random physically consistent inertial parameters."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.devices.registry import preset


@pytest.fixture(scope="session")
def phantom3():
    return preset("phantom-3dof")


@pytest.fixture(scope="session")
def phantom6():
    return preset("phantom-6dof")


def random_standard_parameters(rng: np.random.Generator, n_bodies: int) -> np.ndarray:
    """Standard parameters of random rigid bodies: a random positive definite pseudo-inertia each."""
    out = []
    for _ in range(n_bodies):
        a = rng.normal(size=(4, 4)) * np.array([0.05, 0.05, 0.05, 0.5])
        p = a @ a.T + 1e-4 * np.eye(4)
        sigma, h, m = p[:3, :3], p[:3, 3], p[3, 3]
        j = np.trace(sigma) * np.eye(3) - sigma
        out.append([m, *h, j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2]])
    return np.array(out).ravel()
