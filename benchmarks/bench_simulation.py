"""Simulation benchmarks (issue 4): numba loop vs solve_ivp, and the full-campaign time.

1. One 5-s virtual-wall simulation of the 3-DOF Phantom at the seed's settings (type 1, K = 4
   N m/rad, T = 1 ms, step 1e-4 s) with the numba RK4 loop and with the plain SciPy loop
   (``solve_ivp`` RK45 per sample period, checking the excursion at every plant step as the
   kernel does), in the same run. Goal (issue 15): 200 x faster.
2. A mini campaign (16 designs x 2 criteria x 2 types) on local Dask processes, extrapolated to
   the seed's 600 designs (2400 cases). Goal: under 15 minutes on 2 cores.
3. With ``--full``: the seed's whole campaign for real, 600 designs (Table 3.3 levels, 100 each,
   seed 1, made by the Linearity Number engine) x 2 criteria x 2 types = 2400 simulations, timed
   end to end (design generation separately). ``--realizability seed`` makes the designs under
   eq. 3.28 only, as the seed's were; ``--out DIR`` keeps the campaign folder.

   python benchmarks/bench_simulation.py --full [--realizability rigid-body|seed] [--out DIR]
4. With ``--cases`` only the impedance cases of 16 designs, analytic against simulated, per type (CPU
   time per case of this process).
5. With ``--compare SIM_DIR AN_DIR``: two finished campaigns on the same designs (``campaign --method
   simulation`` and ``--method analytic``) side by side per LN level and type: means of K_max and of the
   bandwidth, the share of equal results (K_max equal, bandwidths within 0.05 Hz) and the mean
   difference; ``--figure PATH`` plots the analytic against the simulated bandwidths.
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from hapticdesign.devices.registry import preset
from hapticdesign.simulation.campaign import META_COLUMNS, run_campaign
from hapticdesign.simulation.impedance import type_paths
from hapticdesign.simulation.config import LoopConfig, Wall
from hapticdesign.simulation.loop import simulate

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: the tests' SciPy loop
from tests.helpers.reference import simulate_adaptive  # noqa: E402


def _wall_run() -> None:
    device = preset("phantom-3dof").with_params({"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05})
    config = LoopConfig(duration=5.0, wall=Wall(0, 4.0, 0.0, 0.01))
    paths = type_paths(1, 3)
    simulate(device, config, paths)  # compile / load the numba cache
    runs = 5
    t0 = time.perf_counter()
    for _ in range(runs):
        fast = simulate(device, config, paths)
    t_fast = (time.perf_counter() - t0) / runs
    t0 = time.perf_counter()
    slow = simulate_adaptive(device, config, paths)
    t_slow = time.perf_counter() - t0
    print(f"5-s wall simulation, type 1: numba RK4 {t_fast * 1e3:.1f} ms, solve_ivp {t_slow:.2f} s, "
          f"speed-up {t_slow / t_fast:.0f}x (max |dq| = {np.abs(fast.q - slow.q).max():.1e} rad)")
    paths2 = type_paths(2, 3)
    simulate(device, config, paths2)
    t0 = time.perf_counter()
    for _ in range(runs):
        simulate(device, config, paths2)
    t_fast2 = (time.perf_counter() - t0) / runs
    t0 = time.perf_counter()
    simulate_adaptive(device, config, paths2)
    t_slow2 = time.perf_counter() - t0
    print(f"5-s wall simulation, type 2: numba RK4 {t_fast2 * 1e3:.1f} ms, solve_ivp {t_slow2:.2f} s, "
          f"speed-up {t_slow2 / t_fast2:.0f}x")


def _analytic_against_simulated() -> None:
    """Impedance cases of the campaign answered analytically and by simulation, same designs, one process."""
    from hapticdesign.simulation.campaign import CampaignOptions, read_designs, run_case

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "designs.csv"
        _designs(path, 16)
        designs = read_designs(path)
    timings = {}
    for method in ("analytic", "simulation"):
        options = CampaignOptions(method=method)
        run_case("phantom-3dof", designs[0].params, "impedance", 1, options)  # compile / warm up
        for sim_type in (1, 2):
            t0 = time.process_time()
            values = [run_case("phantom-3dof", d.params, "impedance", sim_type, options)["value"] for d in designs]
            timings[method, sim_type] = (time.process_time() - t0) / len(values), values
    for sim_type in (1, 2):
        analytic, simulated = timings["analytic", sim_type], timings["simulation", sim_type]
        same = sum(a == b for a, b in zip(analytic[1], simulated[1]))
        print(f"impedance case, type {sim_type} (CPU time of this process): analytic {analytic[0] * 1e3:.1f} ms, "
              f"simulated {simulated[0] * 1e3:.1f} ms ({simulated[0] / analytic[0]:.1f}x); same K_max in {same} of "
              f"{len(analytic[1])} designs")


def _designs(path: Path, count: int) -> None:
    device = preset("phantom-3dof")
    names = device.inertial_names()
    rng = np.random.default_rng(0)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, ["design", *META_COLUMNS, *names])
        writer.writeheader()
        for i in range(count):
            values = {n: device.params[n] for n in names}
            if i:
                values.update({"r3y": rng.uniform(-0.01, 0.01), "Ixy2": rng.uniform(-4e-4, 4e-4),
                               "m3": rng.uniform(0.03, 0.08), "Iyy1": rng.uniform(0.002, 0.02)})
            writer.writerow({"design": f"b{i}", "level": float(i % 2), "ln": 0.0, "ln_H": 0.0, "ln_C": 0.0,
                             "ln_G": 0.0, **values})


def _campaign() -> None:
    count = 16
    stamps: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        designs = Path(tmp) / "designs.csv"
        _designs(designs, count)
        workers = min(2, os.cpu_count() or 1)
        t0 = time.perf_counter()
        counts = run_campaign(designs, Path(tmp) / "out", workers=workers,
                              progress=lambda done, total: stamps.append(time.perf_counter()))
        elapsed = time.perf_counter() - t0
    rate = (len(stamps) - 1) / (stamps[-1] - stamps[0])
    startup = stamps[0] - t0
    full = 2400 / rate + startup
    print(f"campaign: {counts['cases']} cases on {workers} processes in {elapsed:.1f} s (start-up and first case "
          f"{startup:.1f} s, then {rate:.2f} cases/s); 600 designs x 2 criteria x 2 types (2400 cases) "
          f"extrapolate to {full / 60:.1f} min")


def _full_campaign(realizability: str, out: Path | None, workers: int) -> None:
    from hapticdesign.interface.commands.linearity_adapter import write_design_set

    with tempfile.TemporaryDirectory() as tmp:
        folder = out or Path(tmp) / "campaign"
        folder.mkdir(parents=True, exist_ok=True)
        designs = folder / "designs.csv"
        t0 = time.perf_counter()
        write_design_set("phantom-3dof", None, None, False, "0,0.001,0.01,0.1,1,2", 100, 1, designs, "fast",
                         realizability)
        t_designs = time.perf_counter() - t0
        t0 = time.perf_counter()
        counts = run_campaign(designs, folder, workers=workers)
        elapsed = time.perf_counter() - t0
    print(f"full campaign ({realizability} designs): 600 designs made in {t_designs:.1f} s; {counts['run']} of "
          f"{counts['cases']} cases run ({counts['skipped']} resumed) on {workers} processes in "
          f"{elapsed / 60:.1f} min ({counts['run'] / elapsed:.2f} cases/s; goal < 15 min)")


def _compare(simulated: Path, analytic: Path, figure: Path | None) -> None:
    """Per level and type: means, share of equal results and mean difference (analytic - simulated)."""
    rows = {name: {r["design"]: r for r in csv.DictReader((folder / "results.csv").open())}
            for name, folder in (("sim", simulated), ("an", analytic))}

    def column(name: str, key: str, designs: list[str]) -> np.ndarray:
        return np.array([float(rows[name][d][key]) if rows[name][d][key] else np.nan for d in designs])

    print("| LN | type | K_max simulated | K_max analytic | same K_max | mean difference | bandwidth simulated [Hz] "
          "| bandwidth analytic [Hz] | within 0.05 Hz | mean difference [Hz] | largest difference [Hz] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    levels = sorted({float(r["level"]) for r in rows["sim"].values()})
    for level in levels:
        designs = [d for d, r in rows["sim"].items() if float(r["level"]) == level]
        for t in (1, 2):
            ks, ka = column("sim", f"k_max_type{t}", designs), column("an", f"k_max_type{t}", designs)
            bs, ba = column("sim", f"bandwidth_hz_type{t}", designs), column("an", f"bandwidth_hz_type{t}", designs)
            print(f"| {level:g} | {t} | {ks.mean():.2f} | {ka.mean():.2f} | {100 * np.mean(ks == ka):.0f} % | "
                  f"{np.mean(ka - ks):+.2f} | {np.nanmean(bs):.4f} | {np.nanmean(ba):.4f} | "
                  f"{100 * np.mean(np.abs(ba - bs) < 0.05):.0f} % | {np.nanmean(ba - bs):+.4f} | "
                  f"{np.nanmax(np.abs(ba - bs)):.4f} |")
    if figure is None:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    for level in levels:
        designs = [d for d, r in rows["sim"].items() if float(r["level"]) == level]
        ax.scatter(column("sim", "bandwidth_hz_type2", designs), column("an", "bandwidth_hz_type2", designs), s=10,
                   label=f"LN = {level:g}")
    lo, hi = ax.get_xlim()
    ax.plot([lo, hi], [lo, hi], "k:", lw=0.8)
    ax.set_xlabel("simulated bandwidth, type 2 [Hz]")
    ax.set_ylabel("analytic bandwidth, type 2 [Hz]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(figure, dpi=120)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="run the seed's whole 2400-case campaign")
    parser.add_argument("--realizability", default="rigid-body", choices=("rigid-body", "seed"))
    parser.add_argument("--out", type=Path, default=None, help="keep the full campaign in this folder")
    parser.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    parser.add_argument("--compare", nargs=2, type=Path, metavar=("SIM_DIR", "AN_DIR"),
                        help="compare a simulated and an analytic campaign of the same designs")
    parser.add_argument("--figure", type=Path, default=None, help="with --compare: the bandwidth scatter (PNG)")
    parser.add_argument("--cases", action="store_true", help="only the analytic against simulated impedance cases")
    args = parser.parse_args([] if argv is None else argv)
    if args.compare:
        _compare(*args.compare, args.figure)
        return
    if args.full:
        _full_campaign(args.realizability, args.out, args.workers)
        return
    if args.cases:
        _analytic_against_simulated()
        return
    _wall_run()
    _analytic_against_simulated()
    _campaign()


if __name__ == "__main__":
    import sys

    main(sys.argv[1:])
