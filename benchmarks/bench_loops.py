"""Closed-loop benchmarks (issue 13), side by side with the tree case (the 3-DOF Phantom).

1. H, C, G in actuated coordinates on one core, poses per second (goal >= 1e5): at closed poses
   (the actuated-coordinate kernel alone) and along a smooth motion sampled at 1 kHz, passive joints
   continued from pose to pose by the loop solver (kernel + solver).
2. LN set-up (model + quadratic form by converged quadrature) for the closed-loop devices (goal < 10 s),
   next to the Phantom's exact-basis set-up.
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
            t = time.perf_counter(); f(); out = min(out, time.perf_counter() - t)
        return out

    n = {poses}
    tree = preset("phantom-3dof")
    qs = np.random.default_rng(0).uniform(-np.pi, np.pi, (n, 3))
    dynamics_of(tree).entries(qs[:10], tree.standard_parameters())
    print("phantom-3dof", n / best(lambda: dynamics_of(tree).entries(qs, tree.standard_parameters())), "nan")
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
    t0 = time.perf_counter()
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
        home = dynamics_of(device).solver.home[dynamics_of(device).solver.arrays.actuated]
        region = Region({{k: (h - {half}, h + {half}) for k, h in enumerate(home)}})
    form = linearity_form(dynamics_of(device), region)
    print(time.perf_counter() - t0, form.accuracy, float(form.ln(device.standard_parameters())))
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


if __name__ == "__main__":
    main()
