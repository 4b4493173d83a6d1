"""The whole optimization chain of seed 001 ch. 7 and its tables: synthesis (Table 7.2), post-evaluation
and selection (Tables 7.3-7.5), the weighted-sum swarm, the cross-section ratio (eq. 7.5), the plies
(Tables 7.6-7.7) and the final design with its specifications (Tables 7.8-7.9)."""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.analysis.metrics import names
from hapticdesign.analysis.rcube.design import RCubeDesign
from hapticdesign.analysis.rcube.dynamics import cartesian_mass_matrix
from hapticdesign.analysis.rcube.kinematics import dexterous_cube
from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness
from hapticdesign.files import csv_rows, output_folder, to_jsonable, write_atomically
from hapticdesign.optimization.rcube import figures
from hapticdesign.optimization.rcube.constraints import CubeWorkspace
from hapticdesign.optimization.rcube.cross_section import RATIO_BOUNDS, CrossSectionResult, optimize_ratio
from hapticdesign.optimization.rcube.objectives import EvaluationLinks, geometry_of
from hapticdesign.optimization.rcube.plies import PlyResult, choose, optimize_plies, ply_design
from hapticdesign.optimization.front_selection import normalize, weighted_rms
from hapticdesign.optimization.rcube.selection import METRIC_NAMES, normalized_indices, post_evaluate
from hapticdesign.optimization.rcube.swarm import SwarmResult, weighted_sum_swarm
from hapticdesign.optimization.rcube.synthesis import BOUND_SETS, SynthesisResult, synthesize

WEIGHTS = (0.0, 0.25, 0.5, 0.75)
"""Weights on ``mu_vn*`` of Table 7.5."""

SPEC_FORCE = 5.0
"""N per axis, the continuous force of Table 7.9."""


