"""Command ``zwidth``: the exact Z-width of a 1-DOF haptic display (seed 000 ch. 5 future work)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Optional

import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import note, parse_vector, print_json, user_errors
from hapticdesign.interface.options import JSON_OUT, QUIET


def _dampers(text: Optional[str]) -> Optional[list[float]]:
    if text is None:
        return None
    values = [v for v in text.replace(" ", "").split(",") if v]
    if not 1 <= len(values) <= 1000:
        raise UserError("--b-values: give 1 to 1000 comma-separated dampers")
    return [float(v) for v in parse_vector(text, len(values), "b-values")]


def zwidth_command(
    inertia: float = typer.Option(..., help="Inertia J of the joint [kg m^2]."),
    damping: float = typer.Option(..., help="Physical viscous damping b [N m s/rad]."),
    period: float = typer.Option(1e-3, help="Sample period T [s]."),
    delay: int = typer.Option(0, help="Computation delay N [samples]: the torque of interval k uses the samples of k - N."),
    velocity: str = typer.Option("sampled", help="The damper's velocity: sampled (the seed's perfect sensor) or "
                                                 "difference (backward difference of sampled positions)."),
    compensate_inertia: bool = typer.Option(False, help="Feed the sampled acceleration forward (c J a)."),
    error_percent: float = typer.Option(0.0, help="Compensator modelling error E [%]: c = 1 - E/100 "
                                                  "(needs --compensate-inertia)."),
    b_values: Optional[str] = typer.Option(None, help="Virtual dampers B1,B2,... [N m s/rad]; default: a grid up "
                                                      "to the largest usable damper."),
    points: int = typer.Option(25, help="Points of the default damper grid."),
    out: Optional[Path] = typer.Option(None, help="Folder for the chart zwidth.png / zwidth.svg."),
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
) -> None:
    """Exact Z-width of a 1-DOF haptic display, K_max for each virtual damper B (seed 000 ch. 5 future work).

    Exact for the sampled-data loop (zero-order hold, delay, compensator), with the passivity bound of
    Colgate & Schenkel beside it (Colgate & Brown 1994)."""
    from hapticdesign.simulation.figures import zwidth_chart
    from hapticdesign.simulation.zwidth import DisplayLoop, zwidth

    with user_errors(quiet=quiet):
        if not (math.isfinite(error_percent) and 0.0 <= error_percent < 100.0):
            raise UserError(f"--error-percent must lie in [0, 100), got {error_percent}")
        if error_percent and not compensate_inertia:
            raise UserError("--error-percent needs --compensate-inertia (it scales the compensator's inertia)")
        fraction = (1.0 - error_percent / 100.0) if compensate_inertia else 0.0
        loop = DisplayLoop(inertia, damping, period, delay, velocity, fraction)
        result = zwidth(loop, _dampers(b_values), points)
        figures = []
        if out is not None:
            title = (f"J = {inertia:g} kg m^2, b = {damping:g} N m s/rad, T = {period:g} s, N = {delay}, "
                     f"{velocity} velocity" + (f", compensator c = {fraction:g}" if compensate_inertia else ""))
            figures = [str(p) for p in zwidth_chart(result, title, Path(out) / "zwidth")]
        payload = {**result.as_dict(), "loop": {"inertia": inertia, "damping": damping, "period": period,
                                                 "delay": delay, "velocity": velocity, "fraction": fraction},
                   "figures": figures}
        if json_out:
            print_json(payload)
            return
        typer.echo("B [N m s/rad]   K_max [N m/rad]   passivity K   linear approximation K")
        for b, k, p, lin in zip(result.B, result.K, result.passivity, result.linear):
            typer.echo(f"{b:13.5g}   {k:15.6g}   {p:11.6g}   {lin:22.6g}")
        for f in figures:
            note(f"wrote {f}", quiet)


def register(app: typer.Typer) -> None:
    app.command("zwidth")(zwidth_command)
