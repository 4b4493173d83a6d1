"""Designs evaluated per second with the wall index ``kmax`` (issue 23): the five-bar of
benchmarks/bench_design_indices.py (link lengths and motor spacing, the same random designs, 25 points), ``kmax``
with its defaults (1 kHz, one sample of delay, the worst of 66 directions per point).

- batched: :func:`hapticdesign.analysis.metrics.indices.evaluate_designs` (the compiled kernels' ``J_v`` and
  ``H``, all designs' points and directions in one boundary search,
  :func:`hapticdesign.analysis.wall_stiffness.wall_limits`);
- one at a time: ``DesignSpace.device`` then :func:`hapticdesign.analysis.metrics.indices.evaluate` per design.

CPU time of this process (``time.process_time``, one thread), the best of three runs (one for one at a time).
Run it with another checkout's ``src`` on ``PYTHONPATH`` to time that version (before the batched search, both rows
are design by design).

    python benchmarks/bench_kmax.py [--designs 200]
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402  (the thread counts above must be set before NumPy loads)

import numpy as np  # noqa: E402

from bench_design_indices import BOUNDS, FIVE_BAR, _best  # noqa: E402
from hapticdesign.analysis.workspace import Workspace  # noqa: E402
from hapticdesign.devices.design_space import design_space  # noqa: E402
from hapticdesign.analysis.metrics.indices import evaluate, evaluate_designs  # noqa: E402


def main(count: int = 200) -> None:
    space = design_space(FIVE_BAR, list(BOUNDS))
    points = Workspace((0.0, 0.0, 0.18), (0.06, 0.0, 0.06), 5).points()
    rng = np.random.default_rng(0)
    designs = [{k: float(rng.uniform(*b)) for k, b in BOUNDS.items()} for _ in range(count)]
    evaluate_designs(space, designs[:5], points, ["kmax"])  # compile
    batched = _best(lambda: evaluate_designs(space, designs, points, ["kmax"]))
    feasible = sum(e.reason is None for e in evaluate_designs(space, designs, points, ["kmax"]))
    few = designs[:20]
    single = _best(lambda: [evaluate(space.device(values), points, ["kmax"]) for values in few], repeat=1)
    print(f"five-bar, {len(points)} points, kmax; {count} designs, {feasible} reach the workspace")
    print("\n".join(["| path | designs/s (one core, CPU time) | CPU s per design |", "|---|---|---|",
                     f"| batched | {count / batched:.1f} | {batched / count:.4f} |",
                     f"| one design at a time | {len(few) / single:.2f} | {single / len(few):.4f} |"]))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=200)
    main(parser.parse_args().designs)
