"""Study evaluation speed: designs evaluated per second in one process for the example studies
(examples/studies/five-bar.yaml: 25 workspace points, isotropy and apparent mass; delta.yaml: 27 points),
on designs drawn uniformly within the studies' bounds (seeded). The issue's goal for the five-bar is
2000 designs/s. The whole run's time comes from docs/scripts/example_studies.py.

Run: ``.venv/bin/python benchmarks/bench_study.py``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from hapticdesign.optimization.study_evaluation import bind_study
from hapticdesign.optimization.study_file import load_study
from hapticdesign.optimization.study_run import Encoding

STUDIES = Path(__file__).resolve().parents[1] / "examples" / "studies"


def rate(name: str, designs: int = 60, seed: int = 0) -> tuple[float, float, int]:
    """Designs per second, milliseconds per workspace point and the designs that reached the workspace."""
    study = load_study(STUDIES / f"{name}.yaml")
    bound = bind_study(study)
    encoding = Encoding.of(study.spec)
    rng = np.random.default_rng(seed)
    X = rng.uniform(encoding.xl, encoding.xu, size=(designs, len(encoding.names)))
    X[:, list(encoding.discrete)] = np.round(X[:, list(encoding.discrete)])
    batch = [encoding.decode(x) for x in X]
    bound.evaluate(batch[:2])  # first calls build the caches
    start = time.perf_counter()
    answers = bound.evaluate(batch)
    elapsed = time.perf_counter() - start
    return designs / elapsed, 1e3 * elapsed / (designs * len(bound.points)), sum(not a.reason for a in answers)


def main() -> None:
    for name in ("five-bar", "delta"):
        per_second, per_point, valid = rate(name)
        print(f"{name}: {per_second:.1f} designs/s, {per_point:.2f} ms per workspace point ({valid} of 60 random "
              "designs reach the workspace)")


if __name__ == "__main__":
    main()
