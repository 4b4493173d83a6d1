"""Seed 001's printed Tables 7.2-7.7 (transcribed CSV files next to this module)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

HERE = Path(__file__).parents[1] / "optimization"  # the seed tables sit beside the tests that use them


def table(name: str) -> np.ndarray:
    """Rows of ``seed001_<name>.csv`` without the header; column 0 is the solution number."""
    return np.loadtxt(HERE / f"seed001_{name}.csv", delimiter=",", skiprows=1)


def table_7_2_designs() -> np.ndarray:
    """Table 7.2 as design vectors ``(q_max, l2, l3)``; ``q_max`` from the printed ``l1`` (eq. 6.24),
    which carries more digits than the printed angle."""
    t = table("table_7_2")
    return np.column_stack([np.arcsin(60.0 / t[:, 1]), t[:, 2] / 1e3, t[:, 3] / 1e3])
