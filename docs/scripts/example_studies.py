"""Regenerates the example studies' reports of docs/optimization.md ("Example studies").

Runs ``hapticdesign optimize`` on examples/studies/five-bar.yaml, five-bar-geometry.yaml and delta.yaml with seed 1,
copies each run's report.html, pareto.png, front.csv and selected.yaml to docs/figures/optimization/<study>/,
and prints the Markdown of the section: the front's size, the evaluations, the selected design and the wall
time of the whole run (this machine, one process).

Run: ``.venv/bin/python docs/scripts/example_studies.py`` (tens of minutes on a shared 2-core machine).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STUDIES = ("five-bar", "five-bar-geometry", "delta")
KEPT = ("report.html", "pareto.png", "front.csv", "selected.yaml")


def run(study: str, scratch: Path) -> tuple[dict, float]:
    out = scratch / study
    begin = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "optimize",
                           str(ROOT / "examples" / "studies" / f"{study}.yaml"), "--seed", "1", "--out", str(out),
                           "--json", "--quiet"], capture_output=True, text=True, check=True)
    elapsed = time.perf_counter() - begin
    target = ROOT / "docs" / "figures" / "optimization" / study
    target.mkdir(parents=True, exist_ok=True)
    for name in KEPT:
        shutil.copyfile(out / name, target / name)
    return json.loads(done.stdout), elapsed


def markdown(study: str, summary: dict, elapsed: float) -> str:
    selected = summary["selected"]
    values = ", ".join(f"`{k}` = {v:.4g}" for k, v in selected["variables"].items())
    objectives = ", ".join(f"{k} = {v:.4g}" for k, v in selected["objectives"].items())
    return (f"**{study}** (`examples/studies/{study}.yaml`, seed 1): {summary['evaluations']} designs evaluated, "
            f"{len(summary['front'])} on the front, whole run {elapsed:.0f} s wall. Selected (least RMS): design "
            f"{selected['design']}, {values}; {objectives}. Report: "
            f"[figures/optimization/{study}/report.html](figures/optimization/{study}/report.html).\n\n"
            f"![{study} front](figures/optimization/{study}/pareto.png)\n")


def main() -> None:
    with tempfile.TemporaryDirectory() as scratch:
        for study in STUDIES:
            summary, elapsed = run(study, Path(scratch))
            print(markdown(study, summary, elapsed))


if __name__ == "__main__":
    main()
