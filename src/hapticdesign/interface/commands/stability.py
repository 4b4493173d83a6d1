"""Command ``zwidth``: the exact Z-width of a 1-DOF haptic display (seed 000 ch. 5 future work)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import note, parse_vector, print_json, user_errors
from hapticdesign.interface.commands.simulation import COMPENSATION, PERIOD, SETTINGS, VELOCITY
from hapticdesign.interface.options import DEVICE, JSON_OUT, PARAMS, PRESET, QUIET, SEED, STRICT


def _dampers(text: Optional[str]) -> Optional[list[float]]:
    return None if text is None else [float(v) for v in parse_vector(text, None, "b-values")]


def _device_joint(dev, pose, joint, direction, loop) -> tuple[float, float, int, float | None, float | None]:
    """J = H_jj(q), b_j, the joint's index, ``J_n = n^T J_v`` of the joint along a Cartesian wall's ``direction``
    (None without one) and the compensator's ``H_m,jj`` (its model device's, None without a modelling error)."""
    from hapticdesign.analysis.dynamics.device import mass_matrix
    from hapticdesign.simulation.config import Wall, loop_model, normal_jacobian
    from hapticdesign.simulation.loop import joint_index

    j = joint_index(dev, joint)
    inertia = float(mass_matrix(dev, pose)[j, j])
    reach = None
    if direction is not None:
        reach = float(normal_jacobian(dev, Wall(direction=tuple(direction.tolist())), pose)[j])
    model = loop_model(dev, loop, pose)
    return inertia, float(dev.damping[j]), j, reach, None if model is None else float(model[0][j, j])


def zwidth_command(
    inertia: Optional[float] = typer.Option(None, help="Inertia J of the joint [kg m^2] (or take it from a device)."),
    damping: Optional[float] = typer.Option(None, help="Physical viscous damping b [N m s/rad] (or from a device)."),
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    q: Optional[str] = typer.Option(None, help="Pose of the device where the wall holds it [rad or m], "
                                               "comma-separated (default: its home, zeros for an open chain)."),
    joint: str = typer.Option("1", help="The device's joint carrying the wall (1-based or coordinate name); with "
                                        "--wall-direction and --one-dof the joint moving the handle."),
    wall_direction: Optional[str] = typer.Option(
        None, help="Device mode: a Cartesian wall along x,y,z at the handle, every actuated joint free (the limit "
                   "impedance-range --wall-direction and spec give); K in N/m, B in N s/m."),
    one_dof: bool = typer.Option(False, "--one-dof", help="With --wall-direction: the 1-DOF display of --joint, the "
                                                          "other joints held (the wall seen along its reach J_n; "
                                                          "the earlier default). A joint wall is always this."),
    strict: bool = STRICT,
    period: float = PERIOD,
    settings: Optional[str] = SETTINGS,
    delay: Optional[int] = typer.Option(None, help="Computation delay N [samples]: the torque of interval k uses the "
                                                   "samples of k - N. Default: the --settings' own."),
    velocity: Optional[str] = VELOCITY,
    compensation: Optional[str] = COMPENSATION,
    error_percent: float = typer.Option(0.0, help="Compensator modelling error E [%]: c = 1 - E/100 "
                                                  "(needs --compensation full)."),
    b_values: Optional[str] = typer.Option(None, help="Virtual dampers B1,B2,... [N m s/rad]; default: a grid up "
                                                      "to the largest usable damper."),
    points: int = typer.Option(25, help="Points of the default damper grid."),
    map_joints: Optional[str] = typer.Option(None, help="Two other joints (e.g. 2,3): also map K_max at the first "
                                                        "damper over their angles in [-pi, pi] (needs a device and --out)."),
    map_points: int = typer.Option(21, help="Points per axis of the map."),
    out: Optional[Path] = typer.Option(None, help="Folder for the chart zwidth.png / zwidth.svg."),
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
) -> None:
    """Exact Z-width of a haptic display, K_max for each virtual damper B (seed 000 ch. 5 future work).

    Exact for the sampled-data loop (zero-order hold, delay, compensator) under every command's loop settings
    (practice's by default, the seed's on its Phantom presets), with the passivity bound of Colgate & Schenkel beside
    it for a 1-DOF display (Colgate & Brown 1994). J and b come from the options or from one joint of a device at a
    pose (the other joints held); a device's Cartesian wall (--wall-direction) acts with every actuated joint free,
    as impedance-range's and the spec sheet's do (--one-dof: the held view). The output states the settings."""
    from dataclasses import replace

    from hapticdesign.interface.report.index import write_folder_index
    from hapticdesign.simulation.figures import zwidth_chart
    from hapticdesign.simulation.config import unit_direction
    from hapticdesign.simulation.zwidth import along_wall, wall_zwidth, zwidth

    with user_errors(quiet=quiet):
        from hapticdesign.interface.commands.simulation import sampled_loop, seed_settings

        from_device = preset is not None or device is not None
        if from_device == (inertia is not None or damping is not None):
            raise UserError("give either --inertia and --damping, or a device (--preset or --device) with --q and --joint")
        if wall_direction is not None and not from_device:
            raise UserError("--wall-direction needs a device (--preset or --device)")
        if wall_direction is not None and map_joints is not None:
            raise UserError("--map-joints charts a joint wall; leave out --wall-direction")
        if one_dof and wall_direction is None:
            raise UserError("--one-dof views a Cartesian wall from one joint; give --wall-direction (a joint wall is "
                            "always the joint's 1-DOF display)")
        if map_joints is not None and not (from_device and out is not None):
            raise UserError("--map-joints needs a device (--preset or --device) and --out")
        dev = None
        if from_device:
            from hapticdesign.analysis.configuration import configuration_of
            from hapticdesign.devices.loading import resolve_device

            dev = resolve_device(preset, device, params, strict=strict)
            pose = configuration_of(dev).home.copy() if q is None else parse_vector(q, dev.n_dof, "q")
            direction = None if wall_direction is None else parse_vector(wall_direction, 3, "wall-direction")
            if direction is not None and not direction.any():
                raise UserError("--wall-direction must not be the zero vector")
            axes = None if map_joints is None else _map_axes(dev, joint, map_joints, map_points)
        loop = sampled_loop(seed_settings(dev, settings), period, delay, velocity, compensation, error_percent, 0.0)
        if error_percent and loop.compensation != "full":
            raise UserError("--error-percent needs --compensation full (it scales the compensator's inertia)")
        reach, shown, model, free = None, loop, None, from_device and wall_direction is not None and not one_dof
        if free:  # the device's wall, every actuated joint free
            result = wall_zwidth(dev, pose, direction, loop, _dampers(b_values), points)
        else:
            if from_device:  # a 1-DOF display of the joint: the others held, as the settings state
                inertia, damping, wall, reach, model = _device_joint(dev, pose, joint, direction, loop)
                shown = replace(loop, held=tuple(j for j in range(dev.n_dof) if j != wall))
            elif inertia is None or damping is None:
                raise UserError("--inertia and --damping go together")
            if reach is not None:
                inertia, damping = along_wall(inertia, damping, reach)
                model = None if model is None else model / reach ** 2
            result = zwidth(inertia, damping, loop, _dampers(b_values), points, model)
        units = ("kg", "N s/m", "N/m") if wall_direction is not None else ("kg m^2", "N m s/rad", "N m/rad")
        figures, index = [], None
        if out is not None:
            plant = (f"{dev.name} at q = ({', '.join(f'{v:g}' for v in pose)}), wall along "
                     f"({', '.join(f'{v:g}' for v in direction)}), every joint free" if free else
                     f"J = {inertia:g} {units[0]}, b = {damping:g} {units[1]}")
            title = (f"{plant}, T = {period:g} s, N = {loop.delay}, {loop.velocity} velocity, {loop.compensation} "
                     "compensation"
                     + (f" (c = {loop.fraction if model is None else model / inertia:g})"
                        if loop.compensation == "full" and not free else "")
                     + (" (Cartesian wall)" if reach is not None else ""))
            figures = [str(p) for p in zwidth_chart(result, title, Path(out) / "zwidth", units[1:])]
            if map_joints is not None:
                figures += _map(dev, joint, axes, map_points, replace(loop, wall_damping=result.B[0]), Path(out))
            what = "a device" if free else "a 1-DOF"
            index = str(write_folder_index(Path(out), "Z-width", f"Exact Z-width of {what} haptic display (seed 000 "
                                           f"ch. 5 future work): {title}.", figures))
        about = ({"pose": pose.tolist(), "wall_direction": unit_direction(direction).tolist()} if free
                 else {"inertia": inertia, "damping": damping, **({} if model is None else {"model_inertia": model})})
        payload = {**result.as_dict(), "settings": shown.as_dict(), "loop": about,
                   "figures": figures, **({"index": index} if index else {})}
        if reach is not None:
            payload["units"] = {"B": units[1], "K": units[2]}
            payload["loop"]["wall_reach"] = reach
        if json_out:
            print_json(payload)
            return
        typer.echo(f"settings: {shown.describe()}")
        typer.echo(f"B [{units[1]}]   K_max [{units[2]}]   passivity K   linear approximation K")
        for i, (b, k) in enumerate(zip(result.B, result.K)):
            p = "-" if result.passivity is None else f"{result.passivity[i]:.6g}"
            lin = "-" if result.linear is None else f"{result.linear[i]:.6g}"
            typer.echo(f"{b:13.5g}   {k:15.6g}   {p:>11}   {lin:>22}")
        for f in figures + ([index] if index else []):
            note(f"wrote {f}", quiet)


def _map_axes(dev, joint: str, map_joints: str, points: int) -> tuple[int, int]:
    """The two joints of ``--map-joints``, checked with ``--map-points`` before the Z-width is computed or any
    chart written."""
    from hapticdesign.simulation.loop import joint_index
    from hapticdesign.simulation.zwidth import check_map

    names = [v for v in map_joints.replace(" ", "").split(",") if v]
    if len(names) != 2:
        raise UserError(f"--map-joints: give two joints, got {map_joints!r}")
    axes = (joint_index(dev, names[0]), joint_index(dev, names[1]))
    check_map(dev, joint_index(dev, joint), axes, points)
    return axes


def _map(dev, joint: str, axes: tuple[int, int], points: int, loop, out: Path) -> list[str]:
    """The K_max map over the joints ``axes`` (:func:`_map_axes`), charted into ``out``."""
    from hapticdesign.simulation.figures import stiffness_map_chart
    from hapticdesign.simulation.loop import joint_index
    from hapticdesign.simulation.zwidth import stiffness_map

    wall = joint_index(dev, joint)
    result = stiffness_map(dev, wall, axes, points, loop)
    coordinates = dev.mechanism.coordinates
    return [str(p) for p in stiffness_map_chart(result, [coordinates[a] for a in axes], coordinates[wall],
                                                out / "kmax_map")]


def robustness_command(
    designs: Path = typer.Option(..., help="Design CSV (as `designs` writes it): level, ln, ... and the inertial parameters."),
    errors: str = typer.Option("0,1,5,10", help="Modelling errors of masses and inertias [%], comma-separated."),
    per_level: Optional[int] = typer.Option(None, help="Use the first N designs of each LN level (default: all)."),
    seed: int = SEED,
    method: str = typer.Option("analytic", help="analytic (the exact linear loop; type 2 along the driven motion) or "
                                                "fast (the simulation)."),
    sim_type: int = typer.Option(2, "--type", help="1: other joints held; 2: driven at 0.52 sin(3 pi t) (default: "
                                                   "there the design's coupling can matter)."),
    draws: int = typer.Option(5, help="Seeded error-sign draws per design and error level."),
    out: Optional[Path] = typer.Option(None, help="Folder for robustness.csv and the chart robustness.png / .svg."),
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
) -> None:
    """Stable impedance range under modelling error, per LN level (seed 000 ch. 5 future work).

    Does a linear device keep its range better when the compensator's masses and inertias are wrong?
    Draw d of design i takes its error signs from seed + i draws + d; the table gives 95 % confidence
    intervals of the mean change."""
    from hapticdesign.devices.registry import preset
    from hapticdesign.files import csv_rows, write_atomically
    from hapticdesign.interface.common import progress_bar
    from hapticdesign.simulation.campaign import read_designs
    from hapticdesign.simulation.figures import robustness_chart
    from hapticdesign.simulation.robustness import case_count, error_cases, summarize_errors

    with user_errors(quiet=quiet):
        if method not in ("analytic", "fast"):
            raise UserError(f"--method must be 'analytic' or 'fast', got {method!r}")
        if sim_type not in (1, 2):
            raise UserError(f"--type must be 1 or 2, got {sim_type}")
        if not 1 <= draws <= 1000:
            raise UserError(f"--draws must be between 1 and 1000, got {draws}")
        if per_level is not None and per_level < 1:
            raise UserError(f"--per-level must be at least 1, got {per_level}")
        levels = [float(v) for v in parse_vector(errors, None, "errors", most=50)]
        base = preset("phantom-3dof")
        chosen, seen = [], {}
        for d in read_designs(designs):
            seen[d.level] = seen.get(d.level, 0) + 1
            if per_level is None or seen[d.level] <= per_level:
                chosen.append((d.name, d.level, base.with_params(d.params)))
        cases = case_count(len(chosen), levels, draws)
        note(f"robustness: {len(chosen)} designs x {len(levels)} error levels ({draws} draws at each level above 0) = "
             f"{cases} stable-range searches ({method})", quiet or json_out)
        with progress_bar(not (quiet or json_out)) as report:
            advance = (lambda done, total: report("robustness searches", done, total)) if report else None
            cases = error_cases(chosen, levels, seed, method=method, progress=advance, sim_type=sim_type, draws=draws)
        rows = summarize_errors(cases)
        files = []
        if out is not None:
            write_atomically(Path(out) / "robustness.csv", csv_rows(list(rows[0]), [list(r.values()) for r in rows]))
            files = [str(Path(out) / "robustness.csv"),
                     *map(str, robustness_chart(rows, Path(out) / "robustness", sim_type))]
        if json_out:
            print_json({"rows": rows, "designs": len(chosen), "errors": levels, "seed": seed, "type": sim_type,
                        "draws": draws, "files": files})
            return
        typer.echo("LN level   error [%]   mean K_max [N m/rad]   mean |change| [N m/rad] (95 % CI)   changed")
        for r in rows:
            change = "-" if r["mean_absolute_change"] is None else f"{r['mean_absolute_change']:.2f}"
            if r["absolute_change_ci_low"] is not None:
                change += f" ({r['absolute_change_ci_low']:.2f} to {r['absolute_change_ci_high']:.2f})"
            share = "-" if r["changed_share"] is None else f"{100 * r['changed_share']:.0f} %"
            typer.echo(f"{r['level']:8g}   {r['error_percent']:9g}   {r['mean']:20.2f}   {change:>33}   {share:>7}")
        for f in files:
            note(f"wrote {f}", quiet)


def register(app: typer.Typer) -> None:
    app.command("zwidth")(zwidth_command)
    app.command("robustness")(robustness_command)
