"""Commands of the R-CUBE area (seed 001 ch. 4-5, §7.5): ``rcube ik | fk | stiffness | mass | metrics | maps``.

Lengths in metres, angles in radians. Without options the seed's final design (Table 7.8) is used.
"""

from __future__ import annotations

from dataclasses import replace
from math import inf
from pathlib import Path
from typing import Optional

import numpy as np
import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import parse_vector, print_json, progress_bar, user_errors
from hapticdesign.interface.options import FORCE, FORCE_HINT, JSON_OUT, QUIET
from hapticdesign.workload import allow_large

MAP_POINT_LIMIT = 3 * 201 * 201
"""Poses the metric maps may evaluate without --force (3 planes of 201 x 201: about a minute)."""

rcube_app = typer.Typer(help="Modified R-CUBE: kinematics, VJM stiffness, dynamics, metrics, optimization (seed 001 ch. 4-7).", no_args_is_help=True)

L1 = typer.Option(None, "--l1", help="Active link length l1 (m); default 0.1117 (Table 7.8).")
L2 = typer.Option(None, "--l2", help="Passive link length l2 (m); default 0.0741.")
L3 = typer.Option(None, "--l3", help="Passive link length l3 (m); default 0.1218.")
OFFSET = typer.Option(None, "--offset", help="Chain offset S (m); default S = l1 (eq. 6.39).")
SIGMA = typer.Option(None, "--sigma", help="Passive configuration, -1 or +1 (eq. 5.42); default the design file's, else -1.")
DESIGN = typer.Option(None, "--design", help="Design file (YAML/JSON: l1, l2, l3, links with D, d, plies).")
OUTER = typer.Option(None, "--outer", help="Outer diameters D of links 1-3 (m), comma-separated.")
INNER = typer.Option(None, "--inner", help="Inner diameters d of links 1-3 (m), comma-separated.")
PLIES = typer.Option(None, "--plies", help="Ply counts at 0,90,-45,45 deg per link, e.g. '4,7,7,7;2,6,6,6;2,6,2,2'.")
DENSITY = typer.Option(None, "--density", help="Link density (kg/m^3); default 1790.")
POSITION = typer.Option(None, "--position", help="Platform position x,y,z (m); default home (S, S, S).")


def _design(design_file, l1, l2, l3, offset, sigma, outer=None, inner=None, plies=None, density=None):
    """The design file's design (else the final design, Table 7.8) with the geometry options given."""
    from hapticdesign.analysis.rcube.design import final_design
    from hapticdesign.analysis.rcube.design_io import load_design

    design = load_design(design_file) if design_file else final_design()
    given = {k: v for k, v in (("l1", l1), ("l2", l2), ("l3", l3), ("offset", offset), ("sigma", sigma)) if v is not None}
    if given:
        design = design.with_geometry(replace(design.geometry, **given))
    if outer or inner or plies or density is not None:
        design = _override_links(design, outer, inner, plies, density)
    return design


def _override_links(design, outer, inner, plies, density):
    from hapticdesign.analysis.rcube.design_io import link_from_mapping

    D = parse_vector(outer, 3, "outer") if outer else [link.section.D for link in design.links]
    d = parse_vector(inner, 3, "inner") if inner else [link.section.d for link in design.links]
    if plies:
        groups = [g for g in plies.split(";") if g.strip()]
        if len(groups) != 3:
            raise UserError("--plies: expected three groups separated by ';'")
        counts = [[_count(v) for v in g.split(",")] for g in groups]
    else:
        counts = [None] * 3
    links = []
    for k, link in enumerate(design.links):
        entry = {"D": D[k], "d": d[k], "density": density if density is not None else link.density}
        if counts[k] is not None:
            entry["plies"] = counts[k]
            links.append(link_from_mapping(entry, entry["density"], f"link {k + 1}"))
        else:
            from hapticdesign.analysis.stiffness.sections import Tube

            links.append(replace(link, section=Tube(float(D[k]), float(d[k])), density=float(entry["density"])))
    return replace(design, links=tuple(links))


def _count(text: str) -> int:
    try:
        value = float(text)
    except ValueError:
        raise UserError(f"--plies: {text!r} is not a number") from None
    if value < 0 or value != int(value):
        raise UserError(f"--plies: ply counts must be non-negative integers, got {text!r}")
    return int(value)


