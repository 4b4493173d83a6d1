"""Commands of the Linearity Number area (seed 000 chapter 3): ``ln``, ``linearize``, ``designs``.

Their work (options, engines, files, text) is in :mod:`.linearity_adapter`, imported when a command runs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from hapticdesign.interface.common import activity, print_json, user_errors
from hapticdesign.interface.options import DEVICE, FORCE, FORCE_HINT, JSON_OUT, PARAMS, PRESET, QUIET, SEED, STRICT
from hapticdesign.workload import allow_large


def ln_command(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    strict: bool = STRICT,
    region: Optional[str] = typer.Option(
        None, "--region", help='Joint ranges in radians, e.g. "q2=-0.5:0.5,q3=0:1" (other joints keep their limits), or "torus" '
        '(eq. 3.4); default: the joint limits, full turns where none are given.'
    ),
    weights: Optional[Path] = typer.Option(None, "--weights", help="Weights file with keys H, C, G (eq. 3.1)."),
    as_json: bool = JSON_OUT,
    quiet: bool = QUIET,
    symbolic: bool = typer.Option(
        False, "--symbolic", help="Print LN as a polynomial in the seed's design variables (Appendix B.1/B.2)."
    ),
    fmt: Optional[str] = typer.Option(None, "--format", help="With --symbolic: text (default), latex or python."),
    part: Optional[str] = typer.Option(None, "--part", help="With --symbolic: all (default), H, C or G."),
    symbolic_gravity: bool = typer.Option(False, "--symbolic-gravity", help="With --symbolic: keep g as a symbol."),
    force: bool = FORCE,
) -> None:
    """Linearity Number of a device (seed 000 eq. 3.1-3.4) and its H, C, G parts, or its closed form."""
    with user_errors(strict, quiet), allow_large(force, FORCE_HINT):
        from hapticdesign.interface.commands.linearity_adapter import evaluate_ln, symbolic_ln
        from hapticdesign.errors import UserError

        if symbolic:
            if as_json:
                raise UserError("--json does not apply to --symbolic; choose --format text, latex or python")
            typer.echo(
                symbolic_ln(preset, device, params, strict, region, weights, fmt or "text", part or "all", symbolic_gravity)
            )
            return
        if fmt is not None or part is not None or symbolic_gravity:
            raise UserError("--format, --part and --symbolic-gravity need --symbolic")
        result = evaluate_ln(preset, device, params, strict, region, weights)
        if as_json:
            print_json({"device": result.device, "region": result.region, "ln": result.ln, "parts": result.parts})
            return
        typer.echo(f"device   {result.device}")
        typer.echo(f"region   {result.region}")
        typer.echo(f"LN       {result.ln:.10g}")
        for key, value in result.parts.items():
            typer.echo(f"  {key}      {value:.10g}")


def linearize_command(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    strict: bool = STRICT,
    find: int = typer.Option(0, "--find", help="Write this many realizable fully linear designs."),
    seed: int = SEED,
    out: Optional[Path] = typer.Option(None, "--out", help="CSV file for --find (default: print)."),
    realizability: str = typer.Option("rigid-body", "--realizability", help="rigid-body or seed (eq. 3.28)."),
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Conditions for LN = 0 (seed 000 eq. 3.12-3.27), free parameters, constant H; verdict when impossible."""
    with user_errors(strict, quiet), allow_large(force, FORCE_HINT), activity(not (quiet or json_out), "linearizing"):
        from hapticdesign.interface.commands.linearity_adapter import linearize, linearize_report

        result = linearize(preset, device, params, strict, find, seed, out, realizability)
        if json_out:
            print_json(result)
            return
    for line in linearize_report(result):
        typer.echo(line)


def designs_command(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    strict: bool = STRICT,
    levels: str = typer.Option("0,0.001,0.01,0.1,1,2", "--levels", help="LN levels (Table 3.3)."),
    count: int = typer.Option(100, "--count", help="Designs per level."),
    seed: int = SEED,
    out: Path = typer.Option(Path("designs.csv"), "--out", help="CSV output."),
    method: str = typer.Option("fast", "--method", help="fast (quadratic structure) or de (seed's differential evolution)."),
    realizability: str = typer.Option("rigid-body", "--realizability", help="rigid-body or seed (eq. 3.28 only)."),
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Designs at prescribed LN levels under eq. 3.35-3.38 (seed 000 §3.2.2), written to CSV."""
    with user_errors(strict, quiet), allow_large(force, FORCE_HINT):
        from hapticdesign.interface.commands.linearity_adapter import write_design_set

        with activity(not (quiet or json_out), "designs"):
            message = write_design_set(preset, device, params, strict, levels, count, seed, out, method, realizability)
        if json_out:
            print_json({"path": str(out), "levels": _level_summary(out)})
            return
        typer.echo(message)


def _level_summary(path: Path) -> list[dict]:
    """Per LN level of a written design set: how many designs and the range of their LN."""
    import csv

    rows: dict[float, list[float]] = {}
    with Path(path).open(newline="") as f:
        for row in csv.DictReader(f):
            rows.setdefault(float(row["level"]), []).append(float(row["ln"]))
    return [{"level": level, "count": len(lns), "ln_min": min(lns), "ln_max": max(lns)} for level, lns in rows.items()]


def register(app: typer.Typer) -> None:
    app.command("ln")(ln_command)
    app.command("linearize")(linearize_command)
    app.command("designs")(designs_command)
