"""Every study on the fast path (issue 36): what a study that varies what a designer varies costs beside a
geometry-only one, and the example five-bar study end to end.

- **(a) tubes vs geometry.** Two five-bar studies of the same size (40 designs x 60 generations, 25 workspace points,
  isotropy and apparent mass, the constraints of examples/studies/five-bar.yaml): *geometry* varies l1, l2, d of
  examples/devices/five-bar.yaml (bodies of their own); *tubes* varies the same on
  examples/studies/five-bar-tubes.yaml (bodies that are the tubes, so their masses follow the lengths and sections),
  two tube sections (links.prox1.D, links.dist1.D) and the two capstan ratios as discrete choices. Goal: tubes at
  most 1.5x the CPU of geometry. Each is run end to end (``hapticdesign optimize ... --seed 1``, CPU time of the
  child process, start-up included), and its evaluation alone is timed in this process (one generation's worth of
  random designs through the study's ``StudyEvaluator``, the best of three).
- **(b) examples/studies/five-bar.yaml end to end** (``hapticdesign optimize examples/studies/five-bar.yaml --seed 1``):
  wall-clock and CPU time of the child process. Goal: under 30 s on the project's 2-core machine.

The batched index evaluation of a five-bar over 25 points (goal (c), designs per second on one core) is
benchmarks/bench_design_indices.py. Run this script with another checkout's ``src`` on ``PYTHONPATH`` to time that
version; the machine's load (``os.getloadavg``) is printed with the figures.

    python benchmarks/bench_fast_path.py
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import resource  # noqa: E402  (the thread counts above must be set before NumPy loads)
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import yaml  # noqa: E402

from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study  # noqa: E402
from hapticdesign.optimization.study_file import load_study  # noqa: E402
from bench_study import random_designs  # noqa: E402  (benchmarks/ is the script's folder)

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "examples" / "studies"
GEOMETRY = {"l1": [0.06, 0.16], "l2": [0.10, 0.22], "d": [0.0, 0.12]}
TUBES = {**GEOMETRY, "links.prox1.D": [0.009, 0.02], "links.dist1.D": [0.008, 0.016],
         "actuators.q1.gear_ratio": {"values": [5, 8, 11.2, 13.3]},
         "actuators.q2.gear_ratio": {"values": [5, 8, 11.2, 13.3]}}


def _study(device: Path, variables: dict) -> dict:
    example = yaml.safe_load((STUDIES / "five-bar.yaml").read_text())
    return {**example, "device": str(device), "variables": variables, "objectives": example["objectives"][:2]}


def _cli(study: Path, out: Path) -> tuple[float, float]:
    """CPU and wall-clock seconds of ``hapticdesign optimize study --seed 1``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    command = "import sys; from hapticdesign.interface.cli import main; sys.argv[0] = 'hapticdesign'; sys.exit(main())"
    subprocess.run([sys.executable, "-c", command, "optimize", str(study), "--seed", "1", "--out", str(out)],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


def _evaluation(study_path: Path, designs: int = 40, seed: int = 0) -> float:
    """CPU seconds of one generation of random designs through the study's ``StudyEvaluator`` (the best of three)."""
    study = load_study(study_path)
    evaluate = StudyEvaluator(bind_study(study))
    batch = random_designs(study, designs, seed)
    evaluate(batch[:2])  # the first call builds the caches
    best = float("inf")
    for _ in range(3):
        start = time.process_time()
        evaluate(batch)
        best = min(best, time.process_time() - start)
    return best


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.1f} (2 cores)")
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        rows = []
        for name, device, variables in (("geometry", ROOT / "examples" / "devices" / "five-bar.yaml", GEOMETRY),
                                        ("tubes", STUDIES / "five-bar-tubes.yaml", TUBES)):
            path = root / f"{name}.yaml"
            path.write_text(yaml.safe_dump(_study(device, variables), sort_keys=False))
            cpu, wall = _cli(path, root / name)
            rows.append((name, cpu, wall, _evaluation(path)))
        print("| (a) study (40 x 60, 25 points) | end to end CPU s | wall s | one generation's evaluation CPU ms |")
        print("|---|---|---|---|")
        for name, cpu, wall, one in rows:
            print(f"| {name} | {cpu:.1f} | {wall:.1f} | {1e3 * one:.1f} |")
        print(f"tubes / geometry: {rows[1][1] / rows[0][1]:.2f}x end to end, {rows[1][3] / rows[0][3]:.2f}x "
              "evaluation (goal <= 1.5x)")
        cpu, wall = _cli(STUDIES / "five-bar.yaml", root / "five-bar")
        print(f"(b) examples/studies/five-bar.yaml end to end: {wall:.1f} s wall, {cpu:.1f} s CPU (goal < 30 s)")
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
