"""Compile cost of a fresh install's first commands (issue 43): what each command compiles, and for how long.

Each case runs the command in a fresh Python process with ``NUMBA_CACHE_DIR`` set to a new, empty folder, so
that numba compiles every kernel the command needs. Inside that process a listener on numba's event API
(``numba.core.event``, the ``numba:compile`` event, fired only when a dispatcher compiles rather than loads
from the cache) records each compile: the dispatcher, its argument types, and the CPU seconds between the
start and the end of the event (``time.process_time``), inclusive of the kernels it compiled for its callees
and exclusive of them (self). When the command ends, the process counts the specializations of every
dispatcher of the package (``len(dispatcher.signatures)``).

Cases (``main(["phantom", ...])`` runs only the named ones; the three of the issue by default):

1. ``phantom``: ``impedance-range --duration 1 --json`` on the default device (the 3-DOF Phantom);
2. ``delta``: ``impedance-range --device examples/devices/delta.yaml --joint 1 --duration 1 --resolution 0.002
   --k-limit 1 --json`` (the first closed-loop run);
3. ``five-bar``: ``optimize examples/studies/five-bar-geometry.yaml --seed 1`` (into a temporary folder);
4. ``demo`` (only when named): ``hapticdesign demo``, the README's ``make demo``;
5. ``falcon-spec`` and ``falcon-study`` (only when named): ``spec`` of examples/devices/falcon-assumed-motors.yaml
   and ``optimize examples/studies/falcon-redesign.yaml --seed 1``, the commands whose first compiles the compile
   notice's typical times per area (:data:`hapticdesign.simulation.warmup.AREAS`) were measured on.

Figures are CPU seconds (user + system) of the child process (``resource.getrusage(RUSAGE_CHILDREN)``
before and after it), not wall time: the machine may be shared, and a compile spends CPU whether or not
another process waits for the core. The compile figures per kernel are the process's CPU time, so they are
comparable with the total. ``--warm`` runs each case a second time with the same cache (kernels loaded, not
compiled). The output is a Markdown table per case and a summary, headed by the load average.
"""

from __future__ import annotations

import argparse
import json
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
FIVE_BAR = ROOT / "examples" / "studies" / "five-bar-geometry.yaml"
FALCON = ROOT / "examples" / "devices" / "falcon-assumed-motors.yaml"
FALCON_STUDY = ROOT / "examples" / "studies" / "falcon-redesign.yaml"
ONE_CORE = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}

CASES: dict[str, Callable[[Path], list[str]]] = {
    "phantom": lambda work: ["impedance-range", "--duration", "1", "--json"],
    "delta": lambda work: ["impedance-range", "--device", str(DELTA), "--joint", "1", "--duration", "1",
                           "--resolution", "0.002", "--k-limit", "1", "--json"],
    "five-bar": lambda work: ["optimize", str(FIVE_BAR), "--seed", "1", "--out", str(work / "five-bar")],
    "demo": lambda work: ["demo"],
    "falcon-spec": lambda work: ["spec", "--device", str(FALCON), "--out", str(work / "falcon-spec")],
    "falcon-study": lambda work: ["optimize", str(FALCON_STUDY), "--seed", "1", "--out", str(work / "falcon-study")],
}
DEFAULT = ("phantom", "delta", "five-bar")
GOALS = {"phantom": 15.0, "delta": 20.0, "five-bar": 40.0}
"""CPU seconds: issue 43's goal for each case's first run with an empty cache."""

CHILD = r'''
import atexit, json, sys, time
from numba.core import event
from numba.core.dispatcher import Dispatcher

RECORDS, STACK = [], []


class Recorder(event.Listener):
    """Each compile's dispatcher, argument types and CPU seconds (inclusive, and exclusive of nested compiles)."""

    def on_start(self, ev):
        STACK.append([time.process_time(), 0.0])

    def on_end(self, ev):
        start, nested = STACK.pop()
        spent = time.process_time() - start
        if STACK:
            STACK[-1][1] += spent
        d = ev.data["dispatcher"]
        f = d.py_func
        RECORDS.append({"kernel": f"{f.__module__}.{f.__qualname__}", "args": str(ev.data["args"]),
                        "inclusive": spent, "self": spent - nested, "depth": len(STACK)})


def dump():
    kernels = {}
    for name, module in list(sys.modules.items()):
        if not name.startswith("hapticdesign"):
            continue
        for value in list(vars(module).values()):
            if isinstance(value, Dispatcher) and value.py_func.__module__ == name:
                kernels[f"{name}.{value.py_func.__qualname__}"] = [str(s) for s in value.signatures]
    with open(OUT, "w") as handle:
        json.dump({"compiles": RECORDS, "kernels": kernels, "cpu_at_exit": time.process_time()}, handle)


OUT = sys.argv[1]
atexit.register(dump)
event.register("numba:compile", Recorder())
sys.argv = ["hapticdesign", *sys.argv[2:]]
from hapticdesign.interface.cli import main
main()
'''


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_case(name: str, cache: Path, work: Path) -> dict:
    """Run case ``name`` in a child process caching in ``cache``: its CPU and wall seconds, compiles and kernels."""
    record = work / f"{name}-{time.monotonic_ns()}.json"
    env = {**os.environ, **ONE_CORE, "NUMBA_CACHE_DIR": str(cache)}
    src = str(ROOT / "src")
    env["PYTHONPATH"] = src + os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else src
    command = [sys.executable, "-c", CHILD, str(record), *CASES[name](work)]
    cpu0, wall0 = _children_cpu(), time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True, cwd=work)
    cpu, wall = _children_cpu() - cpu0, time.perf_counter() - wall0
    if done.returncode != 0:
        raise RuntimeError(f"{name} failed ({done.returncode}): {done.stderr.strip()[-2000:]}")
    result = json.loads(record.read_text())
    result.update(cpu=cpu, wall=wall, stderr=done.stderr)
    return result


