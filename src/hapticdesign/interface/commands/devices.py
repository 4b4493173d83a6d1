"""Commands ``ik``, ``spec`` and ``export``: a device's inverse kinematics, its spec sheet, and its model for
other simulators (:mod:`hapticdesign.analysis.inverse_kinematics`, :mod:`hapticdesign.devices.spec`,
:mod:`hapticdesign.devices.export`)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from hapticdesign.devices.loading import resolve_device
from hapticdesign.interface.common import parse_vector, print_json, user_errors
from hapticdesign.interface.options import DEVICE, JSON_OUT, PARAMS, PRESET, QUIET, STRICT


def ik(
    position: str = typer.Option(..., "--position", help="Handle position x,y,z in the device's base frame (m)."),
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
) -> None:
    """Inverse kinematics: the actuated (and passive) joint coordinates that put the handle at a position, on
    the branch of the home pose (continued from home along the straight segment)."""
    from hapticdesign.analysis.inverse_kinematics import handle_pose

    with user_errors(strict=strict, quiet=quiet):
        dev = resolve_device(preset, device, params, strict=strict)
        target = parse_vector(position, 3, "position")
        pose = handle_pose(dev, target)
        result = {"device": dev.name, "position": target, "q": pose.q, "passive": pose.passive,
                  "coordinates": list(dev.mechanism.actuated_coordinates),
                  "passive_coordinates": [dev.mechanism.coordinates[k] for k in
                                          (dev.mechanism.loops.passive if dev.mechanism.loops else ())],
                  "units": {"position": "m", "q": "rad or m", "passive": "rad or m"}}
        if json_out:
            print_json(result)
            return
        typer.echo(f"{dev.name}: handle at ({', '.join(f'{v:.6g}' for v in target)}) m")
        for name, value in zip(result["coordinates"], pose.q):
            typer.echo(f"  {name} = {value:.9g}")
        for name, value in zip(result["passive_coordinates"], pose.passive):
            typer.echo(f"  {name} = {value:.9g} (passive)")


def register(app: typer.Typer) -> None:
    app.command("ik")(ik)
