"""Regenerates the example studies' reports of docs/optimization.md ("Example studies").

Runs ``hapticdesign optimize`` on examples/studies/five-bar.yaml, five-bar-geometry.yaml, five-bar-wall.yaml and
delta.yaml with seed 1, copies each run's pareto.png, front.csv and selected.yaml to
docs/figures/optimization/<study>/, and prints the Markdown of the section: the front's size, the evaluations, the
selected design (and, for a study with a ``kmax`` constraint, the front's and the selected design's worst wall
limit, read from front.csv) and the wall time of the whole run (this machine, one process).

Run: ``.venv/bin/python docs/scripts/example_studies.py [STUDY ...]`` (all four: tens of minutes on a shared 2-core
machine).
"""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STUDIES = ("five-bar", "five-bar-geometry", "five-bar-wall", "delta")
KEPT = ("pareto.png", "front.csv", "selected.yaml")  # report.html needs its folder: the docs show screenshots


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


def walls(study: str, design: int) -> str:
    """The front's range and the selected design's value of a ``min_kmax`` column of the kept front.csv, if any."""
    with open(ROOT / "docs" / "figures" / "optimization" / study / "front.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    column = next((c for c in rows[0] if c.startswith("min_kmax")), None)
    if column is None:
        return ""
    values = [float(r[column]) for r in rows]
    return (f"; the worst wall limit `{column}` = {values[design - 1]:.4g} N/m (front: {min(values):.4g} to "
            f"{max(values):.4g} N/m)")


def markdown(study: str, summary: dict, elapsed: float) -> str:
    selected = summary["selected"]
    values = ", ".join(f"`{k}` = {v:.4g}" for k, v in selected["variables"].items())
    objectives = ", ".join(f"{k} = {v:.4g}" for k, v in selected["objectives"].items())
    return (f"**{study}** (`examples/studies/{study}.yaml`, seed 1): {summary['evaluations']} designs evaluated, "
            f"{len(summary['front'])} on the front, whole run {elapsed:.0f} s wall. Selected (least RMS): design "
            f"{selected['design']}, {values}; {objectives}{walls(study, selected['design'])}.\n\n"
            f"![{study} front](figures/optimization/{study}/pareto.png)\n")


def main(studies: list[str]) -> None:
    unknown = sorted(set(studies) - set(STUDIES))
    if unknown:
        raise SystemExit(f"unknown example study {unknown[0]!r} (known: {', '.join(STUDIES)})")
    with tempfile.TemporaryDirectory() as scratch:
        for study in studies or STUDIES:
            summary, elapsed = run(study, Path(scratch))
            print(markdown(study, summary, elapsed))


if __name__ == "__main__":
    main(sys.argv[1:])
