"""R-CUBE optimization benchmarks: evaluations per second of each objective and the whole chain
(synthesis, selection, swarm, cross-section, plies) at the default settings (goal < 5 min)."""

from __future__ import annotations

import time

import numpy as np

from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.optimization.rcube.chain import Settings, run_chain
from hapticdesign.optimization.rcube.constraints import constraint_values
from hapticdesign.optimization.rcube.cross_section import cs1, cs2
from hapticdesign.optimization.rcube.objectives import EvaluationLinks, geometry_of, o1, o2, o3
from hapticdesign.optimization.rcube.plies import PlyEvaluator


def _rate(fn, items) -> float:
    fn(items[0])
    start = time.perf_counter()
    for item in items:
        fn(item)
    return len(items) / (time.perf_counter() - start)


def main() -> None:
    rng = np.random.default_rng(0)
    x0 = np.array([np.arcsin(60 / 111.7), 0.0741, 0.1218])
    X = x0 + rng.uniform(-0.002, 0.002, size=(200, 3)) * np.array([1.0, 1.0, 1.0])
    links = EvaluationLinks()
    designs = [links.design(geometry_of(x)) for x in X]
    print(f"O1 = tan q_max:        {_rate(o1, X[:, 0]):12.0f} evaluations/s")
    print(f"O2 = det M_C:          {_rate(lambda d: o2(d, 0.06), designs):12.0f} evaluations/s")
    print(f"O3 = 1/det K_CA:       {_rate(lambda d: o3(d, 0.06), designs):12.0f} evaluations/s")
    print(f"constraints 3-8:       {_rate(lambda x: constraint_values(x[None]), X):12.0f} evaluations/s")
    print(f"CS1, CS2:              {_rate(lambda r: (cs1(r), cs2(r)), rng.uniform(0, 0.9, 500)):12.0f} evaluations/s")
    ev = PlyEvaluator(RCubeGeometry(0.1117, 0.0741, 0.1218), 0.768)
    counts = rng.integers(1, 11, size=(300, 3, 3))
    print(f"CF1, CF2, plies:       {_rate(ev.objectives, counts):12.0f} evaluations/s")
    start = time.perf_counter()
    result = run_chain(seed=1, settings=Settings())
    elapsed = time.perf_counter() - start
    s = Settings()
    print(f"whole chain (NSGA-II {s.population} x {s.generations} x 3 sets, swarm, cross-section, plies "
          f"{s.ply_population} x {s.ply_generations}): {elapsed:.1f} s (goal < 300 s); "
          f"front {len(result.synthesis.front)}, {result.synthesis.evaluations} O2/O3 evaluations, "
          f"ratio {result.cross_section.ratio:.4f}")


if __name__ == "__main__":
    main()
