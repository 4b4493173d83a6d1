"""Metric maps over planes of a workspace, saved as images (seed 001 §7.5, Figures 7.5-7.19)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.files import save_figure


def plane_grid(centre, half_width: float, n: int, normal_axis: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """An ``n x n`` grid ``(n, n, 3)`` on the plane through ``centre`` normal to ``normal_axis``,
    spanning ``+-half_width`` along the two other axes; returns the grid and the 1-D offsets."""
    if n < 2 or half_width <= 0.0:
        raise UserError("a map needs n >= 2 points per side and a positive half width")
    centre = np.asarray(centre, dtype=float)
    axes = [k for k in range(3) if k != normal_axis]
    offsets = np.linspace(-half_width, half_width, n)
    A, B = np.meshgrid(offsets, offsets, indexing="ij")
    grid = np.broadcast_to(centre, (n, n, 3)).copy()
    grid[..., axes[0]] += A
    grid[..., axes[1]] += B
    return grid, offsets


def evaluate_planes(
    evaluate: Callable[[np.ndarray], dict[str, np.ndarray]], centres, half_width: float, n: int, normal_axis: int = 2
) -> list[dict[str, np.ndarray]]:
    """``evaluate`` (positions ``(P, 3)`` to named metrics ``(P,)``) on each plane; maps ``(n, n)``."""
    out = []
    for c in centres:
        grid, _ = plane_grid(c, half_width, n, normal_axis)
        values = evaluate(grid.reshape(-1, 3))
        out.append({name: np.asarray(v, dtype=float).reshape(n, n) for name, v in values.items()})
    return out


def save_map(path: Path, values: np.ndarray, offsets: np.ndarray, title: str, labels: tuple[str, str]) -> Path:
    """One metric map as a PNG heat map (matplotlib Agg backend)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    extent = (offsets[0] * 1e3, offsets[-1] * 1e3, offsets[0] * 1e3, offsets[-1] * 1e3)
    fig, ax = plt.subplots(figsize=(4.8, 4.0), dpi=100)
    image = ax.imshow(np.ma.masked_invalid(values).T, origin="lower", extent=extent, cmap="viridis")
    fig.colorbar(image, ax=ax)
    ax.set_title(title)
    ax.set_xlabel(f"{labels[0]} (mm from centre)")
    ax.set_ylabel(f"{labels[1]} (mm from centre)")
    fig.tight_layout()
    path = save_figure(fig, path)
    plt.close(fig)
    return path
