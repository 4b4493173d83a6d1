"""The README's speed table, measured: the parts of the benchmarks that feed it, run on this machine.

    python benchmarks/run_all.py --readme            # print the table
    python benchmarks/run_all.py --readme --write    # and put it into README.md between the speed-table markers

Each row reuses its benchmark's code (bench_dynamics, bench_linearity, bench_simulation, bench_loops, bench_rcube,
bench_optimization) or runs the command a user runs (``study phantom --quick``). The machine's load average
(1 min) before and after is printed under the table: the machine is shared, and times grow with its load.
The plain-SymPy baseline of the 6-DOF equations (over 15 minutes) is not re-run: the table quotes issue 2's
figure for it, marked as such.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
ROOT = HERE.parent
README = ROOT / "README.md"
BEGIN, END = "<!-- speed-table: begin (python benchmarks/run_all.py --readme --write) -->", "<!-- speed-table: end -->"


def _bench(name: str):
    spec = importlib.util.spec_from_file_location(name, HERE / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def dynamics_rows() -> list[tuple[str, str, str]]:
    b = _bench("bench_dynamics")
    with tempfile.TemporaryDirectory() as cache:
        cold = b._run(b.BUILD.format(name="phantom-6dof"), {"NUMBA_CACHE_DIR": cache})[0]
        warm = b._run(b.BUILD.format(name="phantom-6dof"), {"NUMBA_CACHE_DIR": cache})[0]
    start = time.perf_counter()
    b._run("from hapticdesign.devices.registry import preset\nfrom hapticdesign.analysis.dynamics.symbolic import derive"
           "\nderive(preset('phantom-6dof'), 'all')")
    symbolic = time.perf_counter() - start
    per_s, lam_per_s = b._run(b.BATCH.format(poses=1_000_000), b.ONE_CORE)
    return [
        ("6-DOF Phantom, nothing to numeric H, C, G with all 80 inertial parameters as inputs",
         "plain SymPy: 35 s build + 163 s `lambdify` (issue 2's figure; not re-run)",
         f"{cold:.1f} s cold (JIT compile included), {warm:.1f} s with a warm cache"),
        ("6-DOF exact symbolic H, C, G, every parameter symbolic (process start included)", "—", f"{symbolic:.1f} s"),
        ("3-DOF H, C, G, vectorized, one core", f"`lambdify` of the exact symbolic form: {lam_per_s / 1e6:.2f} M poses/s",
         f"{per_s / 1e6:.1f} M poses/s"),
    ]


def linearity_rows() -> list[tuple[str, str, str]]:
    from hapticdesign.analysis.dynamics.device import dynamics_of
    from hapticdesign.analysis.dynamics.model import DynamicsModel
    from hapticdesign.analysis.linearity.bounds import practical_bounds
    from hapticdesign.analysis.linearity.conditions import linear_conditions
    from hapticdesign.analysis.linearity.design_sets import design_set
    from hapticdesign.analysis.linearity.form import linearity_form
    from hapticdesign.devices.registry import preset

    b = _bench("bench_linearity")
    micro = {}
    for name in ("phantom-3dof", "phantom-6dof"):
        device = preset(name)
        micro[name] = 1e6 * b._per_design(linearity_form(DynamicsModel(device.mechanism)), device)
    device = preset("phantom-3dof")
    form = linearity_form(dynamics_of(device))
    start = time.perf_counter()
    design_set(device, form, linear_conditions(device, form), practical_bounds(device), count=100, seed=1)
    seconds = time.perf_counter() - start
    return [("LN per design, batched (20 000 designs)", "—",
             f"{micro['phantom-3dof']:.0f} µs (3 DOF), {micro['phantom-6dof']:.0f} µs (6 DOF)"),
            ("600-design set at six LN levels", "—", f"{seconds:.1f} s")]


def simulation_rows() -> list[tuple[str, str, str]]:
    from hapticdesign.devices.registry import preset
    from hapticdesign.simulation.campaign import CampaignOptions, read_designs, run_campaign, run_case
    from hapticdesign.simulation.config import LoopConfig, Wall
    from hapticdesign.simulation.impedance import type_paths
    from hapticdesign.simulation.loop import simulate
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: the tests' SciPy loop
    from tests.helpers.reference import simulate_adaptive

    b = _bench("bench_simulation")
    device = preset("phantom-3dof").with_params({"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05})
    config = LoopConfig(duration=5.0, wall=Wall(0, 4.0, 0.0, 0.01))
    fast, slow = {}, {}
    for kind in (1, 2):
        paths = type_paths(kind, 3)
        simulate(device, config, paths)
        start = time.perf_counter()
        for _ in range(5):
            simulate(device, config, paths)
        fast[kind] = (time.perf_counter() - start) / 5
        start = time.perf_counter()
        simulate_adaptive(device, config, paths)
        slow[kind] = time.perf_counter() - start
    rows = [("one 5-s virtual-wall simulation of the 3-DOF Phantom, type 1 / type 2",
             f"`solve_ivp` of the same loop, same run: {slow[1]:.1f} / {slow[2]:.1f} s",
             f"{1e3 * fast[1]:.0f} / {1e3 * fast[2]:.0f} ms ({slow[1] / fast[1]:.0f}x / {slow[2] / fast[2]:.0f}x)")]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "designs.csv"
        b._designs(path, 16)
        designs = read_designs(path)
        cpu, same = {}, {}
        for method in ("analytic", "simulation"):
            options = CampaignOptions(method=method)
            run_case("phantom-3dof", designs[0].params, "impedance", 1, options)
            for kind in (1, 2):
                start = time.process_time()
                cpu[method, kind] = [run_case("phantom-3dof", d.params, "impedance", kind, options)["value"]
                                     for d in designs]
                cpu[method, kind] = (time.process_time() - start) / len(designs), cpu[method, kind]
        for kind in (1, 2):
            same[kind] = sum(a == s for a, s in zip(cpu["analytic", kind][1], cpu["simulation", kind][1]))
        rows.append(("impedance case of a campaign, analytic against simulated (16 designs, CPU time of one process)",
                     f"type 1 / type 2: {1e3 * cpu['simulation', 1][0]:.1f} / {1e3 * cpu['simulation', 2][0]:.0f} ms "
                     "simulated",
                     f"{1e3 * cpu['analytic', 1][0]:.1f} / {1e3 * cpu['analytic', 2][0]:.0f} ms analytic, same K_max in "
                     f"{same[1]} / {same[2]} of 16 designs"))
        stamps: list[float] = []
        workers = min(2, os.cpu_count() or 1)
        start = time.perf_counter()
        run_campaign(path, Path(tmp) / "out", workers=workers,
                     progress=lambda done, total: stamps.append(time.perf_counter()))
        rate = (len(stamps) - 1) / (stamps[-1] - stamps[0])
        full = 2400 / rate + (stamps[0] - start)
    rows.append(("rendering campaign, 600 designs x 2 types x 2 criteria (simulated; extrapolated from 16 designs, "
                 f"{len(stamps)} cases, on {workers} processes)", "—", f"{full / 60:.1f} min"))
    return rows


def study_rows() -> list[tuple[str, str, str]]:
    from hapticdesign.studies.phantom import PhantomSettings

    estimate = PhantomSettings.for_scale("quick").estimate_seconds()
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "study", "phantom",
                        "--quick", "--out", tmp, "--quiet"], check=True, capture_output=True, cwd=ROOT)
        if not (Path(tmp) / "report.html").is_file():
            raise RuntimeError("study phantom --quick wrote no report")
        seconds = time.perf_counter() - start
    return [("`study phantom --quick` (90 designs, 360 rendering cases, report; process start included)",
             f"announced {estimate / 60:.1f} min", f"{seconds:.0f} s")]


def loop_rows() -> list[tuple[str, str, str]]:
    b = _bench("bench_loops")
    lines = b._run(b.POSES.format(poses=100_000, examples=b.EXAMPLES), b.ONE_CORE)
    rates = {lines[i]: (float(lines[i + 1]), float(lines[i + 2])) for i in range(0, len(lines), 3)}
    return [("closed-loop H, C, G on one core (CPU time), at closed poses / along a 1 kHz motion with the loop solver",
             f"tree (Phantom): {rates['phantom-3dof'][0] / 1e6:.1f} M poses/s",
             f"five-bar {rates['five-bar'][0]:.2g} / {rates['five-bar'][1]:.2g}, delta {rates['delta'][0]:.2g} / "
             f"{rates['delta'][1]:.2g} poses/s")]


def rcube_rows() -> list[tuple[str, str, str]]:
    from hapticdesign.analysis.rcube.design import final_design
    from hapticdesign.analysis.rcube.metrics import workspace_maps
    from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness
    from hapticdesign.optimization.rcube.chain import Settings, run_chain

    design = final_design()
    position = design.geometry.home + np.array([0.02, -0.03, 0.01])
    cartesian_stiffness(design, position)
    start = time.perf_counter()
    for _ in range(2000):
        cartesian_stiffness(design, position)
    per_call = (time.perf_counter() - start) / 2000
    workspace_maps(design, n=3)
    start = time.perf_counter()
    workspace_maps(design, n=21)
    maps = time.perf_counter() - start
    start, cpu = time.perf_counter(), time.process_time()
    run_chain(seed=1, settings=Settings())
    chain, chain_cpu = time.perf_counter() - start, time.process_time() - cpu
    return [("whole R-CUBE optimization chain (`run_chain(seed=1)`, as `rcube optimize --seed 1`)", "—",
             f"{chain:.0f} s wall, {chain_cpu:.0f} s CPU"),
            ("R-CUBE `K_C` at one pose", "—", f"{1e3 * per_call:.2f} ms"),
            ("workspace maps, 3 planes x 21 x 21, all metrics", "—", f"{maps:.2f} s")]


PARTS = {"dynamics": dynamics_rows, "linearity": linearity_rows, "simulation": simulation_rows, "study": study_rows,
         "loops": loop_rows, "rcube": rcube_rows}


def table(parts=tuple(PARTS)) -> str:
    before = os.getloadavg()[0]
    rows = [row for part in parts for row in PARTS[part]()]
    after = os.getloadavg()[0]
    lines = ["| measurement | baseline | here |", "|---|---|---|"]
    lines += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    lines += ["", f"Machine load (1-min load average, {os.cpu_count()} cores, shared with other sessions): "
              f"{before:.1f} at the start, {after:.1f} at the end of the run."]
    return "\n".join(lines)


def write(text: str, path: Path = README) -> None:
    readme = path.read_text()
    head, rest = readme.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    path.write_text(f"{head}{BEGIN}\n{text}\n{END}{tail}")


def main(argv: list[str]) -> None:
    parts = [a for a in argv if a in PARTS] or list(PARTS)
    text = table(parts)
    print(text, flush=True)
    if "--write" in argv:
        write(text)
