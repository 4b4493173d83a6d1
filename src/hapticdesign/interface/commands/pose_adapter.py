"""Where a device is at a pose, for ``dynamics``, ``metrics`` and ``show``: the handle's position and, for a
closed-loop device, the assembly branch its file selects. Imported when a command runs.
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.interface.round_off import without_round_off


def handle(device, q: np.ndarray) -> dict | None:
    """The end-effector frame's origin in the base frame [m] at actuated coordinates ``q`` (forward kinematics,
    seed 000 eq. 2.20-2.26; passive joints solved on the assembly branch; round-off below 1e-12 of the largest
    coordinate is 0); None without an end-effector frame."""
    mech = device.mechanism
    if mech.end_effector is None:
        return None
    pose = configuration_of(device).pose(np.asarray(q, dtype=float))
    return {"frame": mech.end_effector, "position": without_round_off(pose[:3, 3])}


def assembly_branch(device) -> dict | None:
    """The branch a closed-loop device's ``assembly`` selects: the sign of ``det Phi_p`` (the constraint
    Jacobian over the passive joints) at home and the passive joints' values there, beside the file's guess;
    None for a tree."""
    mech = device.mechanism
    if mech.loops.empty:
        return None
    solver = configuration_of(device).solver
    passive = mech.loops.passive
    names = [mech.coordinates[k] for k in passive]
    return {"det_phi_p_sign": int(np.sign(solver.branch)),
            "passive_at_home": {n: float(solver.home[k]) for n, k in zip(names, passive)},
            "assembly_guess": dict(zip(names, map(float, mech.loops.assembly)))}


def branch_line(branch: dict) -> str:
    """One line of text naming the assembly branch."""
    sign = "> 0" if branch["det_phi_p_sign"] > 0 else "< 0"
    passive = ", ".join(f"{n} = {v:.6g}" for n, v in branch["passive_at_home"].items())
    guess = ", ".join(f"{n} = {v:g}" for n, v in branch["assembly_guess"].items())
    return f"assembly branch: det Phi_p {sign} at home, passive joints at home {passive} (file's assembly: {guess})"


def handle_line(found: dict) -> str:
    """One line of text with the handle's position."""
    x, y, z = found["position"]
    return f"handle ({found['frame']}) at x = {x:.6g} m, y = {y:.6g} m, z = {z:.6g} m"
