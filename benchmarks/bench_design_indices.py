"""Designs evaluated per second (issue 23): the five-bar with its link lengths and motor spacing as variables, 25
workspace points (a 5 x 5 grid of 60 mm x 60 mm in its plane), isotropy and apparent mass.

- batched: :func:`hapticdesign.analysis.metrics.indices.evaluate_designs`, the compiled kernels of
  :mod:`hapticdesign.analysis.design_batch` (goal >= 2000 designs/s on one core);
- one at a time: ``DesignSpace.device`` then :func:`hapticdesign.analysis.metrics.indices.evaluate` per design (the
  path every other index and device takes).

Random designs (seed 0) within l1 in [0.08, 0.13] m, l2 in [0.12, 0.17] m, d in [0.05, 0.10] m; the batched values
agree with the one-at-a-time ones (tests/design/test_design_batch.py). Times are CPU time of this process
(``time.process_time``, one thread), the best of three runs, after a warm-up that compiles the kernels.

    python benchmarks/bench_design_indices.py [--designs 2000]
    python benchmarks/bench_design_indices.py --write docs/indices.md    # replace the table there
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402  (the thread counts above must be set before NumPy loads)
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from hapticdesign.analysis.design_batch import DesignBatch  # noqa: E402
from hapticdesign.analysis.workspace import Workspace  # noqa: E402
from hapticdesign.devices.design_space import design_space  # noqa: E402
from hapticdesign.analysis.metrics.indices import evaluate, evaluate_designs  # noqa: E402

FIVE_BAR = Path(__file__).resolve().parents[1] / "examples" / "devices" / "five-bar.yaml"
BOUNDS = {"l1": (0.08, 0.13), "l2": (0.12, 0.17), "d": (0.05, 0.10)}
INDICES = ["isotropy", "apparent_mass"]


def _best(run, repeat: int = 3) -> float:
    out = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        run()
        out = min(out, time.process_time() - start)
    return out


def _stages(space, designs, points, total: float) -> dict[str, float]:
    """Shares of the batched time: the variables' arrays, the continuation to every point (the one inverse
    kinematics), ``H`` at every pose, and the rest (the range of ``J_v``, the indices, the per-design results)."""
    batch = DesignBatch(space.base)
    values = space.batch_values(designs, batch)
    offsets = batch.offsets(values.kinematic)
    reached = batch.reach_points(offsets, points)
    times = {"design variables to arrays": _best(lambda: space.batch_values(designs, batch)),
             "continuation (inverse kinematics)": _best(lambda: batch.reach_points(offsets, points)),
             "H at every pose": _best(lambda: batch.mass_matrices(offsets, reached, values.standard, values.reflected))}
    times["indices and the rest"] = max(total - sum(times.values()), 0.0)
    return {name: t / total for name, t in times.items()}


START, END = "<!-- design-indices-speed:start -->", "<!-- design-indices-speed:end -->"


def main(count: int = 2000, write: Path | None = None) -> None:
    space = design_space(FIVE_BAR, list(BOUNDS))
    points = Workspace((0.0, 0.0, 0.18), (0.06, 0.0, 0.06), 5).points()
    rng = np.random.default_rng(0)
    designs = [{k: float(rng.uniform(*b)) for k, b in BOUNDS.items()} for _ in range(count)]
    evaluate_designs(space, designs[:5], points, INDICES)  # compile
    batched = _best(lambda: evaluate_designs(space, designs, points, INDICES))
    feasible = sum(e.reason is None for e in evaluate_designs(space, designs, points, INDICES))
    stages = _stages(space, designs, points, batched)
    few = designs[:20]
    for values in few[:2]:
        evaluate(space.device(values), points, INDICES)
    single = _best(lambda: [evaluate(space.device(values), points, INDICES) for values in few], repeat=1)
    table = "\n".join([f"Load average {os.getloadavg()[0]:.1f} during this run.", "",
                       "| path | designs/s (one core, CPU time) |", "|---|---|",
                       f"| batched (compiled kernels) | {count / batched:.0f} |",
                       f"| one design at a time | {len(few) / single:.1f} |", "",
                       "| batched stage | share of the time |", "|---|---|",
                       *(f"| {name} | {share:.0%} |" for name, share in stages.items())])
    print(f"five-bar, {len(points)} points, {', '.join(INDICES)}; {count} designs, {feasible} reach the workspace")
    print(table)
    if write is not None:
        text = write.read_text()
        head, rest = text.split(START, 1)
        write.write_text(f"{head}{START}\n{table}\n{END}{rest.split(END, 1)[1]}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=2000)
    parser.add_argument("--write", type=Path, default=None, help="replace the table between the markers of this file")
    arguments = parser.parse_args()
    main(arguments.designs, arguments.write)