def _with_joints(design, rotational: Optional[float], translational: Optional[float]):
    """Every joint of every chain with the given bearing stiffnesses (N m/rad, N/m); ``None`` keeps the
    design's joints (rigid unless the design file gives ``joints``)."""
    if rotational is None and translational is None:
        return design
    from hapticdesign.analysis.stiffness.joints import JointStiffness

    return design.with_joints(JointStiffness(inf if rotational is None else rotational,
                                             inf if translational is None else translational))


def _joint_share(design, position, K: np.ndarray, passive: bool) -> np.ndarray:
    """Fraction of the translational compliance (diagonal of ``K_C^-1``) that the joints add."""
    from hapticdesign.analysis.rcube.design import RIGID_JOINTS
    from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness

    rigid = cartesian_stiffness(replace(design, joints=RIGID_JOINTS), position, passive)
    C, C0 = np.diag(np.linalg.inv(K))[:3], np.diag(np.linalg.inv(rigid))[:3]
    return 1.0 - C0 / C


def _position(design, position):
    return design.geometry.home if position is None else parse_vector(position, 3, "position")


def _matrix_text(name: str, M: np.ndarray, unit: str) -> str:
    rows = "\n".join("  " + " ".join(f"{v:12.5g}" for v in row) for row in np.atleast_2d(M))
    return f"{name} [{unit}]\n{rows}"


@rcube_app.command()
def ik(l1: Optional[float] = L1, l2: Optional[float] = L2, l3: Optional[float] = L3,
       offset: Optional[float] = OFFSET, sigma: Optional[int] = SIGMA, design: Optional[Path] = DESIGN,
       position: str = typer.Option(..., "--position", help="Platform position x,y,z (m)."),
       json_out: bool = JSON_OUT, quiet: bool = QUIET) -> None:
    """Inverse kinematics (eq. 5.30-5.45): angles q_i1, q_i2, q_i3 of chains i = 1, 2, 3 (rad), one row per chain."""
    from hapticdesign.analysis.rcube.kinematics import inverse_kinematics, require_regular

    with user_errors(quiet=quiet):
        dsg = _design(design, l1, l2, l3, offset, sigma)
        q = inverse_kinematics(dsg.geometry, parse_vector(position, 3, "position"))
        require_regular(dsg.geometry, q)
        if json_out:
            print_json({"q": q, "units": {"q": "rad"}})
            return
        typer.echo(_matrix_text("q (rows: chains 1-3; columns q_i1, q_i2, q_i3)", q, "rad"))


@rcube_app.command()
def fk(q1: float = typer.Option(..., "--q1", help="Active angle q11 (rad)."),
       q2: float = typer.Option(..., "--q2", help="Active angle q21 (rad)."),
       q3: float = typer.Option(..., "--q3", help="Active angle q31 (rad)."),
       l1: Optional[float] = L1, l2: Optional[float] = L2, l3: Optional[float] = L3,
       offset: Optional[float] = OFFSET, sigma: Optional[int] = SIGMA, design: Optional[Path] = DESIGN,
       json_out: bool = JSON_OUT, quiet: bool = QUIET) -> None:
    """Forward kinematics (eq. 5.28): platform position from the active angles."""
    from hapticdesign.analysis.rcube.kinematics import forward_kinematics, inverse_kinematics

    with user_errors(quiet=quiet):
        dsg = _design(design, l1, l2, l3, offset, sigma)
        angles = np.array([q1, q2, q3])
        if not np.all(np.isfinite(angles)):
            raise UserError("--q1, --q2 and --q3 must be finite angles")
        r = forward_kinematics(dsg.geometry, angles)
        try:  # eq. 5.28 places the platform from the active angles alone; the passive links must reach it
            inverse_kinematics(dsg.geometry, r)
        except UserError:
            raise UserError(f"the active angles {q1:g}, {q2:g}, {q3:g} rad put the platform at "
                            f"{', '.join(f'{v:.4g}' for v in r)} m, which the passive links "
                            f"(l2 = {dsg.geometry.l2:g}, l3 = {dsg.geometry.l3:g} m) cannot reach") from None
        if json_out:
            print_json({"position": r, "units": {"position": "m"}})
            return
        typer.echo("position [m]: " + ", ".join(f"{v:.9g}" for v in r))


