"""Commands ``dynamics`` (numeric H, C, C_cvt, G, tau at a pose) and ``eom`` (symbolic equations)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np
import typer

from hapticdesign.errors import UserError
from hapticdesign.files import require_finite, write_atomically
from hapticdesign.interface.options import DEVICE, FORCE, FORCE_HINT, JSON_OUT, PARAMS, PRESET, QUIET, STRICT
from hapticdesign.workload import allow_large
from hapticdesign.interface.common import joint_units, note as stderr_note, parse_vector, print_json, user_errors



def dynamics(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    q: Optional[str] = typer.Option(None, help="Joint coordinates, comma-separated (rad or m); default the device's "
                                    "home pose (zeros without loops), as `spec` and `show`."),
    qd: Optional[str] = typer.Option(None, help="Joint rates, comma-separated."),
    qdd: Optional[str] = typer.Option(None, help="Joint accelerations, comma-separated."),
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """H, C, C_cvt, G and tau at one pose, in SI units (seed 000 eq. 2.50-2.52); H includes actuators' reflected
    rotor inertia. A pose outside the joint limits is computed, with a warning line on stderr. Entries below
    1e-12 of their matrix's largest (C's: H's) are round-off and shown as 0."""
    from hapticdesign.analysis.dynamics.device import (
        coriolis_centrifugal,
        coriolis_matrix,
        dynamics_of,
        gravity,
        inverse_dynamics,
        mass_matrix,
    )
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.interface.commands.pose_adapter import assembly_branch, branch_line, handle, handle_line
    from hapticdesign.interface.round_off import RELATIVE, without_round_off

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        from hapticdesign.devices.loading import resolve_device

        dev = resolve_device(preset, device, params, strict=strict)
        n = dev.n_dof
        qv = parse_vector(q, n, "q") if q is not None else configuration_of(dev).home
        qdv = parse_vector(qd, n, "qd")
        qddv = parse_vector(qdd, n, "qdd")
        for message in dev.limit_warnings(qv):  # allowed (the equations hold there), but worth a line
            stderr_note(f"warning: {message}", quiet)
        H = mass_matrix(dev, qv)
        inertia = float(np.max(np.abs(H)))  # the scale of C and C_cvt, derivatives of H
        result = {
            "device": dev.name,
            "q": qv,
            "qd": qdv,
            "qdd": qddv,
            "H": without_round_off(H),
            "C": without_round_off(coriolis_centrifugal(dev, qv), scale=inertia),
            "C_cvt": without_round_off(coriolis_matrix(dev, qv, qdv), scale=inertia * float(np.max(np.abs(qdv),
                                                                                                    initial=0.0))),
            "G": without_round_off(gravity(dev, qv)),
            "tau": without_round_off(inverse_dynamics(dev, qv, qdv, qddv)),
            "units": {"joints": joint_units(dev), "handle": "m",
                      "note": "SI: q in rad or m, tau in N m or N; H, C, G in the units that make tau so",
                      "round_off": f"entries below {RELATIVE:g} of their matrix's largest magnitude (for C that of H, for "
                                   "C_cvt that of H times the largest rate) are shown as 0"},
        }
        require_finite(result)  # text as JSON: no NaN or infinity printed as a result
        found, branch = handle(dev, qv), assembly_branch(dev)
        if found is not None:
            result["handle"] = found
        if branch is not None:
            result["assembly_branch"] = branch
        if json_out:
            print_json(result)
            return
        typer.echo(f"{dev.name} at q = {_row(qv)}, qd = {_row(qdv)}, qdd = {_row(qddv)}")
        pairs = ", ".join(f"({j + 1},{k + 1})" for j, k in dynamics_of(dev).pairs)
        for key, note in (
            ("H", "mass matrix [kg m^2]"),
            ("C", f"Coriolis/centrifugal, columns {pairs}"),
            ("C_cvt", "N x N form of eq. 2.52"),
            ("G", "gravity [N m]"),
            ("tau", "joint torques [N m]"),
        ):
            typer.echo(f"\n{key}: {note}")
            for row in np.atleast_2d(result[key]) if key not in ("G", "tau") else [result[key]]:
                typer.echo("  " + _row(row))
        if found is not None:
            typer.echo("\n" + handle_line(found))
        if branch is not None:
            typer.echo(branch_line(branch))


def _row(values: np.ndarray) -> str:
    return " ".join(f"{v: .6e}" for v in np.ravel(values))


TERMINAL_LIMIT = 100_000  # characters of equations printed to a terminal; more go to a file (--out) or a pipe


def _terminal() -> bool:
    """True when stdout is a terminal (where megabytes of equations are no use)."""
    import sys

    return sys.stdout.isatty()


def eom(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    symbolic: str = typer.Option(
        "all", help="Parameters kept as symbols: 'all', 'none', 'inertial', or names such as m2,r2x,l2."
    ),
    fmt: str = typer.Option("latex", "--format", help="latex, python or text."),
    part: str = typer.Option("tau", help="What to print: tau, H, C, G or all."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the equations to this file instead of stdout "
                                       "(needed for more than 100 kB on a terminal)."),
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Equations of motion as LaTeX, Python or text, symbols as chosen (seed 000 eq. 2.50, Appendix A). More than
    100 kB is not printed to a terminal: give --out FILE or pipe it."""
    from hapticdesign.analysis.dynamics.symbolic import check_export, derive, export

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        from hapticdesign.devices.loading import resolve_device

        dev = resolve_device(preset, device, params, strict=strict)
        check_export(fmt, part)
        # on a terminal without --out the equations may be refused as too long to read: that error is the one line
        silent = quiet or json_out or (out is None and _terminal())
        text = export(derive(dev, symbolic, started=lambda: stderr_note(
            f"eom: deriving the exact H, C and G of {dev.name} ({dev.n_dof} joints), then writing them as {fmt}: "
            "seconds for six joints with every parameter a symbol (the 6-DOF Phantom: about 5 s, then as long again "
            "for LaTeX)", silent)), fmt, part)
        if out is not None and not json_out:
            write_atomically(out, text + "\n")
            stderr_note(f"wrote {out} ({_size(len(text))} of {fmt})", quiet)
            return
        if not json_out:
            if len(text) > TERMINAL_LIMIT and _terminal():
                raise UserError(f"the equations are {_size(len(text))} of {fmt}, too long to read on a terminal; "
                                "write them to a file with --out FILE (or pipe them)")
            typer.echo(text)
            return
        result = {"device": dev.name, "format": fmt, "part": part}
        if fmt == "python":
            result["source"] = text
        else:
            result["equations"] = dict(_equation_entry(line) for line in text.splitlines())
        print_json(result)


def _size(characters: int) -> str:
    return f"{characters / 1e6:.1f} MB" if characters >= 1e6 else f"{characters / 1e3:.0f} kB"


def _equation_entry(line: str) -> tuple[str, str]:
    """``"H_{1,2} = ..."`` (LaTeX) or ``"H[1,2] = ..."`` (text) as ``("H_1_2", "...")``; vectors tau, G: ``tau_1``."""
    label, expression = line.split(" = ", 1)
    name, _, index = "".join(c for c in label if c not in "{}]").replace("[", "_").partition("_")
    indices = index.split(",")
    return "_".join([name, *(indices[:1] if name in ("tau", "G") else indices)]), expression


def register(app: typer.Typer) -> None:
    app.command("dynamics")(dynamics)
    app.command("eom")(eom)