@dataclass(frozen=True)
class Settings:
    """Population and generations of each step; ``quick`` settings are for tests and demos."""

    population: int = 100
    generations: int = 150
    cs_population: int = 100
    cs_generations: int = 100
    ply_population: int = 100
    ply_generations: int = 200
    swarm_population: int = 40
    swarm_generations: int = 60

    @classmethod
    def quick(cls) -> "Settings":
        return cls(24, 15, 20, 20, 24, 15, 10, 8)

    def with_population(self, population: int | None, generations: int | None) -> "Settings":
        """Override the synthesis population and generations (the other steps scale with them)."""
        out = self
        if population is not None:
            if population < 2:
                raise UserError(f"population must be at least 2, got {population}")
            out = replace(out, population=population, cs_population=population, ply_population=population,
                          swarm_population=max(2, population // 2))
        if generations is not None:
            if generations < 1:
                raise UserError(f"generations must be at least 1, got {generations}")
            out = replace(out, generations=generations, cs_generations=generations, ply_generations=generations,
                          swarm_generations=generations)
        return out


@dataclass(frozen=True)
class Selection:
    metrics: dict[str, np.ndarray]
    normalized: dict[str, np.ndarray]
    rms: np.ndarray
    weighted: dict[float, np.ndarray]
    rms_choice: int
    weighted_choice: dict[float, int]
    selected: int
    weight: float = 0.0
    """The weight on ``mu_vn*`` of the rule that selected ``selected`` (Table 7.5)."""
    evaluation: dict = field(default_factory=dict)
    """The post-evaluation tube (material, D, d, density) the metrics of Table 7.3 were computed with."""


def select_solution(synthesis: SynthesisResult, weight: float = 0.0, workspace: CubeWorkspace = CubeWorkspace(),
                    links: EvaluationLinks = EvaluationLinks()) -> Selection:
    """Post-evaluate the front (Table 7.3), normalize (Table 7.4, eq. 7.1-7.4) and pick the minimum
    weighted RMS with ``weight`` on ``mu_vn*`` (the seed picks weight 0, Sol. 1, §7.2)."""
    metrics = post_evaluate(synthesis.front.X, workspace, links)
    n = normalized_indices(metrics)
    rms = weighted_rms(n[names.FREQUENCY_INDEX], n[names.CRITICAL_MANIPULABILITY])
    weighted = {float(w): weighted_rms(n[names.FREQUENCY_INDEX], n[names.CRITICAL_MANIPULABILITY], w)
                for w in sorted(set(WEIGHTS) | {weight})}
    choices = {w: int(np.argmin(v)) for w, v in weighted.items()}
    return Selection(metrics, n, rms, weighted, int(np.argmin(rms)), choices, choices[float(weight)], float(weight),
                     links.settings())


SEED_RELATIVE_DEFLECTION = 0.291 / 0.048
"""The seed's chosen ply design (Table 7.6, Sol. 29) deflects 6.06 times as much as its stiffest one (Sol. 1)."""


def choose_plies(result: PlyResult, max_deflection: float | None = None,
                 relative: float = SEED_RELATIVE_DEFLECTION) -> int:
    """The fewest plies whose translational deflection ``CF1`` stays below ``max_deflection`` (m) or,
    without it, below ``relative`` times the smallest ``CF1`` of the front (the seed's choice of
    Table 7.6 Sol. 29, scale free so that it carries over to a model with different absolute
    deflections)."""
    return choose(result.F, ply_limit(result, max_deflection, relative))


def ply_limit(result: PlyResult, max_deflection: float | None = None, relative: float = SEED_RELATIVE_DEFLECTION) -> float:
    """The ``CF1`` limit (m) of :func:`choose_plies`."""
    return max_deflection if max_deflection is not None else relative * float(result.F[:, 0].min())


def specifications(design: RCubeDesign, workspace: CubeWorkspace = CubeWorkspace()) -> dict[str, float | bool]:
    """Table 7.9's computable rows: dexterous workspace, link mass, maximum deflection under 5 N per
    axis at the fully extended pose (``K_C`` with passive joints eliminated and ``K_C*``), and ``M_C``
    at home."""
    g = design.geometry
    extended = g.home + workspace.half
    F = np.array([SPEC_FORCE] * 3 + [0.0] * 3)
    deflection = np.linalg.solve(cartesian_stiffness(design, extended), F)[:3]
    locked = np.linalg.solve(cartesian_stiffness(design, extended, passive=False), F)[:3]
    M = cartesian_mass_matrix(design, g.home)
    return {
        "workspace_mm": workspace.side * 1e3,
        "dexterous_workspace": dexterous_cube(g, workspace.side),
        "total_link_mass_g": design.total_link_mass() * 1e3,
        "max_deflection_mm": float(np.linalg.norm(deflection)) * 1e3,
        "max_deflection_locked_mm": float(np.linalg.norm(locked)) * 1e3,
        "M_C_diagonal_kg": float(M[0, 0]),
        "M_C_offdiagonal_kg": float(M[0, 1]),
    }


@dataclass(frozen=True)
class ChainResult:
    synthesis: SynthesisResult
    selection: Selection
    swarm: SwarmResult
    cross_section: CrossSectionResult
    plies: PlyResult
    ply_choice: int
    design: RCubeDesign
    specs: dict
    ply_limit: float = float("nan")
    """The ``CF1`` limit (m) that chose the plies."""


def run_chain(seed: int = 1, settings: Settings = Settings(), weight: float = 0.0, bound_sets=BOUND_SETS,
              workspace: CubeWorkspace = CubeWorkspace(), ratio_bounds=RATIO_BOUNDS, max_deflection: float | None = None,
              progress: Callable[[str, int, int], None] | None = None, client=None) -> ChainResult:
    """Synthesis, selection, swarm, cross-section and plies, all seeded from ``seed``.

    ``progress(step, done, total)`` reports generations; ``client`` (a ``dask.distributed.Client``,
    none by default) evaluates the synthesis, swarm and ply objectives on its workers.
    """
    s = settings
    n_sets = len(bound_sets)

    def report(step: str, total: int, offset: Callable[..., int] = lambda *a: 0):
        if progress is None:
            return None
        return lambda *a: progress(step, offset(*a) + a[-1], total)

    synthesis = synthesize(bound_sets, s.population, s.generations, seed, workspace, client=client,
                           progress=report("synthesis", n_sets * s.generations, lambda k, gen: k * s.generations))
    selection = select_solution(synthesis, weight, workspace)
    swarm = weighted_sum_swarm(synthesis.front, bounds=bound_sets[-1], population=s.swarm_population,
                               generations=s.swarm_generations, seed=seed, workspace=workspace, client=client)
    cross = optimize_ratio(ratio_bounds, s.cs_population, s.cs_generations, seed, report("cross-section", s.cs_generations))
    geometry = geometry_of(synthesis.front.X[selection.selected], workspace)
    plies = optimize_plies(geometry, cross.ratio, s.ply_population, s.ply_generations, seed,
                           progress=report("plies", s.ply_generations), client=client)
    k = choose_plies(plies, max_deflection)
    design = ply_design(geometry, plies.counts[k], cross.ratio)
    return ChainResult(synthesis, selection, swarm, cross, plies, k, design, specifications(design, workspace),
                       ply_limit(plies, max_deflection))


def _write_csv(path: Path, header: list[str], rows) -> Path:
    write_atomically(path, csv_rows(header, ([f"{v:.10g}" if isinstance(v, (float, np.floating)) else v for v in row]
                                             for row in rows)))
    return path


def front_rows(synthesis: SynthesisResult):
    f = synthesis.front
    for k in range(len(f)):
        yield [k + 1, f.l1[k] * 1e3, f.X[k, 1] * 1e3, f.X[k, 2] * 1e3, f.total_length[k] * 1e3,
               float(np.degrees(f.X[k, 0])), *f.F[k]]


FRONT_HEADER = ["solution", "l1_mm", "l2_mm", "l3_mm", "total_mm", "q_max_deg", "O1", "O2", "O3"]


def write_synthesis(out: Path, synthesis: SynthesisResult) -> list[Path]:
    """Table 7.2 with the objectives, and the front figure."""
    paths = [_write_csv(out / "table_7_2_front.csv", FRONT_HEADER, front_rows(synthesis))]
    return paths + figures.pareto_front_3d(synthesis.front.F, out)


def write_selection(out: Path, selection: Selection) -> list[Path]:
    """Tables 7.3-7.5 and Figures 7.1-7.3."""
    m, n = selection.metrics, selection.normalized
    count = len(m[names.INERTIA_FROBENIUS])
    paths = [
        _write_csv(out / "table_7_3_post_evaluation.csv", ["solution", *METRIC_NAMES],
                   ([k + 1, *(m[name][k] for name in METRIC_NAMES)] for k in range(count))),
        _write_csv(out / "table_7_4_normalized.csv", ["solution", "I_fn", "S_fn*", "omega_nn*", "mu_vn*", "c_vn"],
                   ([k + 1, *(n[name][k] for name in METRIC_NAMES)] for k in range(count))),
        _write_csv(out / "table_7_5_weighted_rms.csv", ["weight_mu_vn", "solution"],
                   ([w, c + 1] for w, c in selection.weighted_choice.items())),
    ]
    paths += figures.frequency_vs_manipulability(n[names.FREQUENCY_INDEX], n[names.CRITICAL_MANIPULABILITY],
                                                 selection.rms_choice, selection.selected, selection.weight, out)
    paths += figures.rms_curves({"RMS, eq. 7.2-7.4": selection.rms}, out, "figure_7_2_rms",
                                "Figure 7.2: RMS of omega_nn* and mu_vn*", selection.selected, selection.weight)
    paths += figures.rms_curves({f"weight {w:g}": v for w, v in selection.weighted.items()}, out,
                                "figure_7_3_weighted_rms", "Figure 7.3: weighted RMS", selection.selected, selection.weight)
    return paths


def write_cross_section(out: Path, cross: CrossSectionResult) -> list[Path]:
    """The cross-section front with its RMS (eq. 7.5) and Figure 7.4."""
    paths = [_write_csv(out / "cross_section_front.csv", ["ratio", "CS1", "CS2", "rms"],
                        zip(cross.ratios, cross.CS1, cross.CS2, cross.rms))]
    return paths + figures.cross_section_figure(cross.ratios, normalize(cross.CS1), normalize(cross.CS2),
                                                cross.rms, cross.ratio, out)


PLY_HEADER = ["solution", "CF1_mm", "CF2_deg", "plies",
              "link1_0", "link1_90", "link1_45", "link2_0", "link2_90", "link2_45", "link3_0", "link3_90", "link3_45",
              "D1_mm", "d1_mm", "D2_mm", "d2_mm", "D3_mm", "d3_mm"]


def ply_rows(plies: PlyResult):
    for k, (counts, F) in enumerate(zip(plies.counts, plies.F)):
        design = ply_design(plies.evaluator.geometry, counts, plies.evaluator.ratio)
        tubes = [v * 1e3 for link in design.links for v in (link.section.D, link.section.d)]
        yield [k + 1, F[0] * 1e3, float(np.degrees(F[1])), int(F[2]), *counts.ravel().tolist(), *tubes]


def write_plies(out: Path, plies: PlyResult, chosen: int, limit: float | None = None) -> list[Path]:
    """Tables 7.6-7.7 (one table) and the ply front figure; ``limit`` (m) is the ``CF1`` bound that chose."""
    paths = [_write_csv(out / "table_7_6_7_plies.csv", PLY_HEADER, ply_rows(plies))]
    rule = "" if limit is None or not np.isfinite(limit) else f"fewest plies with CF1 <= {limit * 1e3:.3g} mm"
    return paths + figures.ply_front(plies.F, chosen, out, rule)


def write_final(out: Path, design: RCubeDesign, counts: np.ndarray, specs: dict) -> list[Path]:
    """Table 7.8 and Table 7.9."""
    rows = []
    for j, (link, L, c) in enumerate(zip(design.links, design.lengths, counts)):
        rows.append([f"l{j + 1}", link.section.D * 1e3, link.section.d * 1e3, L * 1e3, int(c[0]), int(c[1]), int(c[2]), int(c[2])])
    return [
        _write_csv(out / "table_7_8_final_design.csv", ["link", "D_mm", "d_mm", "length_mm", "plies_0", "plies_90", "plies_45", "plies_-45"], rows),
        _write_csv(out / "table_7_9_specifications.csv", ["quantity", "value"], ([k, v] for k, v in specs.items())),
    ]


def selected_summary(synthesis: SynthesisResult, index: int) -> dict:
    f = synthesis.front
    return {"solution": index + 1, "l1": float(f.l1[index]), "l2": float(f.X[index, 1]), "l3": float(f.X[index, 2]),
            "q_max_deg": float(np.degrees(f.X[index, 0]))}


def shortest_summary(synthesis: SynthesisResult) -> dict:
    """The front's shortest design, the certified constrained minimum of the total length (both
    ``l1, l2, l3, q_max, total_length`` in m and rad; None when not computed) and its certificate."""
    minimum = synthesis.constrained_minimum
    certificate = None if minimum is None else {
        "active_constraints": list(minimum.certificate.active),
        "multipliers": [float(v) for v in minimum.certificate.multipliers],
        "stationarity": minimum.certificate.stationarity,
        "strict_local_minimum": minimum.certificate.strict_local_minimum,
        "starts": minimum.starts, "starts_reaching_it": minimum.converged}
    return {"shortest": synthesis.front.shortest(),
            "constrained_minimum": None if minimum is None else minimum.summary(),
            "constrained_minimum_certificate": certificate}


def chain_summary(result: ChainResult) -> dict:
    """The JSON summary of the whole chain."""
    sel, sw = result.selection, result.swarm
    counts = result.plies.counts[result.ply_choice]
    return to_jsonable({
        "front_size": len(result.synthesis.front),
        "hypervolume": result.synthesis.hypervolume,
        "evaluations": result.synthesis.evaluations,
        **shortest_summary(result.synthesis),
        "selected": selected_summary(result.synthesis, sel.selected),
        "post_evaluation": sel.evaluation,
        "rms_choice": sel.rms_choice + 1,
        "weighted_choice": {str(w): c + 1 for w, c in sel.weighted_choice.items()},
        "swarm": {"l2": float(sw.x[1]), "l3": float(sw.x[2]), "q_max_deg": float(np.degrees(sw.x[0])),
                  "weighted_sum": sw.value, "front_best_solution": sw.nearest + 1,
                  "front_best_weighted_sum": sw.nearest_value, "dominated_by_front": sw.dominated},
        "ratio": result.cross_section.ratio,
        "plies": {"front_size": len(result.plies.F), "chosen": result.ply_choice + 1, "counts": counts,
                  "CF1_mm": float(result.plies.F[result.ply_choice, 0] * 1e3),
                  "CF2_deg": float(np.degrees(result.plies.F[result.ply_choice, 1]))},
        "final_design": {"D_mm": [link.section.D * 1e3 for link in result.design.links],
                         "d_mm": [link.section.d * 1e3 for link in result.design.links]},
        "specifications": result.specs,
    })


def write_chain(out: Path, result: ChainResult) -> list[Path]:
    """Every table (CSV), figure (PNG and SVG) and ``summary.json`` of the chain."""
    out = output_folder(out)
    paths = write_synthesis(out, result.synthesis) + write_selection(out, result.selection)
    paths += write_cross_section(out, result.cross_section) + write_plies(out, result.plies, result.ply_choice, result.ply_limit)
    paths += write_final(out, result.design, result.plies.counts[result.ply_choice], result.specs)
    summary = out / "summary.json"
    write_atomically(summary, json.dumps(chain_summary(result), indent=2))
    return paths + [summary]
