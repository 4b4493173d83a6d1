"""Study evaluation speed: designs evaluated per second in one process for the example studies
(examples/studies/five-bar.yaml: 25 workspace points, isotropy, apparent mass and stiffness over lengths,
spacing, tube sections and capstan ratios; delta.yaml: 27 points, geometry only; all batched since issue 36)
and for the five-bar study restricted to its geometry (l1, l2, d) with isotropy and apparent mass on
examples/devices/five-bar.yaml (bodies of their own, not tubes: the issue's benchmark, 25 points, batched
through the compiled kernels; goal 2000 designs/s), on designs drawn uniformly within the bounds (seeded). The whole run's time comes from docs/scripts/example_studies.py.

Run: ``.venv/bin/python benchmarks/bench_study.py``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import yaml

from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import Study, load_study, study_from_mapping
from hapticdesign.optimization.study_run import Encoding

STUDIES = Path(__file__).resolve().parents[1] / "examples" / "studies"


def geometry_only(study: Study) -> Study:
    """The study with its ``parameters`` variables only and its first two objectives, on
    examples/devices/five-bar.yaml (the same geometry, its bodies given by their parameters)."""
    data = yaml.safe_load(study.study_text)
    data["variables"] = {k: v for k, v in data["variables"].items() if "." not in k}
    data["objectives"] = data["objectives"][:2]
    device = STUDIES.parent / "devices" / "five-bar.yaml"
    return Study(study_from_mapping(data), study.path, device, yaml.safe_dump(data), device.read_text())


def random_designs(study: Study, designs: int, seed: int = 0) -> list[dict[str, float]]:
    """``designs`` designs drawn uniformly (with ``seed``) within the study's bounds, choices rounded to one."""
    encoding = Encoding.of(study.spec)
    rng = np.random.default_rng(seed)
    X = rng.uniform(encoding.xl, encoding.xu, size=(designs, len(encoding.names)))
    X[:, list(encoding.discrete)] = np.round(X[:, list(encoding.discrete)])
    return [encoding.decode(x) for x in X]


def rate(study: Study, designs: int = 60, seed: int = 0) -> tuple[float, float, int]:
    """Designs per second, milliseconds per workspace point and the designs that reached the workspace."""
    bound = bind_study(study)
    evaluate = StudyEvaluator(bound)
    batch = random_designs(study, designs, seed)
    evaluate(batch[:2])  # first calls build the caches
    start = time.perf_counter()
    answers = evaluate(batch)
    elapsed = time.perf_counter() - start
    return designs / elapsed, 1e3 * elapsed / (designs * len(bound.points)), sum(not a.reason for a in answers)


def main() -> None:
    five_bar = load_study(STUDIES / "five-bar.yaml")
    cases = {"five-bar": (five_bar, 60), "delta": (load_study(STUDIES / "delta.yaml"), 2000),
             "five-bar, geometry only": (geometry_only(five_bar), 2000)}
    for name, (study, designs) in cases.items():
        per_second, per_point, valid = rate(study, designs)
        print(f"{name}: {per_second:.1f} designs/s, {per_point:.3f} ms per workspace point ({valid} of {designs} "
              "random designs reach the workspace)")


if __name__ == "__main__":
    main()