def kernel_table(result: dict, top: int) -> list[str]:
    """Markdown rows: the ``top`` kernels by compile CPU seconds (self), with their inclusive time and count."""
    totals: dict[str, list[float]] = {}
    for c in result["compiles"]:
        entry = totals.setdefault(c["kernel"], [0.0, 0.0, 0])
        entry[0] += c["self"]
        entry[1] += c["inclusive"]
        entry[2] += 1
    rows = ["| kernel | compile CPU-s (self) | incl. callees | specializations |", "| --- | ---: | ---: | ---: |"]
    ranked = sorted(totals.items(), key=lambda kv: -kv[1][0])
    for kernel, (own, inclusive, count) in ranked[:top]:
        short = kernel.removeprefix("hapticdesign.")
        rows.append(f"| `{short}` | {own:.2f} | {inclusive:.2f} | {count} |")
    if len(ranked) > top:
        rest = sum(v[0] for _, v in ranked[top:])
        rows.append(f"| {len(ranked) - top} more | {rest:.2f} | | |")
    return rows


def area_line(result: dict) -> str:
    """Compile CPU seconds (self) per area of the compile notice (:func:`hapticdesign.simulation.warmup.area_of`),
    to set against the typical times the notice quotes."""
    sys.path.insert(0, str(ROOT / "src"))
    from hapticdesign.simulation.warmup import area_of

    spent: dict[str, float] = {}
    for c in result["compiles"]:
        found = area_of(c["kernel"].rsplit(".", 1)[0])
        area = found[0] if found else "numba's own"
        spent[area] = spent.get(area, 0.0) + c["self"]
    return "Compile CPU-s per area of the compile notice: " + ", ".join(f"{a} {s:.1f}" for a, s in spent.items())


def summary(name: str, result: dict) -> dict[str, float]:
    """Totals of one cold run: CPU, compile CPU (top-level compiles), kernels, specializations and the kernels of
    several signatures."""
    compiled = {c["kernel"] for c in result["compiles"]}
    specializations = sum(1 for _ in result["compiles"])
    multiple = sorted(k for k, s in result["kernels"].items() if len(s) > 1)
    return {"cpu": result["cpu"], "compile": sum(c["inclusive"] for c in result["compiles"] if c["depth"] == 0),
            "kernels": len(compiled), "specializations": specializations, "multiple": multiple}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", nargs="*", help=f"cases to run, of {', '.join(CASES)} (default: {', '.join(DEFAULT)})")
    parser.add_argument("--top", type=int, default=12, help="kernels listed per case (the most expensive)")
    parser.add_argument("--warm", action="store_true", help="run each case again with the same cache")
    parser.add_argument("--json", type=Path, default=None, help="write the raw records to this file")
    args = parser.parse_args([] if argv is None else argv)
    unknown = [c for c in args.cases if c not in CASES]
    if unknown:
        parser.error(f"unknown cases {', '.join(unknown)}; choose among {', '.join(CASES)}")
    load = os.getloadavg()
    print(f"Load average at start: {load[0]:.2f}, {load[1]:.2f}, {load[2]:.2f} ({os.cpu_count()} cores)\n", flush=True)
    rows = ["| first command (empty cache) | CPU-s | compiling CPU-s | kernels compiled | specializations | "
            "warm CPU-s | goal |", "| --- | ---: | ---: | ---: | ---: | ---: | --- |"]
    raw = {}
    for name in args.cases or DEFAULT:
        with tempfile.TemporaryDirectory(prefix=f"bench-compile-{name}-") as tmp:
            cache = Path(tmp) / "cache"
            cache.mkdir()
            cold = run_case(name, cache, Path(tmp))
            warm = run_case(name, cache, Path(tmp)) if args.warm else None
        s = summary(name, cold)
        raw[name] = {"cold": cold, "warm": warm}
        print(f"### `{' '.join(CASES[name](Path('OUT'))).replace(str(ROOT) + '/', '')}`\n", flush=True)
        print("\n".join(kernel_table(cold, args.top)))
        if s["multiple"]:
            several = (f"`{k.removeprefix('hapticdesign.')}` ({len(cold['kernels'][k])})" for k in s["multiple"])
            print("\nKernels with more than one specialization: " + ", ".join(several))
        print(f"\n{area_line(cold)}")
        print(f"\nCPU {s['cpu']:.1f} s, of which compiling {s['compile']:.1f} s; wall {cold['wall']:.1f} s\n",
              flush=True)
        goal = GOALS.get(name)
        verdict = f"<= {goal:g}: {'met' if s['cpu'] <= goal else 'not met'}" if goal else ""
        warm_cpu = f"{warm['cpu']:.1f}" if warm else ""
        rows.append(f"| {name} | {s['cpu']:.1f} | {s['compile']:.1f} | {s['kernels']} | {s['specializations']} | "
                    f"{warm_cpu} | {verdict} |")
    load = os.getloadavg()
    print("\n".join(rows))
    print(f"\nLoad average at end: {load[0]:.2f}, {load[1]:.2f}, {load[2]:.2f}")
    if args.json:
        args.json.write_text(json.dumps(raw, indent=1))


if __name__ == "__main__":
    main(sys.argv[1:])
