"""Regenerates docs/optimization.md's "Redesigning the Novint Falcon": runs ``hapticdesign optimize`` on
examples/studies/falcon-redesign.yaml with seed 1, copies its pareto.png, front.csv and selected.yaml to
docs/figures/optimization/falcon-redesign/, and prints the section's numbers: the run's size and time, the selected
design beside the published Falcon (falcon-assumed-motors.yaml at home), and the lightest leg of falcon.yaml's mass
per length that reaches Novint's 4-inch cube (why the study varies the legs' mass per length).

Run: ``.venv/bin/python docs/scripts/falcon_redesign.py`` (a few minutes on a shared 2-core machine).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from hapticdesign.devices.loading import load_device
from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import load_study
from hapticdesign.studies.spec import spec_sheet

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "examples" / "studies" / "falcon-redesign.yaml"
DEVICE = ROOT / "examples" / "devices" / "falcon-assumed-motors.yaml"
TARGET = ROOT / "docs" / "figures" / "optimization" / "falcon-redesign"
KEPT = ("pareto.png", "front.csv", "selected.yaml")  # report.html needs its folder: the docs show screenshots
SEED = 1


def run(scratch: Path) -> tuple[dict, float]:
    """The study's run (``optimize --json``) and its wall time; its files copied to :data:`TARGET`."""
    out = scratch / "run"
    begin = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "optimize",
                           str(STUDY), "--seed", str(SEED), "--out", str(out), "--json", "--quiet"],
                          capture_output=True, text=True, check=True)
    elapsed = time.perf_counter() - begin
    TARGET.mkdir(parents=True, exist_ok=True)
    for name in KEPT:
        shutil.copyfile(out / name, TARGET / name)
    return json.loads(done.stdout), elapsed


def lightest_full_legs() -> tuple[dict, list[float]] | None:
    """Of a grid of arms and parallelograms at falcon.yaml's mass per length (rod = 1) and the published ratio, the
    design reaching every point of the cube with the least moving mass, and its reduced values; None if none."""
    bound = bind_study(load_study(STUDY))
    designs = [{"a": a / 1000, "b": b / 1000, "ratio": 0.110 / 0.01425, "rod": 1.0}
               for a in range(45, 86, 5) for b in range(85, 141, 5)]
    keys = list(bound.keys)
    answers = StudyEvaluator(bound)(designs)
    reached = [(d, dict(zip(keys, ans.reduced))) for d, ans in zip(designs, answers) if not ans.reason]
    if not reached:
        return None
    mass = next(k for k in keys if k[0] == "mass")
    design, values = min(reached, key=lambda item: item[1][mass])
    return design, [values[k] for k in keys]


def main() -> None:
    published = spec_sheet(load_device(DEVICE), workspace=False, simulate=False)
    with tempfile.TemporaryDirectory() as scratch:
        summary, elapsed = run(Path(scratch))
    selected = summary["selected"]
    print(f"falcon-redesign (seed {SEED}): {summary['evaluations']} designs evaluated, {len(summary['front'])} on the "
          f"front, whole run {elapsed:.0f} s wall")
    print("selected (least RMS): " + ", ".join(f"{k} = {v:.4g}" for k, v in selected["variables"].items()) + "; "
          + ", ".join(f"{k} = {v:.4g}" for k, v in selected["objectives"].items()))
    for n, design in enumerate(summary["front"], start=1):
        print(f"  front {n}: " + ", ".join(f"{k} {v:.4g}" for k, v in {**design["variables"],
                                                                      **design["objectives"]}.items()))
    print(f"published Falcon at home (assumed motors): apparent mass {published['apparent_mass']['max']:.4g} kg, "
          f"wall with the light hand {published['renderable_stiffness']['exact_with_hand']:.4g} N/m, peak force "
          f"{published['force_peak']:.4g} N")
    lightest = lightest_full_legs()
    print("lightest design at falcon.yaml's mass per length reaching the cube: "
          + ("none on the grid" if lightest is None else f"{lightest[0]} -> {[round(v, 4) for v in lightest[1]]}"))


if __name__ == "__main__":
    main()
