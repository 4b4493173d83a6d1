"""Regenerates the closed-loop wall figures of docs/simulation.md ("Closed-loop devices").

For the five-bar and the delta of examples/devices: the joint walls' k_max (type 1, seed criteria, full
compensation) and the Cartesian walls along the direction in which the free joint moves the handle (rest
0.01 J_n,w m from the start, criteria scaled with the step), each beside the exact growth boundary of the
loop linearized where the wall holds the free joint (spectral radius 1) and the 1-DOF closed form b^2 / (H_ww J_n,w^2); and the joint
damping that a 1000-N/m Cartesian wall needs by that closed form, ``b = J_n,w sqrt(1000 H_ww)``.

Run: ``.venv/bin/python docs/scripts/closed_loop_walls.py`` (a few minutes: the simulated searches).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import hapticdesign as hd
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.simulation.analytic import AnalyticProblem
from hapticdesign.simulation.config import LoopConfig, Wall, normal_jacobian, rest_pose

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
WALLS = {"five-bar": (1, 0.01), "delta": (0, 0.002)}
"""Device: (joint of the joint wall, its grid resolution in N m/rad)."""
CARTESIAN_JOINT = {"five-bar": 1, "delta": 2}


def growth_boundary(problem: AnalyticProblem, high: float) -> float:
    """The stiffness at which the linearized loop starts to grow (bisection on the spectral radius)."""
    lo, hi = 0.0, high
    while not problem.grows(hi):
        lo, hi = hi, 2 * hi
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if problem.grows(mid) else (mid, hi)
    return lo


def main() -> None:
    print("| device | wall | k_max simulated | k_max analytic | growth boundary | b^2 / (H_ww J^2) |")
    print("|---|---|---|---|---|---|")
    needs = []
    for name in ("five-bar", "delta"):
        device = load_device_file(EXAMPLES / f"{name}.yaml")
        home = rest_pose(device)
        joint, resolution = WALLS[name]
        found = [hd.impedance_range(device, 1, method=m, wall_joint=joint, resolution=resolution, k_limit=1)
                 for m in ("fast", "analytic")]
        boundary = growth_boundary(AnalyticProblem(device, 1, joint), 1.0)
        closed = device.damping[joint] ** 2 / hd.mass_matrix(device, home)[joint, joint]
        print(f"| {name} | joint {joint + 1} [N m/rad] | {found[0].k_max:.4g} | {found[1].k_max:.4g} | "
              f"{boundary:.4g} | {closed:.4g} |")
        w = CARTESIAN_JOINT[name]
        v = configuration_of(device).jacobian(home)[:3, w]
        n = v / np.linalg.norm(v)
        j_nw = float(normal_jacobian(device, Wall(w, 1.0, equilibrium=0.0, direction=tuple(n)), home)[w])
        h_ww = float(hd.mass_matrix(device, home)[w, w])
        limit = device.damping[w] ** 2 / h_ww / j_nw ** 2
        found = [hd.impedance_range(device, 1, method=m, wall_joint=w, resolution=limit / 10, k_limit=20,
                                    equilibrium=0.01 * j_nw, wall_direction=n) for m in ("fast", "analytic")]
        config = LoopConfig(wall=Wall(direction=tuple(n)))
        boundary = growth_boundary(AnalyticProblem(device, 1, w, 0.01 * j_nw, config=config), limit)
        print(f"| {name} | along n, joint {w + 1} free [N/m] | {found[0].k_max:.4g} | {found[1].k_max:.4g} | "
              f"{boundary:.4g} | {limit:.4g} |")
        needs.append((name, w, j_nw, h_ww, device.damping[w], j_nw * np.sqrt(1000.0 * h_ww)))
    print()
    print("| device | free joint | J_n,w [m/rad] | H_ww [kg m^2] | joint damping b [N m s/rad] | b for 1000 N/m |")
    print("|---|---|---|---|---|---|")
    for name, w, j_nw, h_ww, b, need in needs:
        print(f"| {name} | {w + 1} | {abs(j_nw):.4g} | {h_ww:.4g} | {b:.4g} | {need:.3g} |")


if __name__ == "__main__":
    main()
