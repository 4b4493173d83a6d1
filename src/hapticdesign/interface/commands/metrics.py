"""Command ``metrics``: kinematic and dynamic performance metrics of any device at one pose.

The metrics of seed 001 chapter 4 are general: they are indices of the one registry
(:mod:`hapticdesign.analysis.metrics.indices`) on the task Jacobian of the handle (translational rows for devices of up
to 3 joints, all six rows for 6 joints) and the mass matrix H over the actuated coordinates. ``--index`` adds any
index of the registry by name (built-in, a package's through its entry point, or your own of an ``--indices`` file).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Optional

import numpy as np
import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import note, parse_vector, print_json, user_errors
from hapticdesign.interface.options import DEVICE, FORCE, FORCE_HINT, JSON_OUT, PARAMS, PRESET, QUIET, STRICT
from hapticdesign.workload import allow_large

if TYPE_CHECKING:
    from hapticdesign.analysis.metrics.indices import Registry
    from hapticdesign.model.device import Device

SINGULAR_CONDITION = 1e10


def _metric_table() -> tuple[tuple, tuple]:
    """The metrics of seed 001 ch. 4 the command gives, as indices of the one registry on the task Jacobian (key,
    index, options), and the order of the output's keys (imported when the command runs, not with the CLI's table)."""
    from hapticdesign.analysis.metrics import names

    indices = ((names.CONDITION_NUMBER, "condition", {"jacobian": "task"}),
               (names.MANIPULABILITY, "manipulability", {"jacobian": "task"}),
               ("I_m", "I_m", {}), ("I_d", "I_d", {}), ("I_f", "I_f", {}), ("I_e", "I_e", {}),
               ("acceleration_radius", "acceleration_radius", {}))
    order = (names.MANIPULABILITY, names.CONDITION_NUMBER, "velocity_ellipsoid_radii", "cartesian_inertia",
             names.INERTIA_VOLUME, names.DYNAMIC_MANIPULABILITY, names.INERTIA_FROBENIUS, names.INERTIA_UNIFORMITY,
             names.ACCELERATION_RADIUS)
    return indices, order


def device_metrics(device: Device, q: np.ndarray, extra: Sequence[str] = (), registry: Registry | None = None) -> dict:
    """Kinematic (eq. 4.24-4.38) and dynamic (eq. 4.90-4.99) metrics at pose ``q``, keyed as in
    :mod:`hapticdesign.analysis.metrics.names`: the indices of the one registry on the task Jacobian
    (:attr:`~hapticdesign.analysis.metrics.indices.states.HandleStates.task`: translational rows for devices of up
    to 3 joints, all six rows for 6 joints), and under ``indices`` the indices ``extra`` of ``registry`` (default:
    the one registry) by name, with the ``options`` they ran with and, for those that include the drive's compliance
    (``kmax``), which (``compliance``, :func:`~hapticdesign.analysis.metrics.indices.drive_compliance`)."""
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.analysis.metrics.indices import INDICES, drive_compliance, evaluate_at, options_used, requests_of
    from hapticdesign.analysis.metrics import kinematic, names
    from hapticdesign.analysis.metrics.indices.states import HandleStates

    registry = INDICES if registry is None else registry
    extra = requests_of(extra, registry)
    pose = HandleStates(device, configuration_of(device).full(q)[None])
    values = {}
    metric_indices, order = _metric_table()
    for key, name, options in metric_indices:
        values[key] = float(registry[name].values(pose, options)[0])
        if key == names.CONDITION_NUMBER and not values[key] <= SINGULAR_CONDITION:
            raise UserError(f"singular configuration at q = {np.round(q, 6).tolist()}: the Jacobian loses rank")
    J, M_C = pose.task[0], pose.task_inertia[0]
    values.update(velocity_ellipsoid_radii=kinematic.velocity_ellipsoid(J)[0], cartesian_inertia=M_C)
    out = {"device": device.name, "q": q, "jacobian": J, **{key: values[key] for key in order}}
    if extra:
        found = evaluate_at(device, pose.full, extra, registry=registry)
        out["indices"] = {key: float(value[0]) for key, value in found.values.items()}
        used = options_used(extra, registry)
        if used:
            out["options"] = used
        compliance = drive_compliance(device, [r.index for r in extra], registry)
        if compliance:
            out["compliance"] = compliance
    return out


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
    index: str = typer.Option("", "--index", help="Comma-separated design indices to add at the pose "
                              "(docs/indices.md): built-in, a package's through its entry point, or one of --indices."),
    indices: Optional[Path] = typer.Option(None, "--indices", help="A Python file of your own design indices "
                                           "(decorated with @hapticdesign.index) that --index may name. Its code "
                                           "RUNS, as 'python FILE' would."),
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Kinematic and dynamic metrics of any device at one pose (seed 001 eq. 4.24-4.38, 4.90-4.99)."""
    from hapticdesign.analysis.metrics.indices import INDICES, compliance_line, options_line
    from hapticdesign.devices.loading import resolve_device
    from hapticdesign.interface.commands.optimize_adapter import index_module
    from hapticdesign.interface.commands.pose_adapter import handle, handle_line

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        dev = resolve_device(preset, device, params, strict=strict)
        qv = parse_vector(q, dev.n_dof, "q")
        for message in dev.limit_warnings(qv):
            note(f"warning: {message}", quiet)
        registry = INDICES.with_indices(index_module(indices)) if indices is not None else INDICES
        result = device_metrics(dev, qv, [name.strip() for name in index.split(",") if name.strip()], registry)
        found = handle(dev, qv)
        result["units"] = metric_units(dev)
        if "indices" in result:
            result["units"]["indices"] = {key: registry[key].unit for key in result["indices"]}
        if json_out:
            print_json({**result, **({"handle": found} if found is not None else {})})
            return
        del result["units"]
        for key, value in result.items():
            if key == "indices":
                for name, number in value.items():
                    unit = registry[name].unit
                    typer.echo(f"{name}: {number:.6g}" + ("" if unit == "1" else f" {unit}"))
            elif key == "options":
                for name, used in value.items():
                    typer.echo(f"{name} options: {options_line(used)}")
            elif key == "compliance":
                typer.echo(compliance_line(value))
            elif key in ("jacobian", "cartesian_inertia"):
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
