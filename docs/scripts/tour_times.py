"""The README tour's long commands: the small sizes the tour runs, measured, and the full sizes, extrapolated.

The tour runs the campaigns on 6 designs (`few.csv`) and the robustness study on one design per LN level, so each
finishes in seconds; beside them the README names the full sizes (all 600 designs of `designs.csv`). This script
runs each command as a user does (a fresh process; CPU time, which the machine's load changes less than wall
time) at two sizes, fits ``time = start + per design x
designs`` through them and extrapolates to the 600 designs, then prints the Markdown table and, with ``--write``,
puts it into README.md between the tour-times markers. The machine's 1-min load average before and after is
stated under the table: the machine is shared, and times grow with its load.

Run: ``.venv/bin/python docs/scripts/tour_times.py [--write]`` (a few minutes on a shared 2-core machine).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import resource
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
BEGIN, END = "<!-- tour-times: begin (python docs/scripts/tour_times.py --write) -->", "<!-- tour-times: end -->"
LEVELS = "0,0.001,0.01,0.1,1,2"
LARGER = 5  # designs per level of the second measured size
FULL = 600  # designs of the tour's designs.csv: 100 per level at six levels


def hapticdesign(*args: str, cwd: Path) -> float:
    """CPU seconds of one command in a fresh process, its worker processes included (its output discarded)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", *args, "--quiet"],
                   cwd=cwd, check=True, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def extrapolate(sizes: tuple[int, int], seconds: tuple[float, float], full: int) -> float:
    """``start + per x full`` through the two measured sizes."""
    per = (seconds[1] - seconds[0]) / (sizes[1] - sizes[0])
    return seconds[0] + per * (full - sizes[0])


def measure(scratch: Path) -> list[tuple[str, str, float, str, float]]:
    """Per command: the tour's size, its CPU time, the full size and its extrapolated CPU time."""
    hapticdesign("designs", "--levels", LEVELS, "--count", "100", "--seed", "1", "--out", "designs.csv", cwd=scratch)
    rows = []
    sets = {}
    for per_level in (1, LARGER):  # 6 and 6 x LARGER designs
        name = f"d{per_level}.csv"
        hapticdesign("designs", "--levels", LEVELS, "--count", str(per_level), "--seed", "1", "--out", name,
                     cwd=scratch)
        sets[per_level] = name
    for method in ("simulation", "analytic"):
        seconds = tuple(hapticdesign("campaign", "--designs", sets[k], "--out", f"{method}{k}", "--method", method,
                                     cwd=scratch) for k in (1, LARGER))
        rows.append((f"`campaign --method {method}`", "6 designs (24 cases)", seconds[0],
                     f"{FULL} designs (2400 cases)", extrapolate((6, 6 * LARGER), seconds, FULL)))
    seconds = tuple(hapticdesign("robustness", "--designs", "designs.csv", "--per-level", str(k), "--errors",
                                 "0,1,5,10", "--out", f"rob{k}", cwd=scratch) for k in (1, LARGER))
    rows.append(("`robustness --errors 0,1,5,10` (5 draws)", "`--per-level 1`: 6 designs (96 searches)", seconds[0],
                 f"all {FULL} designs (9600 searches)", extrapolate((6, 6 * LARGER), seconds, FULL)))
    return rows


def minutes(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min"


def table(rows, load_before: float, load_after: float) -> str:
    lines = ["| command | tour's size | CPU time | full size | CPU time (extrapolated) |", "|---|---|---|---|---|"]
    lines += [f"| {c} | {small} | {minutes(t)} | {full} | {minutes(tf)} |" for c, small, t, full, tf in rows]
    lines += ["", f"CPU time of each command in a fresh process, its Dask workers included (start-up and loading the "
                  f"compiled kernels too); the full sizes extrapolated from 6 and {6 * LARGER} designs. Machine load (1-min load average, 2 cores, "
                  f"shared with other sessions): {load_before:.1f} at the start, {load_after:.1f} at the end."]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="put the table into README.md")
    args = parser.parse_args()
    before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as scratch:
        rows = measure(Path(scratch))
    text = table(rows, before, os.getloadavg()[0])
    print(text)
    if args.write:
        readme = README.read_text()
        start, end = readme.index(BEGIN) + len(BEGIN), readme.index(END)
        README.write_text(readme[:start] + "\n" + text + "\n" + readme[end:])


if __name__ == "__main__":
    main()
