"""Commands ``ik``, ``spec`` and ``export``: a device's inverse kinematics, its spec sheet, and its model for
other simulators (:func:`hapticdesign.analysis.configuration.handle_pose`, :mod:`hapticdesign.studies.spec`,
:mod:`hapticdesign.devices.export`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Optional

import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import note, parse_vector, print_json, progress_bar, user_errors
from hapticdesign.interface.options import DEVICE, JSON_OUT, PARAMS, PRESET, QUIET, STRICT

if TYPE_CHECKING:  # for the hints only: the commands import no engine until they run
    from hapticdesign.model.device import Device
    from hapticdesign.studies.spec import Report


def ik(
    position: str = typer.Option(..., "--position", help="Handle position x,y,z in the device's base frame (m)."),
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
) -> None:
    """Inverse kinematics by Newton on the geometric Jacobian (seed 000 eq. 2.20-2.26): the actuated (and
    passive) joint coordinates that put the handle at a position, on the branch of the home pose (continued from
    home along the straight segment)."""
    from hapticdesign.analysis.configuration import handle_pose
    from hapticdesign.model.loops import handle_position

    with user_errors(strict=strict, quiet=quiet):
        from hapticdesign.devices.loading import resolve_device

        dev = resolve_device(preset, device, params, strict=strict)
        target = parse_vector(position, 3, "position")
        handle_position(target, "--position")
        pose = handle_pose(dev, target)
        result = {"device": dev.name, "position": target, "q": pose.q, "passive": pose.passive,
                  "coordinates": list(dev.mechanism.actuated_coordinates),
                  "passive_coordinates": [dev.mechanism.coordinates[k] for k in dev.mechanism.loops.passive],
                  "units": {"position": "m", "q": "rad or m", "passive": "rad or m"}}
        if json_out:
            print_json(result)
            return
        typer.echo(f"{dev.name}: handle at ({', '.join(f'{v:.6g}' for v in target)}) m")
        for name, value in zip(result["coordinates"], pose.q):
            typer.echo(f"  {name} = {_coordinate_text(dev, name, value)}")
        for name, value in zip(result["passive_coordinates"], pose.passive):
            typer.echo(f"  {name} = {_coordinate_text(dev, name, value)}, passive")


def _coordinate_text(dev: Device, name: str, value: float) -> str:
    """A joint coordinate with its unit: metres for a prismatic joint, radians and degrees for a revolute one."""
    import math

    from hapticdesign.model.mechanism import JointType

    mechanism = dev.mechanism
    if mechanism.joint_types[mechanism.coordinates.index(name)] == JointType.PRISMATIC:
        return f"{value:.9g} m"
    return f"{value:.9g} rad ({math.degrees(value):.6g} deg)"


def export(
    out: Path = typer.Option(..., "--out", help="File to write (MJCF: .xml; URDF: .urdf)."),
    fmt: str = typer.Option("mjcf", "--format", help="mjcf (MuJoCo; loops as equality constraints) or urdf (trees "
                            "only)."),
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
) -> None:
    """Write the device's seed 000 eq. 2.50 dynamics for other simulators: MJCF with couplings as tendons,
    loops as connect constraints, motors with gear and armature; or URDF for a device without loops."""
    from hapticdesign.devices.export import export_text
    from hapticdesign.files import write_atomically

    with user_errors(strict=strict, quiet=quiet):
        if fmt not in ("mjcf", "urdf"):
            raise UserError(f"--format: unknown format {fmt!r} (use mjcf or urdf)")
        from hapticdesign.devices.loading import resolve_device

        dev = resolve_device(preset, device, params, strict=strict)
        write_atomically(out, export_text(dev, fmt))
        if json_out:
            print_json({"device": dev.name, "format": fmt, "out": str(out)})
        else:
            note(f"wrote {out} ({fmt})", quiet)


def spec(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    q: Optional[str] = typer.Option(None, "--q", help="Actuated joint coordinates, comma-separated (rad or m); "
                                    "default the home pose."),
    out: Optional[Path] = typer.Option(None, "--out", help="Folder for spec.html (beside the vendor's numbers where "
                                       "known) and spec.json."),
    period: Optional[float] = typer.Option(None, "--period", min=1e-6, max=1.0, help="Sample period T of the "
                                           "renderable stiffness's loop [s] (default 0.001, 1 kHz)."),
    rate: Optional[float] = typer.Option(None, "--rate", min=1.0, max=1e6, help="Former name: the servo rate [Hz], "
                                         "1 / --period; taken one release with a warning line."),
    delay: int = typer.Option(1, "--delay", min=0, max=100, help="Delay of the renderable stiffness's loop [samples]."),
    compensation: str = typer.Option("gravity", "--compensation", help="none, gravity or full (inverse dynamics)."),
    hand: str = typer.Option("light", "--hand", help="The hand of the 'with the hand' limit: light or firm "
                             "(docs/simulation.md); --hand-mass, --hand-damping, --hand-stiffness change it."),
    hand_mass: Optional[float] = typer.Option(None, "--hand-mass", help="The hand's mass [kg]."),
    hand_damping: Optional[float] = typer.Option(None, "--hand-damping", help="Its damping [N s/m]."),
    hand_stiffness: Optional[float] = typer.Option(None, "--hand-stiffness", help="Its stiffness [N/m]."),
    simulate: bool = typer.Option(True, "--simulate/--no-simulate", help="Simulate the renderable stiffness with "
                                  "the file's dry friction and encoder quantization (a few seconds)."),
    workspace: bool = typer.Option(True, "--workspace/--no-workspace", help="Search the workspace cube (the "
                                   "largest study box reached, on grids 3 and 5)."),
    index: str = typer.Option("", "--index", help="Comma-separated design indices to add at the pose "
                              "(docs/indices.md): built-in, a package's through its entry point, or one of --indices."),
    indices: Optional[Path] = typer.Option(None, "--indices", help="A Python file of your own design indices "
                                           "(decorated with @hapticdesign.index) that --index may name. Its code "
                                           "RUNS, as 'python FILE' would."),
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
) -> None:
    """Spec sheet at a pose (seed 001 ch. 4 metrics, seed 000 §4 rendering): resolution, continuous and peak
    force, apparent mass, backdrive friction, VJM stiffness (seed 001 §5.2), workspace cube and renderable
    stiffness beside the passivity bounds."""
    import warnings
    from dataclasses import replace

    from hapticdesign.errors import RenamedWarning
    from hapticdesign.files import dumps_json, write_atomically

    from hapticdesign.analysis.sampled_loop import Hand, SampledLoop
    from hapticdesign.studies.spec import no_progress, spec_sheet
    from hapticdesign.interface.report.spec_page import spec_page
    from hapticdesign.interface.round_off import without_round_off

    with user_errors(strict=strict, quiet=quiet):
        from hapticdesign.devices.loading import resolve_device

        dev = resolve_device(preset, device, params, strict=strict)
        pose = None if q is None else parse_vector(q, dev.n_dof, "q")
        given = {k: v for k, v in {"mass": hand_mass, "damping": hand_damping, "stiffness": hand_stiffness}.items()
                 if v is not None}
        preset = Hand.named(hand)
        if rate is not None:
            if period is not None:
                raise UserError("--rate is the former name of 1 / --period: give --period only")
            warnings.warn("--rate is now --period (the sample period, 1 / rate, in s); --rate will be removed",
                          RenamedWarning)
            period = 1.0 / rate
        loop = SampledLoop(period=1e-3 if period is None else period, delay=delay, compensation=compensation,
                           hand=replace(preset, **given, name=None) if given else preset)
        from hapticdesign.analysis.metrics.indices import INDICES
        from hapticdesign.interface.commands.optimize_adapter import index_module

        registry = INDICES.with_indices(index_module(indices)) if indices is not None else INDICES
        names = [name.strip() for name in index.split(",") if name.strip()]
        with progress_bar(not (quiet or json_out)) as report:
            report = report or no_progress
            sheet = spec_sheet(dev, pose, loop, workspace=workspace, simulate=simulate, indices=names,
                               registry=registry, progress=report)
            sheet["handle"] = without_round_off(sheet["handle"])  # a position's 1e-18 m residue is 0
            figures = [] if out is None else _spec_figures(dev, sheet, report)
        if out is not None:
            write_atomically(out / "spec.json", dumps_json(sheet) + "\n")
            write_atomically(out / "spec.html", spec_page(sheet, figures))
            note(f"wrote {out / 'spec.html'} and {out / 'spec.json'}", quiet)
        if json_out:
            print_json(sheet)
            return
        units = sheet["units"]
        for key, value in sheet.items():
            if key == "indices":
                for name, number in value.items():
                    typer.echo(f"{name}: {_text(number)} [{units['indices'][name]}]")
            elif key != "units":
                typer.echo(f"{key}: {_text(value)}" + (f" [{units[key]}]" if key in units else ""))


def _spec_figures(dev: Device, sheet: dict, report: Report) -> list[tuple[str, str, bytes]]:
    """The spec page's figures (title, caption, PNG): the workspace sections and the quantities over them, where
    the sheet has a workspace cube; ``report`` hears how far their inverse kinematics is."""
    figures = []
    if sheet["workspace"] is not None and sheet["workspace"]["cube"] > 0.0:
        from hapticdesign.studies.spec_maps import SECTION_SPAN, quantity_png, sheet_sections, workspace_png

        sections, edge = sheet_sections(dev, sheet, progress=report)
        figures.append(("Workspace sections", f"Planes through the home handle position, {SECTION_SPAN:g} "
                        "cube edges wide: blue where the handle gets by inverse kinematics on the home branch "
                        "(within the joint limits, no singularity), the workspace cube's section in red.",
                        workspace_png(dev, sections, edge)))
        quantities = quantity_png(dev, sections, edge, report)
        if quantities is not None:
            figures.append(("Quantities over the workspace", "The sheet's resolution, continuous force, "
                            "largest apparent mass and largest backdrive friction at each point of the "
                            "sections above, at the pose the inverse kinematics finds there (blank: not "
                            "reached); the workspace cube's section in red.", quantities))
    return figures


def _text(value) -> str:
    """Numbers with 4 significant digits, dicts as ``key value`` pairs, None as ``not stated``."""
    if value is None:
        return "not stated"
    if isinstance(value, dict):
        return ", ".join(f"{k} {_text(v)}" for k, v in value.items())
    if isinstance(value, (float, int)):
        return f"{value:.4g}"
    if isinstance(value, str):
        return value
    return "(" + ", ".join(f"{v:.4g}" for v in value) + ")"


def register(app: typer.Typer) -> None:
    app.command("ik")(ik)
    app.command("export")(export)
    app.command("spec")(spec)
