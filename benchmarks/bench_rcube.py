"""R-CUBE benchmarks: K_C at one pose (direct solution; goal < 1 ms) and a full set of workspace
maps (3 planes x 21 x 21 points, every metric; goal < 10 s)."""

from __future__ import annotations

import time

import numpy as np

from hapticdesign.analysis.rcube.design import final_design
from hapticdesign.analysis.rcube.metrics import METRIC_NAMES, workspace_maps
from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness


def main() -> None:
    design = final_design()
    position = design.geometry.home + np.array([0.02, -0.03, 0.01])
    cartesian_stiffness(design, position)  # compile and warm the caches
    repeats = 2000
    start = time.perf_counter()
    for _ in range(repeats):
        cartesian_stiffness(design, position)
    per_call = (time.perf_counter() - start) / repeats
    print(f"K_C at one pose (direct, unloaded): {per_call * 1e3:.3f} ms per call (goal < 1 ms)")
    workspace_maps(design, n=3)
    start = time.perf_counter()
    planes = workspace_maps(design, n=21)
    elapsed = time.perf_counter() - start
    finite = sum(int(np.isfinite(p["S_f"]).sum()) for p in planes)
    print(f"workspace maps, 3 planes x 21 x 21, {len(METRIC_NAMES)} metrics: {elapsed:.2f} s "
          f"({finite} of {3 * 441} points reachable; goal < 10 s)")


if __name__ == "__main__":
    main()
