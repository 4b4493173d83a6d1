"""Command ``stiffness``: the Cartesian stiffness of any device with elastic links (seed 001 §5.2).

The device file's ``links`` (section and material) and ``joint_stiffness`` feed the virtual joint
method of :mod:`hapticdesign.analysis.stiffness.device`: ``K_C`` at the end effector at one pose,
and the deflection under a wrench when one is given.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np
import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import note, parse_vector, print_json, user_errors
from hapticdesign.interface.options import (
    DEVICE,
    JSON_OUT,
    PARAMS,
    PRESET,
    QUIET,
    STRICT,
)

UNITS = {"K_C": "rows and columns (x, y, z, rx, ry, rz): N/m, N/rad, N m/rad", "deflection": "m, m, m, rad, rad, rad",
         "wrench": "N, N, N, N m, N m, N m", "q": "rad or m"}
TRANSLATIONAL = "rows and columns (x, y, z): N/m, rotations held"


def _row(values) -> str:
    return " ".join(f"{v:12.5g}" for v in values)


def stiffness(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    q: Optional[str] = typer.Option(None, "--q", help="Actuated joint coordinates, comma-separated (rad or m); "
                                    "default the file's home pose (zeros without loops)."),
    wrench: Optional[str] = typer.Option(None, "--wrench", help="Fx,Fy,Fz[,Mx,My,Mz] at the end effector (N, N m): "
                                         "also print the deflection."),
    frame: Optional[str] = typer.Option(None, "--frame", help="Frame whose stiffness to compute (default: the end "
                                        "effector)."),
    translational: bool = typer.Option(False, "--translational", help="Print the translational 3 x 3 block of K_C "
                                       "(N/m; rotations held), as the R-CUBE's K_CA."),
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
) -> None:
    """Cartesian stiffness K_C of a device's end effector by the virtual joint method (seed 001 eq. 5.98-5.123):
    elastic links and joint springs from the device file, passive joints free, loops closed. Entries below 1e-12
    of the largest are round-off and shown as 0, as in `rcube stiffness`."""
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.analysis.stiffness.device import cartesian_stiffness, deflection
    from hapticdesign.interface.round_off import RELATIVE, without_round_off

    with user_errors(quiet=quiet):
        from hapticdesign.devices.loading import resolve_device

        dev = resolve_device(preset, device, params, strict=strict)
        qv = parse_vector(q, dev.n_dof, "q") if q is not None else configuration_of(dev).home
        for message in dev.limit_warnings(qv):
            note(f"warning: {message}", quiet)
        if frame is not None and frame not in dev.mechanism.compiled.frame_node:
            raise UserError(f"--frame: unknown frame {frame!r} (frames: {', '.join(f.name for f in dev.mechanism.frames)})")
        K = without_round_off(cartesian_stiffness(dev, qv, frame))
        result = {"device": dev.name, "frame": frame or dev.mechanism.end_effector, "q": qv,
                  "K_C": K[:3, :3] if translational else K}
        if wrench is not None:
            w = parse_vector(wrench, None, "wrench", most=6)
            if len(w) not in (3, 6):
                raise UserError(f"--wrench: give Fx,Fy,Fz or Fx,Fy,Fz,Mx,My,Mz, got {len(w)} values")
            w = np.concatenate([w, np.zeros(6 - len(w))])
            result["wrench"], result["deflection"] = w, deflection(K, w)
        result["units"] = {**UNITS, "K_C": TRANSLATIONAL} if translational else dict(UNITS)
        result["units"]["round_off"] = f"entries of K_C below {RELATIVE:g} of its largest are shown as 0"
        if json_out:
            print_json(result)
            return
        typer.echo(f"{dev.name}: K_C of frame {result['frame']} at q = {', '.join(f'{v:.6g}' for v in qv)} "
                   f"[{result['units']['K_C']}]")
        for row in result["K_C"]:
            typer.echo("  " + _row(row))
        if "deflection" in result:
            typer.echo(f"deflection [{UNITS['deflection']}]: " + ", ".join(f"{v:.6g}" for v in result["deflection"]))


def register(app: typer.Typer) -> None:
    app.command("stiffness")(stiffness)
