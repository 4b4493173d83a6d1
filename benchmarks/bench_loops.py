"""Closed-loop benchmarks (issue 13), side by side with the tree case (the 3-DOF Phantom).

1. H, C, G in actuated coordinates on one core, poses per second (goal >= 1e5): at closed poses
   (``entries_at``, the actuated-coordinate kernel alone) and along a smooth motion sampled at 1 kHz
   (``entries``: one kernel that continues the passive joints from pose to pose and evaluates each pose).
2. LN set-up (model + quadratic form by converged quadrature) for the closed-loop devices (goal < 10 s),
   next to the Phantom's exact-basis set-up.
3. A 5-s rendering simulation of the delta through :func:`hapticdesign.simulation.loop.simulate` (the
   numba loop with the compiled closed-loop plant and compensator,
   :func:`hapticdesign.analysis.dynamics.closed_loop_plant.closed_loop_terms`): type 1 (joints 2 and 3
   held at home), 1 kHz sampling, a stable virtual wall on joint 1, full model compensation, RK4 with
   error-controlled steps (the default for a closed-loop device); real-time factor = 5 s / run time
   (goal >= 20). The same run at every 1e-4-s plant step (``--step-control fixed``, the seed's grid)
   beside it, with the largest differences in q and in the peak excursion.

Times are CPU time of the benchmark process (``time.process_time``), so that a shared machine does not
count other processes' time against one core.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

ONE_CORE = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}
EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "devices"
WALL_K = 0.01
"""N m/rad: the delta's maximum stable impedance on one joint (type 1, seed criteria, ``impedance-range
--resolution 0.002``), so that the benchmarked run is a stable wall held for the whole 5 s."""

POSES = textwrap.dedent(
    """
    import time
    import numpy as np
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.analysis.dynamics.device import dynamics_of
    from hapticdesign.devices.device_file import load_device_file
    from hapticdesign.devices.registry import preset

    def best(f, repeat=3):
        out = 1e9
        for _ in range(repeat):
            t = time.process_time(); f(); out = min(out, time.process_time() - t)
        return out

    n = {poses}
    tree = preset("phantom-3dof")
    qs = np.random.default_rng(0).uniform(-np.pi, np.pi, (n, 3))
    tree_model = dynamics_of(tree)
    tree_model.entries(qs[:10], tree.standard_parameters())
    print("phantom-3dof", n / best(lambda: tree_model.entries(qs, tree.standard_parameters())), "nan")
    for name, amplitude in (("five-bar", 0.3), ("delta", 0.2)):
        device = load_device_file("{examples}/" + name + ".yaml")
        model, pi = dynamics_of(device), device.standard_parameters()
        home = configuration_of(device).home
        t = np.arange(n)[:, None] * 1e-3  # a 1 kHz sampled motion, 2-3 Hz per joint
        path = home + amplitude * np.sin(2 * np.pi * (2.0 + np.arange(len(home))[None, :] * 0.5) * t)
        model.entries(path[:10], pi)
        q_full = model.full_coordinates(path)
        kernel = n / best(lambda: model.entries_at(q_full, pi))
        solved = n / best(lambda: model.entries(path, pi))
        print(name, kernel, solved)
    """
)

SETUP = textwrap.dedent(
    """
    import time
    t0 = time.process_time()
    import numpy as np
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.analysis.dynamics.device import dynamics_of
    from hapticdesign.analysis.linearity.form import linearity_form
    from hapticdesign.analysis.linearity.region import Region
    from hapticdesign.devices.device_file import load_device_file
    from hapticdesign.devices.registry import preset
    name = "{name}"
    if name == "phantom-3dof":
        device = preset(name)
        region = None
    else:
        device = load_device_file("{examples}/" + name + ".yaml")
        home = configuration_of(device).home
        region = Region({{k: (h - {half}, h + {half}) for k, h in enumerate(home)}})
    form = linearity_form(dynamics_of(device), region)
    print(time.process_time() - t0, form.accuracy, float(form.ln(device.standard_parameters())))
    """
)

SIMULATION = textwrap.dedent(
    """
    import time
    import numpy as np
    from hapticdesign.devices.device_file import load_device_file
    from hapticdesign.simulation.config import LoopConfig, Wall, rest_pose
    from hapticdesign.simulation.criteria import type_paths
    from hapticdesign.simulation.loop import simulate

    device = load_device_file("{examples}/delta.yaml")
    home = rest_pose(device)
    paths = type_paths(1, device.n_dof, 0, home)
    traces = []
    for control in ("auto", "fixed"):
        config = LoopConfig(duration=5.0, step_control=control, wall=Wall(0, {stiffness}, 0.0, home[0] + 0.01))
        simulate(device, LoopConfig(duration=0.01, step_control=control, wall=config.wall), paths)  # compile / load
        best = 1e9
        for _ in range(3):
            t0 = time.process_time()
            trace = simulate(device, config, paths)
            best = min(best, time.process_time() - t0)
        traces.append(trace)
        print(best, trace.steps, trace.status)
    print(np.abs(traces[0].q - traces[1].q).max(), abs(traces[0].peak - traces[1].peak))
    """
)


def _run(code: str, env: dict | None = None) -> list[str]:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env={**os.environ, **(env or {})},
                         check=True)
    return out.stdout.split()


def main() -> None:
    lines = _run(POSES.format(poses=100_000, examples=EXAMPLES), ONE_CORE)
    for i in range(0, len(lines), 3):
        name, kernel, solved = lines[i], float(lines[i + 1]), float(lines[i + 2])
        if name == "phantom-3dof":
            print(f"{name:13s} (tree, exact basis) H, C, G on one core: {kernel:,.0f} poses/s")
        else:
            print(f"{name:13s} (closed loops) H, C, G on one core: {kernel:,.0f} poses/s at closed poses, "
                  f"{solved:,.0f} poses/s with the loop solver along a 1 kHz motion (goal >= 1e5)")
    for name, half in (("phantom-3dof", 0.0), ("five-bar", 0.3), ("delta", 0.25)):
        seconds, accuracy, ln = (float(v) for v in _run(SETUP.format(name=name, examples=EXAMPLES, half=half), ONE_CORE))
        region = "torus, exact basis" if name == "phantom-3dof" else f"home +- {half} rad, quadrature to {accuracy:.0e}"
        print(f"{name:13s} LN set-up (process, model and form; {region}): {seconds:.2f} s (goal < 10 s), LN = {ln:.4g}")
    out = [float(v) for v in _run(SIMULATION.format(examples=EXAMPLES, stiffness=WALL_K), ONE_CORE)]
    (seconds, steps, status), (fixed_seconds, fixed_steps, _), (difference, peak) = out[0:3], out[3:6], out[6:8]
    print(f"delta         simulation of 5 s through simulate (type 1, 1 kHz, wall K = {WALL_K:g} N m/rad on joint 1, "
          f"full compensation), RK4 with error-controlled steps (the default for closed loops): {seconds:.3f} s, "
          f"{5 / seconds:.1f} x real time (goal >= 20), {int(steps)} steps, status {int(status)}; RK4 at every "
          f"1e-4-s plant step (--step-control fixed): {fixed_seconds:.2f} s, {5 / fixed_seconds:.1f} x, "
          f"{int(fixed_steps)} steps; max |q difference| {difference:.1e} rad, peak difference {peak:.1e} rad")

if __name__ == "__main__":
    main()
