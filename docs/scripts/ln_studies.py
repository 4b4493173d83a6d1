"""Regenerates the table of seed 000's LN studies in docs/optimization.md ("Method convex").

Runs ``hapticdesign optimize --json`` on examples/studies/phantom-3dof-linear.yaml and phantom-6dof-ln.yaml, each in
its own process, and prints the table's rows: the number of variables, the design's LN, the convex relaxation's
lower bound and the CPU time of the process (user + system, this machine).

Run: ``.venv/bin/python docs/scripts/ln_studies.py`` (about a quarter of a minute).
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STUDIES = {
    "phantom-3dof-linear": "3-DOF, links 2, 2a, 3, 3a in eq. 3.29-3.32",
    "phantom-6dof-ln": "6-DOF (device file `examples/devices/phantom-6dof.yaml`), plus the gimbal links 4, 5, 6 in "
                       "our practical bounds",
}


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def row(study: str, what: str) -> str:
    before = _cpu()
    command = [sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "optimize",
               str(ROOT / "examples" / "studies" / f"{study}.yaml"), "--json", "--quiet"]
    summary = json.loads(subprocess.run(command, capture_output=True, text=True, check=True).stdout)
    cpu = _cpu() - before
    design = summary["selected"]
    return (f"| `examples/studies/{study}.yaml`: {what} | {len(design['variables'])} | {design['objectives']['ln']:.5g} "
            f"| {summary['lower_bound']:.5g} | {cpu:.1f} s |")


def main() -> None:
    print("| study | variables | LN of the design | lower bound | CPU |\n|---|---|---|---|---|")
    for study, what in STUDIES.items():
        print(row(study, what))


if __name__ == "__main__":
    main()
