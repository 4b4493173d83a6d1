"""R-CUBE design optimization commands (seed 001 ch. 6-7), added to the ``rcube`` sub-app:
``rcube optimize | synthesize | cross-section | plies``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Optional

import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import note, print_json, progress_bar, to_jsonable, user_errors
from hapticdesign.interface.options import FORCE, FORCE_HINT, JSON_OUT, QUIET, SEED
from hapticdesign.workload import allow_large

OUT = typer.Option(None, "--out", help="Directory for the CSV tables and PNG/SVG figures (rcube optimize: and report.html, "
                   "the synthesis in the design explorer).")
QUICK = typer.Option(False, "--quick", help="Small populations and few generations (tests, demos).")
POPULATION = typer.Option(None, "--population", help="Population size (default 100; --quick 24).")
GENERATIONS = typer.Option(None, "--generations", help="Generations (default 150 synthesis, 100 cross-section, 200 plies).")
WEIGHT = typer.Option(0.0, "--weight", help="Weight on mu_vn* of the selection (Table 7.5; the seed picks 0).")
BOUNDS = typer.Option(None, "--bounds", help="One bound set 'qlo,qhi;l2lo,l2hi;l3lo,l3hi' (rad; m) instead of Table 7.1's three.")
SIDE = typer.Option(0.120, "--side", help="CubeWorkspace cube edge (m), 120 mm in the seed.")
VIRTUAL = typer.Option(0.130, "--virtual-side", help="Virtual cube edge for the passive constraints (m), 130 mm.")


EVALUATION_LIMIT = 2e6
"""Objective evaluations an optimization command may plan without --force (the default chain plans
about 1.4e5 and takes about a minute on 2 cores; docs/limits.md)."""


def _settings(quick: bool, population: Optional[int], generations: Optional[int]):
    from hapticdesign.optimization.rcube.chain import Settings
    from hapticdesign.workload import require_within

    s = (Settings.quick() if quick else Settings()).with_population(population, generations)
    planned = (3 * s.population * s.generations + s.cs_population * s.cs_generations
               + s.ply_population * s.ply_generations)
    require_within("the optimization", planned, EVALUATION_LIMIT, "objective evaluations")
    return s


def _bound_sets(text: Optional[str]):
    from hapticdesign.optimization.rcube.synthesis import BOUND_SETS, Bounds

    if text is None:
        return BOUND_SETS
    groups = [g for g in text.split(";") if g.strip()]
    if len(groups) != 3:
        raise UserError("--bounds: expected three groups 'qlo,qhi;l2lo,l2hi;l3lo,l3hi'")
    pairs = []
    for g in groups:
        try:
            values = [float(v) for v in g.split(",")]
        except ValueError:
            raise UserError(f"--bounds: {g!r} is not two numbers") from None
        if len(values) != 2:
            raise UserError(f"--bounds: {g!r} is not two numbers")
        pairs.append(values)
    return (Bounds(tuple(p[0] for p in pairs), tuple(p[1] for p in pairs)),)


def _mm(design: dict) -> str:
    return (f"{design['l1'] * 1e3:.1f} / {design['l2'] * 1e3:.1f} / {design['l3'] * 1e3:.1f} mm "
            f"({design['total_length'] * 1e3:.1f} mm) at q_max {math.degrees(design['q_max']):.2f} deg")


def _shortest_line(summary: dict) -> str:
    """The front's shortest design beside the certified constrained minimum of the total length."""
    text = f"shortest on the front: {_mm(summary['shortest'])}"
    if summary["constrained_minimum"] is not None:
        text += f"; constrained minimum: {_mm(summary['constrained_minimum'])}"
    return text


def _note_paths(out: Path, quiet: bool, paths) -> None:
    note(f"wrote {len(paths)} files to {out}", quiet)


def _write(out: Path, result, summary: dict, settings, bound_sets, workspace) -> list[Path]:
    """The chain's tables, figures and summary.json, and report.html: the synthesis in the design explorer."""
    from hapticdesign.interface.report.seed_explorers import REPORT, rcube_page, write_explorer
    from hapticdesign.optimization.rcube.chain import write_chain
    from hapticdesign.optimization.rcube.explorer import chain_explorer
    from hapticdesign.interface.report.optimization_page import PLOTLY

    written = write_chain(out, result)
    data = chain_explorer(result, workspace, bound_sets, settings.generations)
    files = sorted({p.name for p in written} | {REPORT, PLOTLY})
    return written + write_explorer(out, rcube_page(data, summary, files))


