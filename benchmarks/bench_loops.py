"""Closed-loop benchmarks (issue 13), side by side with the tree case (the 3-DOF Phantom).

1. H, C, G in actuated coordinates on one core, poses per second (goal >= 1e5): at closed poses
   (the actuated-coordinate kernel alone) and along a smooth motion sampled at 1 kHz, passive joints
   continued from pose to pose by the loop solver (kernel + solver).
2. LN set-up (model + quadratic form by converged quadrature) for the closed-loop devices (goal < 10 s),
   next to the Phantom's exact-basis set-up.
3. A 5-s rendering simulation of the delta with the compiled closed-loop plant
   (:func:`hapticdesign.analysis.dynamics.closed_loop_plant.closed_loop_terms`) in a plain numba loop:
   classical RK4 at the plant step of :class:`hapticdesign.simulation.config.LoopConfig` (1e-4 s),
   1 kHz sampling, a virtual wall (spring) on joint 1, the model's Coriolis and gravity compensation
   (C, G at the sampled state, its own warm-started workspace; the inertial term fed with the previous
   acceleration makes this undamped-wall loop unstable, so it is off) and the joints' viscous damping;
   real-time factor = 5 s / run time (goal >= 20).

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

POSES = textwrap.dedent(
    """
    import time
    import numpy as np
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
        home = model.solver.home[model.solver.arrays.actuated]
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
        solver = dynamics_of(device).solver
        home = solver.home[solver.arrays.actuated]
        region = Region({{k: (h - {half}, h + {half}) for k, h in enumerate(home)}})
    form = linearity_form(dynamics_of(device), region)
    print(time.process_time() - t0, form.accuracy, float(form.ln(device.standard_parameters())))
    """
)

SIMULATION = textwrap.dedent(
    """
    import time
    import numpy as np
    from numba import njit
    from hapticdesign.analysis.dynamics.closed_loop_plant import OK, ClosedLoopPlant, closed_loop_terms
    from hapticdesign.analysis.dynamics.device import dynamics_of
    from hapticdesign.devices.device_file import load_device_file
    from hapticdesign.simulation.config import LoopConfig

    @njit
    def accelerations(q, qd, u, damping, structure, ws, h, cqd, g, out):
        status = closed_loop_terms(q, qd, structure, ws, h, cqd, g)
        out[:] = np.linalg.solve(h, u - cqd - g - damping * qd)
        return status

    @njit
    def run(q0, structure, plant_ws, model_ws, damping, step, sub, n_steps, wall_k, wall_eq):
        n = q0.shape[0]
        q, qd, u = q0.copy(), np.zeros(n), np.zeros(n)
        h, cqd, g = np.zeros((n, n)), np.zeros(n), np.zeros(n)
        a1, a2, a3, a4 = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
        for it in range(n_steps):
            if it % sub == 0:
                status = closed_loop_terms(q, qd, structure, model_ws, h, cqd, g)
                if status != OK:
                    return it, status
                u[:] = cqd + g
                u[0] -= wall_k * (q[0] - wall_eq)
            s1 = accelerations(q, qd, u, damping, structure, plant_ws, h, cqd, g, a1)
            s2 = accelerations(q + 0.5 * step * qd, qd + 0.5 * step * a1, u, damping, structure, plant_ws, h, cqd, g, a2)
            s3 = accelerations(q + 0.5 * step * (qd + 0.5 * step * a1), qd + 0.5 * step * a2, u, damping, structure,
                               plant_ws, h, cqd, g, a3)
            s4 = accelerations(q + step * (qd + 0.5 * step * a2), qd + step * a3, u, damping, structure, plant_ws,
                               h, cqd, g, a4)
            if max(s1, s2, s3, s4) != OK:
                return it, max(s1, s2, s3, s4)
            q += step / 6.0 * (qd + 2.0 * (qd + 0.5 * step * a1) + 2.0 * (qd + 0.5 * step * a2) + qd + step * a3)
            qd += step / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        return n_steps, OK

    device = load_device_file("{examples}/delta.yaml")
    model, pi = dynamics_of(device), device.standard_parameters()
    config = LoopConfig()
    q0 = model.solver.home[model.solver.arrays.actuated].copy()
    damping = np.array(device.damping, dtype=float)
    sub, n_steps = config.steps_per_sample(), int(round(config.duration / config.step))

    def simulate(steps):
        plant, sensor_model = ClosedLoopPlant(model, pi, q0), ClosedLoopPlant(model, pi, q0)
        return run(q0, plant.structure, plant.workspace, sensor_model.workspace, damping, config.step, sub, steps,
                   config.wall.stiffness, q0[0] + config.wall.equilibrium)

    simulate(sub)
    t0 = time.process_time()
    done, status = simulate(n_steps)
    seconds = time.process_time() - t0
    print(config.duration, seconds, done, n_steps, status)
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
    duration, seconds, done, n_steps, status = (float(v) for v in _run(SIMULATION.format(examples=EXAMPLES), ONE_CORE))
    print(f"delta         simulation of {duration:g} s (RK4 at 1e-4 s, 1 kHz wall on joint 1, closed-loop plant): "
          f"{seconds:.2f} s, {duration / seconds:.1f} x real time (goal >= 20); {int(done)} of {int(n_steps)} steps, "
          f"status {int(status)}")


if __name__ == "__main__":
    main()
