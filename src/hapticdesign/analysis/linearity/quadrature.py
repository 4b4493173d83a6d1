"""The Linearity Number of a closed-loop device: ``pi^T Q pi`` with Q from converged quadrature.

Seed 000 eq. 3.1-3.4 average the variance of every entry of H and G (and the mean square of C)
over the region R. For a tree every entry is an exact trigonometric polynomial and Q follows from
exact basis moments (:mod:`.form`). With closed loops the entries are smooth but not polynomial in
the actuated coordinates, so the averages are computed by tensor Gauss-Legendre quadrature on the
region's box (composite panels of at most pi per coordinate, as :mod:`.region`), with the entries'
regressor ``Y_e(q)`` (:class:`~hapticdesign.analysis.dynamics.closed_loop.ClosedLoopModel`):

    Q_H = sum_e w_e E[(Y_e - E Y_e)^T (Y_e - E Y_e)],  Q_C = sum_e w_e E[Y_e^T Y_e],  Q_G like Q_H,

still a quadratic form in the standard inertial parameters. The number of nodes per panel doubles
(4, 8, 16, ...) until two successive Q agree to ``REL_TOL`` of their largest entry; that change is
kept as the form's ``accuracy`` (Gauss-Legendre converges exponentially for these analytic
integrands, so the finer Q is much closer than that). The grid is traversed as a snake so that
the loop solver continues the assembly branch from node to neighbouring node.
"""

from __future__ import annotations

import math

import numpy as np

from hapticdesign.analysis.linearity.quadratic import LinearityForm
from hapticdesign.analysis.linearity.region import PANEL_LENGTH, Region
from hapticdesign.analysis.linearity.weights import Weights
from hapticdesign.errors import InputError, UserError

REL_TOL = 1e-9
LEVELS = (4, 8, 16, 32)
CHUNK = 2048


def _nodes(lo: float, hi: float, per_panel: int) -> tuple[np.ndarray, np.ndarray]:
    """Composite Gauss-Legendre nodes and weights of the uniform average over [lo, hi]."""
    panels = max(1, math.ceil((hi - lo) / PANEL_LENGTH))
    x, wx = np.polynomial.legendre.leggauss(per_panel)
    edges = np.linspace(lo, hi, panels + 1)
    half = 0.5 * np.diff(edges)
    q = (half[:, None] * x + (0.5 * (edges[1:] + edges[:-1]))[:, None]).ravel()
    return q, np.tile(wx, panels) * np.repeat(half, per_panel) / (hi - lo)


def snake_order(shape: tuple[int, ...]) -> np.ndarray:
    """Multi-indices of a grid (prod shape, d) in which neighbours differ by one step in one index."""
    if len(shape) == 1:
        return np.arange(shape[0])[:, None]
    inner = snake_order(shape[1:])
    rows = [np.hstack([np.full((len(inner), 1), i), inner if i % 2 == 0 else inner[::-1]]) for i in range(shape[0])]
    return np.vstack(rows)


def region_box(region: Region, n_dof: int) -> list[tuple[float, float]]:
    """Ranges of every actuated coordinate: the region's, else the full turn [-pi, pi]."""
    return [region.ranges.get(k, (-math.pi, math.pi)) for k in range(n_dof)]


def quadrature_poses(box: list[tuple[float, float]], per_panel: int) -> tuple[np.ndarray, np.ndarray]:
    """Tensor Gauss-Legendre poses in snake order (P, d) and their weights (P,), summing to 1."""
    axes = [_nodes(lo, hi, per_panel) for lo, hi in box]
    index = snake_order(tuple(len(q) for q, _ in axes))
    poses = np.stack([axes[k][0][index[:, k]] for k in range(len(box))], axis=-1)
    weights = np.prod([axes[k][1][index[:, k]] for k in range(len(box))], axis=0)
    return poses, weights


def _moments(model, q_full: np.ndarray, weights: np.ndarray, entry_weights: tuple) -> np.ndarray:
    """``Q_H, Q_C, Q_G`` (3, P, P) for one set of quadrature poses (two passes: means, then centred squares)."""
    parts = (model.slice_h, model.slice_c, model.slice_g)
    n = model.n_params
    mean = np.zeros((model.n_entries, n))
    for i in range(0, len(q_full), CHUNK):
        y = model.regressor_at(q_full[i:i + CHUNK])
        mean += np.tensordot(weights[i:i + CHUNK], y, axes=(0, 0))
    q = np.zeros((3, n, n))
    for i in range(0, len(q_full), CHUNK):
        y = model.regressor_at(q_full[i:i + CHUNK])
        root = np.sqrt(weights[i:i + CHUNK])[:, None, None]
        for part, (cut, w_e) in enumerate(zip(parts, entry_weights)):
            centred = y[:, cut] if part == 1 else y[:, cut] - mean[cut]
            z = (root * np.sqrt(w_e)[None, :, None] * centred).reshape(-1, n)
            q[part] += z.T @ z
    return q


def quadrature_form(model, region: Region | None = None, weights: Weights | None = None):
    """``LinearityForm`` of a closed-loop model by converged quadrature (see the module docstring)."""
    region = region or Region()
    weights = weights or Weights.unit(model.n_dof)
    box = region_box(region, model.n_dof)
    entry_weights = weights.per_entry()
    previous, change = None, math.inf
    for per_panel in LEVELS:
        poses, w = quadrature_poses(box, per_panel)
        try:
            q_full = model.configuration.full(poses)
        except UserError as exc:
            raise InputError(f"LN region {region.describe(model.mechanism.actuated_coordinates)}: {exc} "
                             "(give joint limits or a region inside the workspace)", "region") from None
        q = _moments(model, q_full, w, entry_weights)
        q = 0.5 * (q + np.swapaxes(q, 1, 2))
        if previous is not None:
            change = float(np.abs(q - previous).max() / max(np.abs(q).max(), 1e-300))
            if change <= REL_TOL:
                break
        previous = q
    return LinearityForm(q, region, weights, accuracy=change)
