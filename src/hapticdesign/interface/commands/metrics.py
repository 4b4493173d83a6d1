"""Command ``metrics``: kinematic and dynamic performance metrics of any device at one pose.

The metrics of seed 001 chapter 4 are general: here they take the end-effector Jacobian of the
kinematic core (translational rows for devices of up to 3 joints, all six rows for 6 joints)
and the joint-space mass matrix H of the equations of motion.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Optional

import numpy as np
import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import note, parse_vector, print_json, user_errors
from hapticdesign.interface.options import DEVICE, FORCE, FORCE_HINT, JSON_OUT, PARAMS, PRESET, QUIET, STRICT
from hapticdesign.workload import allow_large

if TYPE_CHECKING:
    from hapticdesign.model.device import Device

SINGULAR_CONDITION = 1e10


def task_jacobian(device: Device, q: np.ndarray) -> np.ndarray:
    """End-effector Jacobian with as many task rows as joints.

    3 joints: the translational rows in base coordinates; 6 joints: all six rows; 1-2 joints
    (planar devices): the translational rows projected on the plane (or line) of motion, i.e. on
    the leading left singular vectors, which leaves every metric unchanged by the choice of axes.
    """
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.analysis.metrics.kinematic import handle_range_basis

    full = configuration_of(device).jacobian(q)
    n = device.n_dof
    if n == 3:
        return full[:3]
    if n == 6:
        return full
    if n < 3:
        return handle_range_basis(full[None, :3])[2][0]
    raise UserError(f"metrics need 1-3 or 6 joints (a square task Jacobian); {device.name} has {n}")


def device_metrics(device: Device, q: np.ndarray) -> dict:
    """Kinematic (eq. 4.24-4.38) and dynamic (eq. 4.90-4.99) metrics at pose ``q``, keyed as in
    :mod:`hapticdesign.analysis.metrics.names`."""
    from hapticdesign.analysis.dynamics.cartesian import cartesian_inertia
    from hapticdesign.analysis.dynamics.device import mass_matrix
    from hapticdesign.analysis.metrics import dynamic, kinematic, names

    J = task_jacobian(device, q)
    cond = float(kinematic.condition_number(J))
    if not np.isfinite(cond) or cond > SINGULAR_CONDITION:
        raise UserError(f"singular configuration at q = {np.round(q, 6).tolist()}: the Jacobian loses rank")
    H = mass_matrix(device, q)
    M_C = cartesian_inertia(H, J)
    radii, _ = kinematic.velocity_ellipsoid(J)
    return {
        "device": device.name,
        "q": q,
        "jacobian": J,
        names.MANIPULABILITY: kinematic.manipulability(J),
        names.CONDITION_NUMBER: cond,
        "velocity_ellipsoid_radii": radii,
        "cartesian_inertia": M_C,
        names.INERTIA_VOLUME: dynamic.inertia_volume(M_C),
        names.DYNAMIC_MANIPULABILITY: dynamic.dynamic_manipulability(H, J),
        names.INERTIA_FROBENIUS: dynamic.inertia_frobenius(M_C),
        names.INERTIA_UNIFORMITY: dynamic.inertia_uniformity(M_C),
        names.ACCELERATION_RADIUS: dynamic.acceleration_radius(H, J),
    }


def metric_units(device: Device) -> dict:
    """Units of the ``metrics`` output: the R-CUBE's of seed 001 (revolute joints, translational task rows:
    :data:`hapticdesign.analysis.metrics.names.METRICS`) with the power of the determinants set to the number of
    joints; a prismatic joint has m in place of rad."""
    from hapticdesign.analysis.metrics.names import METRICS
    from hapticdesign.interface.common import joint_units

    keys = ("manipulability", "condition_number", "I_m", "I_d", "I_f", "I_e", "acceleration_radius")
    return {"q": [u["position"] for u in joint_units(device)], "handle": "m",
            "jacobian": "m/rad (task rows per joint; for 6 joints rows 4-6 in rad/rad)",
            "velocity_ellipsoid_radii": "m/s per rad/s", "cartesian_inertia": "kg",
            **{key: METRICS[key].unit.replace("^3", f"^{device.n_dof}") for key in keys},
            "note": "units for revolute joints; a prismatic joint has m in place of rad"}


def metrics(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    q: str = typer.Option(..., help="Joint coordinates, comma-separated (rad or m)."),
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Kinematic and dynamic metrics of any device at one pose (seed 001 eq. 4.24-4.38, 4.90-4.99)."""
    from hapticdesign.devices.loading import resolve_device
    from hapticdesign.interface.commands.pose_adapter import handle, handle_line

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        dev = resolve_device(preset, device, params, strict=strict)
        qv = parse_vector(q, dev.n_dof, "q")
        for message in dev.limit_warnings(qv):
            note(f"warning: {message}", quiet)
        result = device_metrics(dev, qv)
        found = handle(dev, qv)
        result["units"] = metric_units(dev)
        if json_out:
            print_json({**result, **({"handle": found} if found is not None else {})})
            return
        del result["units"]
        for key, value in result.items():
            if key in ("jacobian", "cartesian_inertia"):
                typer.echo(f"{key}:")
                for row in value:
                    typer.echo("  " + " ".join(f"{v: .6e}" for v in row))
            elif isinstance(value, np.ndarray) and value.ndim:
                typer.echo(f"{key}: " + " ".join(f"{v:.6g}" for v in value))
            else:
                typer.echo(f"{key}: {value if isinstance(value, str) else f'{float(value):.6g}'}")
        if found is not None:
            typer.echo(handle_line(found))


def register(app: typer.Typer) -> None:
    app.command("metrics")(metrics)
