"""R-CUBE checks beyond the seed (seed 001 ch. 8): ``rcube fem`` (finite-element check of the VJM
stiffness, as §5.2.5 did with ANSYS) and ``rcube tolerance`` (manufacturing tolerances, Monte Carlo).

Registered on the ``rcube`` sub-app by :func:`hapticdesign.interface.commands.rcube.register`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np
import typer

from hapticdesign.errors import UserError
from hapticdesign.files import output_folder
from hapticdesign.interface.common import note, parse_vector, print_json, progress_bar, user_errors
from hapticdesign.interface.options import JSON_OUT, QUIET, SEED

FEM_FIGURE = "rcube_fem_vs_vjm.png"
TOLERANCE_FIGURE = "rcube_tolerance.png"
DESIGN = typer.Option(None, "--design", help="Design file (YAML/JSON: l1, l2, l3, links; for tolerance also 'tolerances').")
OUT = typer.Option(None, "--out", help="Directory for the PNG figure.")


def _design(design_file: Optional[Path]):
    from hapticdesign.analysis.rcube.design import final_design
    from hapticdesign.analysis.rcube.design_io import load_design

    return load_design(design_file) if design_file else final_design()


def _positions(design, texts: Optional[list[str]]) -> np.ndarray:
    from hapticdesign.analysis.rcube.frame_fem import seed_test_positions

    if not texts:
        return seed_test_positions(design)
    return np.array([parse_vector(t, 3, "position") for t in texts])


def _fem_row(k: int, a) -> dict:
    return {
        "pose": k + 1,
        "position": a.position,
        "K_vjm": a.K_vjm,
        "K_fe": a.K_fe,
        "deflection_vjm": a.deflection_vjm,
        "deflection_fe": a.deflection_fe,
        "translational_difference": a.translational_difference,
        "rotational_difference": a.rotational_difference,
        "deflection_difference": a.deflection_difference,
    }


def _fem_text(rows: list[dict], load: float) -> str:
    lines = [f"{'pose':>4} {'position [mm]':>23} {'max |d| VJM':>12} {'max |d| FE':>12} "
             f"{'dK_trans':>9} {'dK_rot':>9} {'d defl':>9}",
             f"{'':>4} {'':>23} {f'[mm] {load:g} N':>12} {f'[mm] {load:g} N':>12} {'[%]':>9} {'[%]':>9} {'[%]':>9}"]
    for r in rows:
        p = ",".join(f"{v * 1e3:.1f}" for v in r["position"])
        dv = np.linalg.norm(r["deflection_vjm"][:, :3], axis=1).max() * 1e3
        df = np.linalg.norm(r["deflection_fe"][:, :3], axis=1).max() * 1e3
        lines.append(f"{r['pose']:>4} {p:>23} {dv:>12.4f} {df:>12.4f} {100 * r['translational_difference']:>9.2g} "
                     f"{100 * r['rotational_difference']:>9.2g} {100 * r['deflection_difference']:>9.2g}")
    return "\n".join(lines)


def fem(position: Optional[list[str]] = typer.Option(
            None, "--position", help="Platform position x,y,z (m); repeat for several; default Table 5.2's TP1-TP10."),
        design: Optional[Path] = DESIGN,
        locked: bool = typer.Option(False, "--locked", help="Passive joints locked in both models (eq. 6.60-6.61)."),
        load: float = typer.Option(20.0, "--load", help="Force along each axis for the deflections (N); 20 N in the seed."),
        out: Optional[Path] = OUT, json_out: bool = JSON_OUT, quiet: bool = QUIET) -> None:
    """Finite-element check of the VJM stiffness: the chains as a PyNiteFEA beam frame (seed 001 §5.2.5, chapter 8)."""
    from hapticdesign.analysis.rcube.frame_fem import compare, save_correlation_figure

    with user_errors(quiet=quiet):
        if not (np.isfinite(load) and load > 0.0):
            raise UserError(f"--load must be a positive force in newtons, got {load!r}")
        dsg = _design(design)
        if out is not None:
            output_folder(out)
        agreements = [compare(dsg, r, load, locked) for r in _positions(dsg, position)]
        rows = [_fem_row(k, a) for k, a in enumerate(agreements)]
        result = {"locked": locked, "load": load, "poses": rows,
                  "max_difference": max(max(r["translational_difference"], r["rotational_difference"],
                                            r["deflection_difference"]) for r in rows)}
        if out is not None:
            save_correlation_figure(agreements, Path(out) / FEM_FIGURE)
            result["figure"] = str(Path(out) / FEM_FIGURE)
            note(f"wrote {result['figure']}", quiet)
        if json_out:
            print_json(result)
            return
        typer.echo(_fem_text(rows, load))
        typer.echo(f"largest relative difference FE vs VJM: {100 * result['max_difference']:.2g} %")


def _tolerances(design_file: Optional[Path], design, l1: Optional[float], l2: Optional[float],
                l3: Optional[float], joint: Optional[float]):
    from hapticdesign.analysis.rcube.tolerance import default_tolerances, tolerances_from_file, with_tolerances

    base = tolerances_from_file(design_file, design) if design_file else default_tolerances(design)
    lengths = None
    if any(v is not None for v in (l1, l2, l3)):
        lengths = [new if new is not None else old for new, old in zip((l1, l2, l3), base.lengths)]
    return with_tolerances(base, lengths, joint)


def _tolerance_text(s: dict) -> str:
    k = s["K_C_diagonal"]
    n = s["nominal"]
    lines = [f"{s['samples']} samples; nominal K_C diagonal [N/m]: " + ", ".join(f"{v:.6g}" for v in s["K_C_diagonal_nominal"])]
    for name, v in k.items():
        lines.append(f"  {name} [N/m]: mean {v['mean']:.6g}, std {v['std']:.3g}, min {v['min']:.6g}, max {v['max']:.6g}")
    d = s["deflection_worst_axis"]
    lines.append(f"  worst-axis deflection under {s['load']:g} N [mm]: mean {d['mean'] * 1e3:.4f}, "
                 f"min {d['min'] * 1e3:.4f}, max {d['max'] * 1e3:.4f}")
    c = s["coverage"]
    lines.append(f"  cube coverage: min {c['min']:.4f}, mean {c['mean']:.4f} (nominal {n['coverage']:.4f})")
    v = s["min_singular_value"]
    lines.append(f"  smallest singular value of J_i over the cube [m/rad]: min {v['min']:.4g} (nominal {n['min_singular_value']:.4g})")
    v = s["max_condition"]
    lines.append(f"  largest condition number of J_i over the cube: max {v['max']:.4g} (nominal {n['max_condition']:.4g})")
    v = s["min_clearance"]
    lines.append(f"  smallest link clearance [mm]: min {v['min'] * 1e3:.3f} (nominal {n['min_clearance'] * 1e3:.3f})")
    lines.append(f"  samples leaving the cube or singular in it: {s['samples_singular_inside']}; "
                 f"self-colliding: {s['samples_colliding']}")
    return "\n".join(lines)


def tolerance(samples: int = typer.Option(200, "--samples", help="Number of Monte Carlo samples."),
              seed: int = SEED, design: Optional[Path] = DESIGN,
              tol_l1: Optional[float] = typer.Option(None, "--tol-l1", help="Tolerance +-t of l1 (m); default from the design file or ISO 2768-m."),
              tol_l2: Optional[float] = typer.Option(None, "--tol-l2", help="Tolerance +-t of l2 (m)."),
              tol_l3: Optional[float] = typer.Option(None, "--tol-l3", help="Tolerance +-t of l3 (m)."),
              tol_joint: Optional[float] = typer.Option(None, "--tol-joint", help="Tolerance +-t of each actuated joint's position, per component (m)."),
              grid: int = typer.Option(7, "--grid", help="Points per edge of the workspace-cube grid."),
              side: float = typer.Option(0.12, "--side", help="Workspace cube edge (m), 120 mm in the seed."),
              load: float = typer.Option(20.0, "--load", help="Force for the deflection spread (N)."),
              allow_long: bool = typer.Option(False, "--allow-long", help="Run even when estimated above the time limit."),
              out: Optional[Path] = OUT, json_out: bool = JSON_OUT, quiet: bool = QUIET) -> None:
    """Manufacturing tolerances by Monte Carlo: K_C spread, cube coverage, distance to singularity, self-collision (seed 001 chapter 8)."""
    from hapticdesign.analysis.rcube import tolerance as tol

    with user_errors(quiet=quiet):
        if samples < 1:
            raise UserError(f"--samples must be at least 1, got {samples}")
        if grid < 2:
            raise UserError(f"--grid must be at least 2, got {grid}")
        if not (np.isfinite(load) and load > 0.0):
            raise UserError(f"--load must be a positive force in newtons, got {load!r}")
        seconds = tol.check_budget(samples, grid, allow=allow_long)
        dsg = _design(design)
        tolerances = _tolerances(design, dsg, tol_l1, tol_l2, tol_l3, tol_joint)
        tolerances.check_design(dsg)
        nominal = tol.evaluate_sample(dsg, *tol.nominal_errors(), side, grid)
        if out is not None:  # the output place is checked (and named) before the run is announced
            output_folder(out)
        note(f"rcube tolerance: {samples} Monte Carlo samples, estimated {seconds:.0f} s", quiet or json_out)
        with progress_bar(not (quiet or json_out)) as report:
            results = tol.monte_carlo(dsg, tolerances, samples, seed, side, grid, report)
        s = tol.summary(nominal, results, load)
        s.update(seed=seed, tolerances={"lengths": list(tolerances.lengths), "joint_offset": tolerances.joint_offset},
                 grid=grid, side=side)
        if out is not None:
            tol.save_figure(nominal, results, Path(out) / TOLERANCE_FIGURE)
            s["figure"] = str(Path(out) / TOLERANCE_FIGURE)
            note(f"wrote {s['figure']}", quiet)
        if json_out:
            print_json(s)
            return
        typer.echo(_tolerance_text(s))


def add_commands(app: typer.Typer) -> None:
    """Add ``fem`` and ``tolerance`` to the ``rcube`` sub-app."""
    app.command("fem")(fem)
    app.command("tolerance")(tolerance)
