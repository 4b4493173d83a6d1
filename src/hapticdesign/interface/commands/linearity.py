"""Commands of the Linearity Number area (seed 000 chapter 3): ``ln``, ``linearize``, ``designs``."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from hapticdesign.interface.common import activity, print_json, user_errors
from hapticdesign.interface.options import DEVICE, JSON_OUT, PARAMS, PRESET, QUIET, SEED, STRICT


def ln_command(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    strict: bool = STRICT,
    region: Optional[str] = typer.Option(
        None, "--region", help='Joint ranges in radians, e.g. "q2=-0.5:0.5,q3=0:1"; default the torus (eq. 3.4).'
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
) -> None:
    """Linearity Number of a device (seed 000 eq. 3.1-3.4) and its H, C, G parts, or its closed form."""
    with user_errors(strict, quiet):
        from hapticdesign.analysis.linearity.service import evaluate_ln, symbolic_ln
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
) -> None:
    """Conditions for LN = 0 (seed 000 eq. 3.12-3.27), free parameters, constant H; verdict when impossible."""
    with user_errors(strict, quiet), activity(not (quiet or json_out), "linearizing"):
        if json_out:
            print_json(linearize_json(preset, device, params, strict, find, seed, out, realizability))
            return
        from hapticdesign.analysis.linearity.service import linearize_report

        lines = linearize_report(preset, device, params, strict, find, seed, out, realizability)
    for line in lines:
        typer.echo(line)


def linearize_json(preset, device_file, params_file, strict, find, seed, out, realizability) -> dict:
    """``linearize --json``: the conditions, then the seed-variable solution, free parameters and constant H
    (eq. 3.12-3.27), or the 6-DOF verdict with its certificate summary and minimum LN (eq. 3.40-3.42)."""
    from hapticdesign.analysis.linearity.bounds import practical_bounds
    from hapticdesign.analysis.linearity.conditions import linear_conditions, seed_conditions
    from hapticdesign.analysis.linearity.linear_designs import find_linear_designs
    from hapticdesign.analysis.linearity.service import (
        _designs_csv, device_form, parse_realizability, scaled_minimum,
    )
    from hapticdesign.analysis.linearity.verdict import decide_linearizable, minimum_ln
    from hapticdesign.devices.loading import resolve_device
    from hapticdesign.errors import UserError
    from hapticdesign.interface.common import write_atomically

    kind = parse_realizability(realizability)
    if find < 0:
        raise UserError("--find: the number of designs must be >= 0")
    dev = resolve_device(preset, device_file, params_file, strict)
    form = device_form(dev)
    conditions = linear_conditions(dev, form)
    result: dict = {"device": dev.name, "conditions": conditions.equations()}
    verdict = decide_linearizable(dev, form, kind)
    result["linear_possible"] = verdict.linear_possible
    names = dev.inertial_names()
    if not verdict.linear_possible:
        cert = verdict.certificate
        mins = minimum_ln(dev, form, practical_bounds(dev), kind)
        result["verdict"] = {
            "realizability": kind.value,
            "certificate": {"bodies": cert.support(), "min_eigenvalue": cert.min_eigenvalue(),
                            "residual": cert.residual},
            "exact": [{"body": body, "entry": k + 1} for body, k in verdict.exact],
            "minimum_ln": {"ln": mins.ln, "lower_bound": mins.lower_bound, "within_bounds": mins.within_bounds,
                           "realizable": mins.realizable, "design": dict(zip(names, mins.design.ravel()))},
            "scaled_minimum_ln": scaled_minimum(dev, mins),
        }
        return result
    solved = seed_conditions(dev, conditions)
    pi = dev.standard_parameters()
    result.update(
        seed_conditions={str(k): str(v) for k, v in solved.solution.items()},
        free_parameters=[s.name for s in solved.free],
        constant_H=conditions.constant_h @ pi,
        ln=form.ln(pi),
    )
    if find:
        designs = find_linear_designs(dev, form, conditions, practical_bounds(dev), find, seed, kind)
        result["designs"] = {"count": find, "max_ln": form.ln_seed(designs).max()}
        if out is None:
            result["designs"]["values"] = [dict(zip(names, row)) for row in designs]
        else:
            write_atomically(out, _designs_csv(names, designs, form))
            result["designs"]["path"] = str(out)
    return result


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
) -> None:
    """Designs at prescribed LN levels under eq. 3.35-3.38 (seed 000 §3.2.2), written to CSV."""
    with user_errors(strict, quiet):
        from hapticdesign.analysis.linearity.service import write_design_set

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