STIFFNESS_UNITS = {
    "position": "m",
    "K_C": "rows and columns x, y, z, rx, ry, rz: N/m (translational block), N/rad (coupling blocks), N m/rad "
           "(rotational block); entries below 1e-12 of the largest are round-off, printed as 0",
    "joint_compliance_share": "fraction of the x, y, z compliance (0 to 1)",
    "deflection": "m (x, y, z), rad (rx, ry, rz)",
}


@rcube_app.command()
def stiffness(l1: Optional[float] = L1, l2: Optional[float] = L2, l3: Optional[float] = L3,
              offset: Optional[float] = OFFSET, sigma: Optional[int] = SIGMA, design: Optional[Path] = DESIGN,
              outer: Optional[str] = OUTER, inner: Optional[str] = INNER, plies: Optional[str] = PLIES,
              density: Optional[float] = DENSITY, position: Optional[str] = POSITION,
              locked: bool = typer.Option(False, "--locked", help="K_C* with passive joints locked (eq. 6.60-6.61)."),
              wrench: Optional[str] = typer.Option(None, "--wrench", help="Fx,Fy,Fz[,Mx,My,Mz]: also print the deflection."),
              joint_stiffness: Optional[float] = typer.Option(
                  None, "--joint-stiffness",
                  help="Rotational stiffness of every joint's bearing (tilt) and of the active joint's drive (N m/rad); default rigid."),
              joint_translational: Optional[float] = typer.Option(
                  None, "--joint-translational", help="Translational stiffness of every joint's bearing (N/m); default rigid."),
              json_out: bool = JSON_OUT, quiet: bool = QUIET) -> None:
    """Cartesian stiffness K_C (eq. 5.121-5.123), unloaded mode, direct solution; with joint stiffness,
    also the share of the translational compliance that sits in the joints."""
    from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness, platform_deflection
    from hapticdesign.interface.round_off import without_round_off

    with user_errors(quiet=quiet):
        dsg = _design(design, l1, l2, l3, offset, sigma, outer, inner, plies, density)
        dsg = _with_joints(dsg, joint_stiffness, joint_translational)
        r = _position(dsg, position)
        K = cartesian_stiffness(dsg, r, passive=not locked)
        result = {"position": r, "K_C": without_round_off(K)}
        if not dsg.rigid_joints:
            result["joint_compliance_share"] = _joint_share(dsg, r, K, not locked)
        if wrench:
            w = parse_vector(wrench, 6 if wrench.count(",") == 5 else 3, "wrench")
            w = np.concatenate([w, np.zeros(6 - len(w))])
            result["deflection"] = np.linalg.solve(K, w) if locked else platform_deflection(dsg, r, w)
        if json_out:
            print_json({**result, "units": STIFFNESS_UNITS})
            return
        typer.echo(_matrix_text("K_C", result["K_C"], "N/m, N/rad, N m/rad"))
        if "joint_compliance_share" in result:
            typer.echo("share of the x, y, z compliance in the joints: "
                       + ", ".join(f"{100 * v:.1f} %" for v in result["joint_compliance_share"]))
        if "deflection" in result:
            typer.echo("deflection [m, rad]: " + ", ".join(f"{v:.6g}" for v in result["deflection"]))


@rcube_app.command()
def mass(l1: Optional[float] = L1, l2: Optional[float] = L2, l3: Optional[float] = L3,
         offset: Optional[float] = OFFSET, sigma: Optional[int] = SIGMA, design: Optional[Path] = DESIGN,
         outer: Optional[str] = OUTER, inner: Optional[str] = INNER, density: Optional[float] = DENSITY,
         position: Optional[str] = POSITION, json_out: bool = JSON_OUT, quiet: bool = QUIET) -> None:
    """Cartesian inertia M_C (eq. 5.223, 5.227) and the total link mass (eq. 5.230)."""
    from hapticdesign.analysis.rcube.dynamics import cartesian_mass_matrix

    with user_errors(quiet=quiet):
        dsg = _design(design, l1, l2, l3, offset, sigma, outer, inner, None, density)
        r = _position(dsg, position)
        M = cartesian_mass_matrix(dsg, r)
        if json_out:
            print_json({"position": r, "M_C": M, "link_mass": dsg.total_link_mass(),
                        "units": {"position": "m", "M_C": "kg", "link_mass": "kg"}})
            return
        typer.echo(_matrix_text("M_C", M, "kg"))
        typer.echo(f"total link mass: {dsg.total_link_mass() * 1e3:.1f} g")


