"""Seed 001's R-CUBE synthesis through the generic study path (examples/studies/rcube-synthesis.yaml) against the
specific path (:func:`hapticdesign.optimization.rcube.synthesis.synthesize`) on the same seed and settings (Table 7.1's
three bound sets, population 100, 150 generations, the shortest design in the first populations): wall and CPU time
of each and the ratio (goal: the generic path within 1.5 times the specific one), with the fronts compared.

Run: ``.venv/bin/python benchmarks/bench_rcube_study.py [--quick]`` (``--quick``: population 24, 15 generations).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from hapticdesign.optimization.pymoo_run import NSGA_II
from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import Study, load_study
from hapticdesign.optimization.study_run import run_study
from hapticdesign.optimization.rcube.synthesis import BOUND_SETS, hypervolume, synthesize

STUDY = Path(__file__).resolve().parents[1] / "examples" / "studies" / "rcube-synthesis.yaml"
SEED = 1


def sized(study: Study, population: int, generations: int) -> Study:
    algorithm = study.spec.algorithm.model_copy(update={"population": population, "generations": generations})
    spec = study.spec.model_copy(update={"algorithm": algorithm})
    return Study(spec, study.path, study.device_path, study.study_text, study.device_text)


def timed(function):
    wall, cpu = time.perf_counter(), time.process_time()
    result = function()
    return result, time.perf_counter() - wall, time.process_time() - cpu


def generic(study: Study):
    evaluate = StudyEvaluator(bind_study(study))
    return run_study(study, SEED, evaluate, None, None, evaluate.constraints, algorithm=NSGA_II)


def main() -> None:
    population, generations = (24, 15) if "--quick" in sys.argv else (100, 150)
    study = sized(load_study(STUDY), population, generations)
    specific, s_wall, s_cpu = timed(lambda: synthesize(BOUND_SETS, population, generations, SEED))
    run, g_wall, g_cpu = timed(lambda: generic(study))
    F = np.array([run.records[k].objectives for k in run.front])
    lengths = [sum(study.spec.with_parameters(run.records[k].values)[n] for n in ("l1", "l2", "l3")) for k in run.front]
    print(f"R-CUBE synthesis, seed {SEED}, population {population}, {generations} generations x 3 bound sets")
    print(f"specific (rcube synthesize): wall {s_wall:.1f} s, CPU {s_cpu:.1f} s; front {len(specific.front)}, "
          f"hypervolume {specific.hypervolume:.10f}, shortest {specific.front.total_length.min() * 1e3:.2f} mm")
    print(f"generic (optimize rcube-synthesis.yaml): wall {g_wall:.1f} s, CPU {g_cpu:.1f} s; front {len(run.front)}, "
          f"hypervolume {hypervolume(F):.10f}, shortest {min(lengths) * 1e3:.2f} mm")
    print(f"generic / specific: wall {g_wall / s_wall:.2f}, CPU {g_cpu / s_cpu:.2f} (goal <= 1.5)")


if __name__ == "__main__":
    main()
