"""Cold start (issue 27): CPU seconds of a fresh install's first result, against the same run warm.

Each case runs in a fresh Python process with ``NUMBA_CACHE_DIR`` set to a new, empty folder (cold:
numba compiles every kernel the case needs and writes it to that folder), then once more in a second
process with the same folder (warm: the kernels load from the on-disk cache):

1. ``impedance``: ``impedance-range --duration 1`` on the default device (the 3-DOF Phantom, type 1, the
   seed's doubling-and-bisection search);
2. ``delta``: the first closed-loop run, ``impedance-range --duration 1`` on the delta of
   ``examples/devices`` (a wall on joint 1, grid 0.002 N m/rad: the compiled closed-loop plant and
   compensator in the rendering loop, error-controlled steps);
3. ``analytic``: the first analytic case, ``impedance-range --method analytic`` on the Phantom;
4. ``imports`` (only when named): importing the impedance search, the part of every warm run that is not
   the search itself (SciPy, python-control and matplotlib come with the analytic growth check);
5. ``campaign`` (only when named): a simulated campaign of 16 designs (the mini campaign of
   ``bench_simulation.py``) on 2 local Dask workers, first with the empty cache, then again into a new
   output folder.

Figures are CPU seconds (user + system) of the child process and the descendants it waited for
(``resource.getrusage(RUSAGE_CHILDREN)`` before and after it), not wall time: the machine may be shared,
and a compile spends CPU whether or not another process waits for the core. Wall time is printed beside
them (for the campaign, whose workers run in parallel, wall time is the figure of the goal).
``main(["impedance", ...])`` runs only the named cases; ``--keep DIR`` leaves the caches in DIR.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
DELTA = ROOT / "examples" / "devices" / "delta.yaml"
ONE_CORE = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}
CLI = [sys.executable, "-c", "from hapticdesign.interface.cli import main; main()"]
CAMPAIGN_DESIGNS = 16


def _campaign(work: Path, run: int) -> list[str]:
    sys.path.insert(0, str(HERE))
    from bench_simulation import _designs

    designs = work / "designs.csv"
    if not designs.exists():
        _designs(designs, CAMPAIGN_DESIGNS)
    return [*CLI, "campaign", "--designs", str(designs), "--out", str(work / f"out{run}"), "--workers", "2", "--quiet"]


CASES: dict[str, Callable[[Path, int], list[str]]] = {
    "impedance": lambda work, run: [*CLI, "impedance-range", "--duration", "1", "--json"],
    "delta": lambda work, run: [*CLI, "impedance-range", "--device", str(DELTA), "--joint", "1", "--duration", "1",
                                "--resolution", "0.002", "--k-limit", "1", "--json"],
    "analytic": lambda work, run: [*CLI, "impedance-range", "--method", "analytic", "--json"],
    "campaign": _campaign,
    "imports": lambda work, run: [sys.executable, "-c", "import hapticdesign.simulation.impedance"],
}
DEFAULT = ("impedance", "delta", "analytic")
COLD_LIMIT = 40.0
"""CPU seconds: issue 27's goal for a cold first run (and at most ``RATIO_LIMIT`` times the warm one)."""
RATIO_LIMIT = 4.0
CAMPAIGN_RATIO = 1.5
"""Issue 27's goal for a campaign: the first (cold) at most this many times the second (wall time)."""


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_once(command: list[str], cache: Path) -> tuple[float, float]:
    """CPU seconds (user + system) and wall seconds of ``command`` in a child process caching in ``cache``."""
    env = {**os.environ, **ONE_CORE, "NUMBA_CACHE_DIR": str(cache)}
    src = str(ROOT / "src")
    env["PYTHONPATH"] = src + os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else src
    cpu0, wall0 = _children_cpu(), time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True, cwd=ROOT)
    cpu, wall = _children_cpu() - cpu0, time.perf_counter() - wall0
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command[3:])} failed ({done.returncode}): {done.stderr.strip()[-2000:]}")
    return cpu, wall


def measure(name: str, keep: Path | None = None) -> dict[str, float]:
    """Cold (empty cache) and warm (same cache, next process) CPU and wall seconds of one case."""
    with tempfile.TemporaryDirectory(prefix=f"numba-cold-{name}-") as tmp:
        cache = (keep / name) if keep else Path(tmp) / "cache"
        cache.mkdir(parents=True, exist_ok=True)
        if any(cache.iterdir()):
            raise RuntimeError(f"{cache} is not empty: a cold run needs an empty cache folder")
        cold_cpu, cold_wall = run_once(CASES[name](Path(tmp), 1), cache)
        warm_cpu, warm_wall = run_once(CASES[name](Path(tmp), 2), cache)
    return {"cold_cpu": cold_cpu, "cold_wall": cold_wall, "warm_cpu": warm_cpu, "warm_wall": warm_wall}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", nargs="*", help=f"cases to run, of {', '.join(CASES)} (default: {', '.join(DEFAULT)})")
    parser.add_argument("--keep", type=Path, default=None, help="keep each case's numba cache in DIR/<case>")
    args = parser.parse_args([] if argv is None else argv)
    unknown = [c for c in args.cases if c not in CASES]
    if unknown:
        parser.error(f"unknown cases {', '.join(unknown)}; choose among {', '.join(CASES)}")
    print(f"{'case':<10} {'cold CPU-s':>10} {'warm CPU-s':>10} {'ratio':>6} {'cold wall-s':>11} {'warm wall-s':>11}  goal",
          flush=True)
    for name in args.cases or DEFAULT:
        r = measure(name, args.keep)
        if name == "campaign":
            ratio = r["cold_wall"] / r["warm_wall"]
            goal = f"wall ratio {ratio:.2f} (goal <= {CAMPAIGN_RATIO:g}): {'met' if ratio <= CAMPAIGN_RATIO else 'not met'}"
        elif name == "imports":
            goal = "no goal: part of every warm run above"
        else:
            ratio = r["cold_cpu"] / r["warm_cpu"]
            met = r["cold_cpu"] <= COLD_LIMIT and ratio <= RATIO_LIMIT
            goal = f"cold <= {COLD_LIMIT:g} CPU-s and <= {RATIO_LIMIT:g}x warm: {'met' if met else 'not met'}"
        print(f"{name:<10} {r['cold_cpu']:>10.1f} {r['warm_cpu']:>10.1f} {r['cold_cpu'] / r['warm_cpu']:>6.1f} "
              f"{r['cold_wall']:>11.1f} {r['warm_wall']:>11.1f}  {goal}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