@rcube_app.command()
def metrics(l1: Optional[float] = L1, l2: Optional[float] = L2, l3: Optional[float] = L3,
            offset: Optional[float] = OFFSET, sigma: Optional[int] = SIGMA, design: Optional[Path] = DESIGN,
            outer: Optional[str] = OUTER, inner: Optional[str] = INNER, plies: Optional[str] = PLIES,
            density: Optional[float] = DENSITY, position: Optional[str] = POSITION, json_out: bool = JSON_OUT,
            quiet: bool = QUIET) -> None:
    """Kinematic, stiffness and dynamic metrics at one position, modes of M_C and K_CA (seed 001 ch. 4, §6.1-6.3)."""
    from hapticdesign.analysis.metrics.dynamic import modes
    from hapticdesign.analysis.rcube.dynamics import cartesian_mass_matrix
    from hapticdesign.analysis.rcube.kinematics import inverse_kinematics, require_regular
    from hapticdesign.analysis.rcube.metrics import metrics_at
    from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness

    with user_errors(quiet=quiet):
        dsg = _design(design, l1, l2, l3, offset, sigma, outer, inner, plies, density)
        r = _position(dsg, position)
        require_regular(dsg.geometry, inverse_kinematics(dsg.geometry, r))
        values = {k: float(v[0]) for k, v in metrics_at(dsg, r[None]).items()}
        m = modes(cartesian_mass_matrix(dsg, r), cartesian_stiffness(dsg, r)[:3, :3])
        result = {"position": r, "metrics": values, "natural_frequencies": m.frequencies, "modal_vectors": m.vectors}
        if json_out:
            print_json(result)
            return
        for k, v in values.items():
            typer.echo(f"{k:>24s}: {v:.6g}")
        typer.echo("natural frequencies [rad/s]: " + ", ".join(f"{v:.5g}" for v in m.frequencies))


@rcube_app.command()
def maps(out: Path = typer.Option(..., "--out", help="Directory for the PNG images."),
         n: int = typer.Option(21, "--n", help="Points per side of each plane."),
         side: float = typer.Option(0.12, "--side", help="Workspace cube edge (m)."),
         l1: Optional[float] = L1, l2: Optional[float] = L2, l3: Optional[float] = L3,
         offset: Optional[float] = OFFSET, sigma: Optional[int] = SIGMA, design: Optional[Path] = DESIGN,
         outer: Optional[str] = OUTER, inner: Optional[str] = INNER, plies: Optional[str] = PLIES,
         density: Optional[float] = DENSITY, json_out: bool = JSON_OUT, quiet: bool = QUIET,
         force: bool = FORCE) -> None:
    """Metric maps on the planes z = home - side/2, home, home + side/2 (Figures 7.5-7.19)."""
    from hapticdesign.analysis.rcube.metrics import save_workspace_maps
    from hapticdesign.interface.report.index import write_folder_index
    from hapticdesign.workload import require_within

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        if n < 2:
            raise UserError("--n must be at least 2")
        require_within(f"maps of {n} x {n} points on 3 planes", 3.0 * n * n, MAP_POINT_LIMIT, "poses")
        if not side > 0.0:
            raise UserError("--side must be positive")
        dsg = _design(design, l1, l2, l3, offset, sigma, outer, inner, plies, density)
        h = side / 2
        planes = (-h, 0.0, h)
        paths = []
        with progress_bar(not (quiet or json_out)) as report:
            for k, plane in enumerate(planes):
                if report:
                    report("planes", k, len(planes))
                paths += save_workspace_maps(dsg, out, n, h, (plane,))
        g = dsg.geometry
        index = write_folder_index(out, "R-CUBE metric maps", (
            f"Metrics of the design l1, l2, l3 = {g.l1 * 1e3:g}, {g.l2 * 1e3:g}, {g.l3 * 1e3:g} mm on the planes "
            f"z = home - {h * 1e3:g} mm, home, home + {h * 1e3:g} mm of a {side * 1e3:g} mm cube, {n} x {n} points "
            "per plane (seed 001 §7.5, Figures 7.5-7.19)."), paths)
        if json_out:
            print_json({"out": str(out), "files": [str(p) for p in paths], "index": str(index)})
            return
        typer.echo(f"wrote {len(paths)} images to {out}, listed in {index}")


def register(app: typer.Typer) -> None:
    from hapticdesign.interface.commands.rcube_checks import add_commands

    add_commands(rcube_app)
    app.add_typer(rcube_app, name="rcube")
