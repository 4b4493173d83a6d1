"""LN by brute force: the variances (and C's mean square) of the dynamics model's H, C, G over a tensor grid
of poses (seed 000 eq. 3.1-3.3), independent of the exact quadratic form. On a torus of full turns, equally
spaced points average the trigonometric polynomials exactly."""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.linearity.weights import Weights


def brute_force_parts(device, pi, nodes_per_axis, weights=None):
    """Average over a tensor product of nodes: ``nodes_per_axis`` is a list of (points, weights)."""
    model = dynamics_of(device)
    n = model.n_dof
    mesh = np.meshgrid(*[p for p, _ in nodes_per_axis], indexing="ij")
    wmesh = np.meshgrid(*[w for _, w in nodes_per_axis], indexing="ij")
    q = np.stack([m.ravel() for m in mesh], axis=-1)
    w = np.prod(np.stack([m.ravel() for m in wmesh]), axis=0)
    weights = weights or Weights.unit(n)
    h, c, g = model.H(q, pi), model.C(q, pi), model.G(q, pi)

    def var(x):
        mean = np.tensordot(w, x, axes=(0, 0))
        return np.tensordot(w, (x - mean) ** 2, axes=(0, 0))

    return np.array(
        [
            np.sum(weights.H * var(h)),
            np.sum(weights.C * np.tensordot(w, c**2, axes=(0, 0))),
            np.sum(weights.G * var(g)),
        ]
    )


def torus_nodes(n, points=6):
    angles = 2 * np.pi * np.arange(points) / points
    return [(angles, np.full(points, 1 / points)) for _ in range(n)]