def register(app: typer.Typer) -> None:
    from hapticdesign.interface.commands.rcube import rcube_app

    @rcube_app.command()
    def optimize(seed: int = SEED, out: Optional[Path] = OUT, quick: bool = QUICK, population: Optional[int] = POPULATION,
                 generations: Optional[int] = GENERATIONS, weight: float = WEIGHT, bounds: Optional[str] = BOUNDS,
                 side: float = SIDE, virtual_side: float = VIRTUAL,
                 max_deflection: Optional[float] = typer.Option(None, "--max-deflection", help="Ply choice: fewest plies with CF1 below this (m) under 20 N."),
                 json_out: bool = JSON_OUT, quiet: bool = QUIET, force: bool = FORCE) -> None:
        """The whole chain: synthesis, selection, swarm, cross-section and plies (seed 001 ch. 7)."""
        from hapticdesign.optimization.rcube.chain import chain_summary, run_chain
        from hapticdesign.optimization.rcube.constraints import CubeWorkspace

        with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
            settings = _settings(quick, population, generations)
            with progress_bar(not (quiet or json_out)) as report:
                result = run_chain(seed, settings, weight, _bound_sets(bounds), CubeWorkspace(side, virtual_side),
                                   max_deflection=max_deflection, progress=report)
            summary = chain_summary(result)
            if out is not None:
                _note_paths(out, quiet, _write(out, result, summary, settings, _bound_sets(bounds),
                                               CubeWorkspace(side, virtual_side)))
            if json_out:
                print_json(summary)
                return
            sel = summary["selected"]
            typer.echo(f"front: {summary['front_size']} designs, hypervolume {summary['hypervolume']:.4f}")
            typer.echo(_shortest_line(summary))
            typer.echo(f"selected solution {sel['solution']}: l1 = {sel['l1'] * 1e3:.1f} mm, l2 = {sel['l2'] * 1e3:.1f} mm, "
                       f"l3 = {sel['l3'] * 1e3:.1f} mm, q_max = {sel['q_max_deg']:.1f} deg")
            typer.echo(f"cross-section ratio d/D = {summary['ratio']:.4f}")
            p = summary["plies"]
            typer.echo(f"plies (0, 90, +-45 per link): {p['counts']}, CF1 = {p['CF1_mm']:.3f} mm under 20 N")
            typer.echo(f"link mass {summary['specifications']['total_link_mass_g']:.1f} g")

    @rcube_app.command()
    def synthesize(seed: int = SEED, out: Optional[Path] = OUT, quick: bool = QUICK, population: Optional[int] = POPULATION,
                   generations: Optional[int] = GENERATIONS, weight: float = WEIGHT, bounds: Optional[str] = BOUNDS,
                   side: float = SIDE, virtual_side: float = VIRTUAL, json_out: bool = JSON_OUT, quiet: bool = QUIET,
                   force: bool = FORCE) -> None:
        """Kinematic synthesis by NSGA-II over Table 7.1's bounds, post-evaluation and selection (§7.1-7.2)."""
        from hapticdesign.optimization.rcube import chain
        from hapticdesign.optimization.rcube.constraints import CubeWorkspace
        from hapticdesign.optimization.rcube.synthesis import synthesize as run

        with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
            s = _settings(quick, population, generations)
            workspace = CubeWorkspace(side, virtual_side)
            sets = _bound_sets(bounds)
            with progress_bar(not (quiet or json_out)) as report:
                callback = (lambda k, gen: report("synthesis", k * s.generations + gen, len(sets) * s.generations)) if report else None
                result = run(sets, s.population, s.generations, seed, workspace, progress=callback)
            selection = chain.select_solution(result, weight, workspace)
            if out is not None:
                _note_paths(out, quiet, chain.write_synthesis(out, result) + chain.write_selection(out, selection))
            summary = {"selected": chain.selected_summary(result, selection.selected), "front_size": len(result.front),
                       "hypervolume": result.hypervolume, **to_jsonable(chain.shortest_summary(result)),
                       "rms_choice": selection.rms_choice + 1,
                       "weighted_choice": {str(w): c + 1 for w, c in selection.weighted_choice.items()}}
            if json_out:
                print_json(summary)
                return
            typer.echo(" ".join(f"{h:>10s}" for h in chain.FRONT_HEADER[:6]))
            for row in chain.front_rows(result):
                typer.echo(" ".join(f"{v:10.1f}" if isinstance(v, float) else f"{v:10d}" for v in row[:6]))
            typer.echo(f"selected solution {selection.selected + 1}; hypervolume {result.hypervolume:.4f}")
            typer.echo(_shortest_line(summary))

    @rcube_app.command("cross-section")
    def cross_section(seed: int = SEED, out: Optional[Path] = OUT, quick: bool = QUICK,
                      population: Optional[int] = POPULATION, generations: Optional[int] = GENERATIONS,
                      lower: float = typer.Option(0.0, "--lower", help="Lower bound of d/D."),
                      upper: float = typer.Option(0.9, "--upper", help="Upper bound of d/D (thin-wall limit)."),
                      json_out: bool = JSON_OUT, quiet: bool = QUIET, force: bool = FORCE) -> None:
        """Inner/outer diameter ratio from CS1 = 1/S_l and CS2 = I_l (eq. 6.85-6.90, Figure 7.4)."""
        from hapticdesign.optimization.rcube import chain
        from hapticdesign.optimization.rcube.cross_section import exact_ratio, optimize_ratio

        with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
            s = _settings(quick, population, generations)
            result = optimize_ratio((lower, upper), s.cs_population, s.cs_generations, seed)
            if out is not None:
                _note_paths(out, quiet, chain.write_cross_section(out, result))
            summary = {"ratio": result.ratio, "exact_ratio": exact_ratio((lower, upper)), "front_size": len(result.ratios)}
            if json_out:
                print_json(summary)
                return
            typer.echo(f"d/D = {result.ratio:.4f} (front of {len(result.ratios)}); exact front: {summary['exact_ratio']:.4f}; seed: 0.768 (an upper d/D limit of 0.9034)")

    @rcube_app.command()
    def plies(seed: int = SEED, out: Optional[Path] = OUT, quick: bool = QUICK,
              population: Optional[int] = POPULATION, generations: Optional[int] = GENERATIONS,
              l1: float = typer.Option(0.1117, "--l1", help="Link length l1 (m); default Table 7.8."),
              l2: float = typer.Option(0.0741, "--l2", help="Link length l2 (m)."),
              l3: float = typer.Option(0.1218, "--l3", help="Link length l3 (m)."),
              ratio: float = typer.Option(0.768, "--ratio", help="Diameter ratio d/D (eq. 7.5)."),
              max_deflection: Optional[float] = typer.Option(None, "--max-deflection", help="Fewest plies with CF1 below this (m)."),
              json_out: bool = JSON_OUT, quiet: bool = QUIET, force: bool = FORCE) -> None:
        """Integer ply counts at 0, 90, +-45 deg per link under 20 N at full extension (eq. 6.91-6.96)."""
        from hapticdesign.model.rcube import RCubeGeometry
        from hapticdesign.optimization.rcube import chain
        from hapticdesign.optimization.rcube.plies import optimize_plies, ply_design

        with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
            s = _settings(quick, population, generations)
            geometry = RCubeGeometry(l1, l2, l3)
            with progress_bar(not (quiet or json_out)) as report:
                callback = (lambda gen: report("plies", gen, s.ply_generations)) if report else None
                result = optimize_plies(geometry, ratio, s.ply_population, s.ply_generations, seed, progress=callback)
            k = chain.choose_plies(result, max_deflection)
            design = ply_design(geometry, result.counts[k], ratio)
            specs = chain.specifications(design)
            if out is not None:
                written = chain.write_plies(out, result, k, chain.ply_limit(result, max_deflection))
                _note_paths(out, quiet, written + chain.write_final(out, design, result.counts[k], specs))
            summary = to_jsonable({"front_size": len(result.F), "chosen": k + 1, "counts": result.counts[k],
                                   "CF1_mm": float(result.F[k, 0] * 1e3), "plies": int(result.F[k, 2]),
                                   "D_mm": [link.section.D * 1e3 for link in design.links],
                                   "d_mm": [link.section.d * 1e3 for link in design.links], "specifications": specs})
            if json_out:
                print_json(summary)
                return
            typer.echo(f"{len(result.F)} ply designs on the front; chosen {k + 1}: {summary['counts']} "
                       f"({summary['plies']} plies, CF1 = {summary['CF1_mm']:.3f} mm), link mass {specs['total_link_mass_g']:.1f} g")
