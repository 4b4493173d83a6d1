"""Study ``rcube``: seed 001 end to end on the modified R-CUBE (Gorgulu 2018).

Steps: kinematics and workspace of the final design (§5.1, Table 7.2), Table 7.3's kinematic
columns, the final design's stiffness, inertia and modes side by side with eq. 7.6-7.13 and Table
7.9, workspace maps of the metrics (§7.5, Figures 7.5-7.19), and the optimization chain (ch. 6-7).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hapticdesign.analysis.metrics import names
from hapticdesign.analysis.metrics.dynamic import modes
from hapticdesign.analysis.metrics.globalization import global_indices
from hapticdesign.analysis.metrics.maps import draw_map
from hapticdesign.analysis.rcube import dynamics as rcube_dynamics
from hapticdesign.analysis.rcube import kinematics as rcube_kinematics
from hapticdesign.analysis.rcube import metrics as rcube_metrics
from hapticdesign.analysis.rcube import stiffness as rcube_stiffness
from hapticdesign.analysis.rcube.design import final_design, seed_final_design
from hapticdesign.errors import UserError
from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.optimization.rcube.chain import (
    Settings,
    chain_summary,
    run_chain,
    write_chain,
)
from hapticdesign.optimization.rcube.constraints import CubeWorkspace, constraint_values
from hapticdesign.optimization.rcube.plies import ply_design
from hapticdesign.optimization.rcube.selection import METRIC_NAMES as TABLE_7_3_METRICS
from hapticdesign.studies.plots import plt
from hapticdesign.studies.seed_reference import (
    RCUBE_FINAL,
    TABLE_7_2_SHORTEST,
    TABLE_7_3,
)
from hapticdesign.studies.steps import (
    Context,
    Outcome,
    Step,
    Table,
    figure_from_files,
    figure_from_matplotlib,
)

SCALES = ("full", "quick", "smoke")
MAP_METRICS = (names.MANIPULABILITY, names.CONDITION_NUMBER, names.INERTIA_FROBENIUS, names.STIFFNESS_FROBENIUS,
               names.STIFFNESS_VOLUME, names.FREQUENCY_INDEX)


@dataclass(frozen=True)
class RCubeSettings:
    """What a run covers: map resolution and the optimization's effort (``full`` = the seed's)."""

    scale: str = "full"
    seed: int = 1
    map_points: int = 21
    ik_points: int = 9
    optimization_effort: str = "full"

    @classmethod
    def for_scale(cls, scale: str, seed: int = 1) -> "RCubeSettings":
        if scale not in SCALES:
            raise UserError(f"unknown scale {scale!r}; choose one of {', '.join(SCALES)}")
        points, ik = {"full": (21, 9), "quick": (21, 7), "smoke": (7, 3)}[scale]
        return cls(scale=scale, seed=seed, map_points=points, ik_points=ik, optimization_effort=scale)

    def estimate_seconds(self) -> float:
        """Run time on a quiet 2-core machine with compiled kernels, dominated by the optimization chain.
        Measured warm (CPU time, which a quiet machine's wall time follows): quick 50 s, full 185 s (of which
        the chain 173 s in ``benchmarks/speed_table.py``; issue 28 saw `rcube optimize` take 238 s on a quiet
        machine); smoke runs a fraction of quick's work."""
        return {"full": 300.0, "quick": 75.0, "smoke": 40.0}[self.scale]


def _final():
    return final_design()


def kinematics_step(ctx: Context) -> Outcome:
    """Inverse then forward kinematics over the dexterous cube (eq. 5.28-5.45), q_max (eq. 6.24), Table 7.3."""
    design = _final()
    g = design.geometry
    n = ctx.settings.ik_points
    grid = rcube_kinematics.cube_grid(g, 0.12, n)
    q = rcube_kinematics.inverse_kinematics(g, grid)
    back = rcube_kinematics.forward_kinematics(g, q[..., 0])
    error = float(np.abs(back - grid).max())
    q_max = float(rcube_kinematics.q_max_for_cube(g, 0.12))
    dexterous = bool(rcube_kinematics.dexterous_cube(g, 0.12))
    rows = []
    for sol, l1, l2, l3, mu, cv in TABLE_7_3:
        geom = type(g)(l1 / 1e3, l2 / 1e3, l3 / 1e3)
        qm = rcube_kinematics.q_max_for_cube(geom)
        rows.append([sol, l1, l2, l3, mu, float(rcube_kinematics.critical_manipulability(geom, qm)), cv,
                     float(rcube_kinematics.critical_condition_number(qm))])
    return Outcome(
        summary=f"Final design l1, l2, l3 = {g.l1 * 1e3:.1f}, {g.l2 * 1e3:.1f}, {g.l3 * 1e3:.1f} mm: the 120 mm cube is "
                f"{'dexterous' if dexterous else 'NOT dexterous'}, q_max = {np.degrees(q_max):.2f} deg "
                f"(seed {RCUBE_FINAL['q_max_deg']} deg), IK then FK returns {n ** 3} cube points within {error:.1e} m.",
        tables=[Table("table_7_3", "Table 7.3, kinematic columns: seed against ours (eq. 6.8, 6.18)",
                      ["solution", "l1 [mm]", "l2 [mm]", "l3 [mm]", "mu_v seed", "mu_v ours", "c_v seed", "c_v ours"], rows)],
        numbers={"q_max_deg": float(np.degrees(q_max)), "ik_fk_max_error_m": error, "dexterous_cube": dexterous},
    )


CHAIN_COLOURS = ("#c0392b", "#27ae60", "#2e6fd8")
"""Frames of :func:`~hapticdesign.model.rcube.chain_mechanism` joined by the drawn links: base, l1, l2, l3."""


def device_figure(design, side: float = 0.12):
    """The design at home: each chain's links l1, l2, l3 from its base (eq. 5.2-5.18, the chain's own forward
    kinematics at the angles of eq. 5.30-5.45), the platform, the dexterous cube and a scale bar."""
    g = design.geometry
    fig = plt.figure(figsize=(6.0, 5.2))
    ax = fig.add_subplot(projection="3d", proj_type="ortho")
    points = [np.zeros(3)]
    for chain, (colour, path) in enumerate(zip(CHAIN_COLOURS, rcube_kinematics.chain_paths(g))):
        ax.plot(*path.T, color=colour, linewidth=3.5, solid_capstyle="round", label=f"chain {chain + 1}")
        ax.scatter(*path[:-1].T, s=14, color="#34495e", depthshade=False)
        ax.plot(*np.stack([np.zeros(3), path[0]]).T, color="#7f8c8d", linewidth=1.0, linestyle=":")
        points.append(path)
    ax.scatter(*g.home, s=50, color="#e67e22", depthshade=False, label="platform (home)")
    half = side / 2
    corners = np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)]) + g.home
    for i in range(8):
        for j in range(i + 1, 8):
            if np.count_nonzero(corners[i] != corners[j]) == 1:
                ax.plot(*corners[[i, j]].T, color="#95a5a6", linewidth=0.8)
    points = np.vstack(points + [corners])
    low, high = points.min(axis=0), points.max(axis=0)
    middle, span = 0.5 * (low + high), 0.55 * float((high - low).max())
    for set_limits, m in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), middle):
        set_limits(m - span, m + span)
    ax.set_box_aspect((1, 1, 1))
    start = middle - span
    ax.plot([start[0], start[0] + 0.05], [start[1]] * 2, [start[2]] * 2, color="black", linewidth=3.0)
    ax.text(start[0], start[1], start[2] + 0.04 * span, "50 mm", fontsize=8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.tick_params(labelsize=7)
    ax.legend(loc="upper left", fontsize=7)
    return fig


def device_step(ctx: Context) -> Outcome:
    """A picture of the final design at home with its dexterous cube (§5.1, Table 7.8)."""
    design = _final()
    g = design.geometry
    caption = (f"Table 7.8's design (l1, l2, l3 = {g.l1 * 1e3:.1f}, {g.l2 * 1e3:.1f}, {g.l3 * 1e3:.1f} mm, chain "
               f"offset S = {g.S * 1e3:.1f} mm) at home, the platform at ({', '.join(f'{v * 1e3:.1f}' for v in g.home)}) "
               "mm: each chain's base on its axis (dotted from the origin), its actuated link l1 and the passive links "
               "l2 and l3 to the platform, and the 120 mm cube the platform must reach (grey).")
    return Outcome(
        summary=f"The final design at home: three chains on the x, y and z axes carrying the platform at "
                f"{np.round(g.home * 1e3, 1).tolist()} mm.",
        figures=[figure_from_matplotlib(device_figure(design), "rcube_device", "The modified R-CUBE at home",
                                        caption)],
    )


SEED_PLIES = ((4, 7, 7), (2, 6, 6), (2, 6, 2))
"""Table 7.8's plies per link at 0, 90 and +-45 deg."""
SEED_RATIO = 0.75
"""The d/D of Tables 7.7-7.8 (e.g. 11.25/15)."""

SEED_EVALUATION = "passive joints eliminated, tubes evaluated as the seed did (seed_final_design)"
DEFLECTION_LOCKED = "max deflection, 5 N per axis, extended pose, passive joints locked (K_C*, eq. 6.60-6.61) [mm]"
DEFLECTION_FREE = ("max deflection, 5 N per axis, extended pose, passive joints free (K_C, eq. 5.121-5.123; "
                   "physical) [mm]")


def final_design_step(ctx: Context) -> Outcome:
    """The final design (Table 7.8) at home: mass, M_C, K_C, modes (eq. 7.6-7.13), deflection (Table 7.9)."""
    design = _final()
    g = design.geometry
    mass_g = 1e3 * design.total_link_mass()
    M_C = rcube_dynamics.cartesian_mass_matrix(design, g.home)
    K_C = rcube_stiffness.cartesian_stiffness(design, g.home)
    K_Cs = rcube_stiffness.cartesian_stiffness(design, g.home, passive=False)
    K_seed = rcube_stiffness.cartesian_stiffness(seed_final_design(), g.home)
    m = modes(M_C, K_Cs[:3, :3])
    extended = rcube_kinematics.critical_poses(g, rcube_kinematics.q_max_for_cube(g, 0.12))["extended"]
    load = np.array([5.0, 5.0, 5.0, 0.0, 0.0, 0.0])
    deflection = {p: 1e3 * float(np.linalg.norm(np.linalg.solve(rcube_stiffness.cartesian_stiffness(design, extended, passive=p), load)[:3]))
                  for p in (True, False)}
    seed = RCUBE_FINAL
    rows = [
        ["total link mass [g] (Table 7.9)", seed["link_mass_g"], mass_g, "density 1790 kg/m^3, a stated input (the value 77.7 g implies for Table 7.8's tubes)"],
        ["M_C diagonal [kg] (eq. 7.6)", seed["M_C_diagonal_kg"], M_C[0, 0], "structure reproduces, values do not"],
        ["M_C off-diagonal [kg] (eq. 7.6)", seed["M_C_off_diagonal_kg"], M_C[0, 1], ""],
        ["K_C translational diagonal [N/m] (eq. 7.7)", seed["K_C_translational_N_per_m"], K_seed[0, 0],
         f"{SEED_EVALUATION}; the physical design gives {K_C[0, 0]:.4g} (K_C*: {K_Cs[0, 0]:.4g})"],
        ["K_C rotational diagonal [N m/rad] (eq. 7.7)", seed["K_C_rotational_Nm_per_rad"], K_seed[3, 3],
         f"{SEED_EVALUATION}; the physical design gives {K_C[3, 3]:.4g} (K_C*: {K_Cs[3, 3]:.4g})"],
        ["K_C coupling (1,6) [N] (eq. 7.7)", seed["K_C_coupling_N"], K_seed[0, 5],
         f"{SEED_EVALUATION}; the physical design gives {K_C[0, 5]:.4g}"],
        *[[f"natural frequency {i + 1} [rad/s] (eq. 7.11-7.13)", seed["natural_frequencies_rad_s"][i], m.frequencies[i],
           "ours from our M_C and K_C*"] for i in range(3)],
        [DEFLECTION_LOCKED, seed["max_deflection_mm"], deflection[False], "seed: 'below'; the seed's evaluation (eq. 6.91)"],
        [DEFLECTION_FREE, None, deflection[True], "not given by the seed; the physical deflection"],
    ]
    return Outcome(
        summary=f"Final design: {mass_g:.1f} g of links (seed {seed['link_mass_g']} g); eq. 7.7's K_C reproduces as "
                f"{K_seed[0, 0]:.6g} N/m and {K_seed[3, 3]:.4g} N m/rad (seed {seed['K_C_translational_N_per_m']:.6g}, "
                f"{seed['K_C_rotational_Nm_per_rad']:.4g}) with the seed's evaluation of the tubes.",
        paragraphs=["The seed's eq. 7.7 is reproduced by the passive-eliminated K_C (eq. 5.121-5.123) only when Table "
                    "7.8's diameters are used where the section formulas take radii and the +-45 degree plies take "
                    "eq. 5.175's printed shear modulus (`seed_final_design`); the physical design is much softer. "
                    "M_C, the modes from our M_C and the deflection limit do not reproduce: docs/rcube.md gives the "
                    "hypotheses tried and their numbers."],
        tables=[Table("final_design", "Final design (Table 7.8) at home: seed against ours",
                      ["quantity", "seed", "ours", "note"], rows),
                Table("stiffness", "Cartesian stiffness K_C (passive joints eliminated, eq. 5.121-5.123) at home",
                      ["row", *[f"c{j + 1}" for j in range(6)]], [[f"r{i + 1}", *K_C[i]] for i in range(6)])],
        numbers={"link_mass_g": mass_g, "M_C": M_C, "K_C_locked_diagonal": float(K_Cs[0, 0]),
                 "K_C_seed_evaluation": K_seed,
                 "natural_frequencies_rad_s": m.frequencies, "max_deflection_mm_locked": deflection[False],
                 "max_deflection_mm_eliminated": deflection[True]},
    )


def maps_step(ctx: Context) -> Outcome:
    """Metric maps over three planes of the workspace (§7.5, Figures 7.5-7.19) and their global values (eq. 4.108)."""
    design = _final()
    n = ctx.settings.map_points
    offsets = (-0.06, 0.0, 0.06)
    planes = rcube_metrics.workspace_maps(design, n=n, offsets=offsets)
    extent = (-60, 60, -60, 60)
    figures = []
    for name in MAP_METRICS:
        fig, axes = plt.subplots(1, 3, figsize=(11, 3.4), constrained_layout=True)
        for ax, o, maps in zip(axes, offsets, planes):
            draw_map(fig, ax, maps[name], extent, f"{name} [{names.METRICS[name].unit}]")
            ax.set_title(f"plane z {o * 1e3:+.0f} mm")
            ax.set_xlabel("x [mm]")
            ax.set_ylabel("y [mm]")
        label, unit = names.METRICS[name]
        figures.append(figure_from_matplotlib(
            fig, f"map_{name}", f"{label[0].upper()}{label[1:]} over the workspace of the final design",
            f"Table 7.8's design on the planes z = -60, 0, +60 mm through the 120 mm cube (§7.5), {n} x {n} points "
            f"per plane; colour: {name} in {unit}, scaled between the 2 % and 98 % points of its values (the few beyond "
            f"in their own colours, counted in the legend); grey cells are unreachable or singular poses."))
    merged = {k: np.concatenate([p[k].ravel() for p in planes]) for k in planes[0]}
    glob = global_indices(merged)
    rows = [[k, float(v), names.METRICS[k].unit, names.METRICS[k].description] for k, v in glob.items()]
    return Outcome(
        summary=f"{len(planes[0])} metrics on 3 planes of {n} x {n} points; {len(MAP_METRICS)} shown.",
        tables=[Table("global", "Global indices over the three planes (eq. 4.108)",
                      ["metric", "global value", "unit", "definition"], rows)],
        figures=figures,
        numbers={"global": {k: float(v) for k, v in glob.items()}},
    )


def _chain_settings(effort: str):
    return {"full": Settings(), "quick": Settings.quick().with_population(60, 40), "smoke": Settings.quick()}[effort]


COLUMN_NAMES = {
    "O1": "O1 = tan q_max [-]", "O2": "O2 = det M_C [kg^3]", "O3": "O3 = 1/det K_CA [m^3/N^3]",
    **{name: f"{name} [{names.METRICS[name].unit}]" for name in TABLE_7_3_METRICS},
}
"""Display names with units of the optimization CSV columns (eq. 6.82-6.84, Table 7.3)."""

SPEC_NAMES = {
    "total_link_mass_g": "total link mass [g]",
    "max_deflection_mm": "max deflection, passive joints free (K_C, physical) [mm]",
    "max_deflection_locked_mm": "max deflection, passive joints locked (K_C*) [mm]",
}


def _column(name: str) -> str:
    """A CSV column name with its unit in brackets (``l1_mm`` -> ``l1 [mm]``)."""
    if name in COLUMN_NAMES:
        return COLUMN_NAMES[name]
    for suffix, unit in (("_mm", "mm"), ("_deg", "deg"), ("_kg", "kg"), ("_g", "g")):
        if name.endswith(suffix):
            return f"{name[: -len(suffix)]} [{unit}]"
    return name


def _csv_table(path, name: str, title: str, note: str = "") -> Table:
    import csv

    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))
    body = [[_number(SPEC_NAMES.get(v, v)) for v in row] for row in rows[1:]]
    return Table(name, title, [_column(c) for c in rows[0]], body, note)


def _number(text: str):
    try:
        return float(text)
    except ValueError:
        return text


def _figure_texts(result, found: dict) -> dict[str, tuple[str, str]]:
    """Title and caption of each figure the chain writes, from the run's own numbers."""
    sel, w = found["selected"]["solution"], result.selection.weight
    least = found["rms_choice"]
    weighted = ", ".join(f"{float(k):g}: {v}" for k, v in found["weighted_choice"].items())
    plies = found["plies"]
    total_plies = int(sum(n0 + n90 + 2 * n45 for n0, n90, n45 in plies["counts"]))
    rule = f"weight {w:g} on mu_vn* (Table 7.5)"
    return {
        "pareto_front_synthesis": (
            "Pareto front of the kinematic synthesis (eq. 6.82-6.84)",
            f"The {found['front_size']} non-dominated designs with l1 + l2 + l3 < 400 mm from NSGA-II over Table 7.1's "
            "three bound sets. O1 = tan q_max (also the colour, dimensionless); O2 = det M_C in kg^3 with two active "
            "links folded; O3 = 1/det K_CA in m^3/N^3 at full extension, plotted in 1e-15 m^3/N^3."),
        "figure_7_1_frequency_vs_manipulability": (
            "Figure 7.1: normalized natural-frequency index against normalized manipulability index",
            f"Each point is a front design; both indices are normalized by eq. 7.1-7.4 so that 0 is best. Ring: "
            f"solution {least}, the least RMS of the two (Figure 7.2's rule). Star: solution {sel}, the selected one, "
            f"the least weighted RMS with {rule}; at weight 0 that is the highest natural-frequency index, the "
            "seed's choice (§7.2)."),
        "figure_7_2_rms": (
            "Figure 7.2: RMS of the normalized frequency and manipulability indices per front solution",
            f"Solutions are numbered by total link length. The RMS (eq. 7.2-7.4) is least at solution {least}; the "
            f"dashed line marks the selected solution {sel}, chosen by the weighted RMS with {rule}, not by "
            "this curve."),
        "figure_7_3_weighted_rms": (
            "Figure 7.3: weighted RMS for the weights of Table 7.5",
            f"One curve per weight on mu_vn*, its least value ringed (weight: solution {weighted}); dashed: the "
            f"selected solution {sel}, chosen with {rule}."),
        "figure_7_4_cross_section": (
            "Figure 7.4: inner-to-outer diameter ratio of the links (eq. 6.85-6.90)",
            f"Left: RMS of the normalized CS1 = 1/S_l and CS2 = I_l along the NSGA-II front of d/D; its least value "
            f"gives d/D = {found['ratio']:.4f} (seed 0.768). Right: the normalized front, the chosen point in red."),
        "pareto_front_plies": (
            "Ply front: translational deflection against the number of plies (eq. 6.91-6.96)",
            f"CF1 is chain 1's translational deflection under 20 N at full extension with passive joints locked "
            f"(K_C1*). Red: the chosen design ({total_plies} plies, CF1 = {plies['CF1_mm']:.3g} mm), the fewest plies "
            f"with CF1 at most {1e3 * result.ply_limit:.3g} mm."),
    }


def _optimization_figures(out, result, found: dict) -> list:
    """The chain's figures with written titles and captions."""
    texts = _figure_texts(result, found)
    return [figure_from_files(out / stem, stem, title, caption) for stem, (title, caption) in texts.items()
            if (out / f"{stem}.png").exists() and (out / f"{stem}.svg").exists()]


def _design_row(label: str, l1: float, l2: float, l3: float, q_max: float, workspace) -> list:
    """A design in mm and degrees with its Constraint 5 (eq. 6.47) and 8 (eq. 6.52, C1) values."""
    g = constraint_values([[q_max, l2, l3]], workspace)[0]
    return [label, 1e3 * l1, 1e3 * l2, 1e3 * l3, 1e3 * (l1 + l2 + l3), float(np.degrees(q_max)), float(g[2]), float(g[5])]


def _seed_shortest(workspace) -> list[list]:
    """The seed's two shortest designs (Table 7.2) evaluated with our constraints."""
    rows = []
    for sol, l1, l2, l3 in TABLE_7_2_SHORTEST:
        q = float(np.arcsin(workspace.half / (l1 / 1e3)))  # eq. 6.24; the printed l1 has more digits than q_max
        rows.append(_design_row(f"seed Table 7.2 Sol. {sol}", l1 / 1e3, l2 / 1e3, l3 / 1e3, q, workspace))
    return rows


def _shortest_table(found: dict) -> tuple[Table, str]:
    """The seed's shortest designs, the front's shortest and the certified minimum, with the
    constraints they sit on; and a paragraph on the seed's Constraint 5 at 65 and 64 mm."""
    printed, shifted = CubeWorkspace(), CubeWorkspace(0.120, 0.128)
    rows = _seed_shortest(printed)
    ours = [("front's shortest (NSGA-II)", found["shortest"])]
    if found.get("constrained_minimum"):
        ours.append(("certified constrained minimum (SLSQP, many starts)", found["constrained_minimum"]))
    rows += [_design_row(label, d["l1"], d["l2"], d["l3"], d["q_max"], printed) for label, d in ours]
    at_64 = [r[6] for r in _seed_shortest(shifted)]
    _, l1, l2, l3 = TABLE_7_2_SHORTEST[0]
    text = (f"At the printed 65 mm half edge of the virtual cube the seed's Sol. 1 and Sol. 2 break Constraint 5 "
            f"(eq. 6.47, cos^2 q_13 < 1 at C5) by {100 * rows[0][6]:.2f} % and {100 * rows[1][6]:.2f} %, and Sol. 1 also "
            f"Constraint 8 at C1 (sin(q_12 + q_13) = {rows[0][7]:+.4f} > 0). At 64 mm both meet Constraint 5 "
            f"(cos^2 q_13 - 1 = {at_64[0]:.1e} and {at_64[1]:.1e}); Sol. 1 sits exactly on it, with the elbow folded: "
            f"l1 - 64 = l3 - l2 = {l1 - 64:.1f} mm. Our front and the certified minimum meet every constraint at 65 mm, "
            "so they are slightly longer than the seed's Sol. 1.")
    table = Table("shortest", "Shortest designs: the seed's, the front's and the certified minimum (eq. 6.24)",
                  ["design", "l1 [mm]", "l2 [mm]", "l3 [mm]", "total [mm]", "q_max [deg]",
                   "constraint 5 at C5: cos^2 q_13 - 1 (<= 0)", "constraint 8 at C1: sin(q_12 + q_13) (<= 0)"], rows,
                  "Constraint values at the printed 65 mm virtual half edge; positive values break the constraint.")
    return table, text


def _o3_text(result) -> str:
    """Why O3 is ~1e-16 (eq. 6.84): its unit, with the stiffness scale taken from the front."""
    O3 = result.synthesis.front.F[:, 2]
    k = (1.0 / O3) ** (1.0 / 3.0)
    return (f"O3 = 1/det K_CA (eq. 6.84) is in m^3/N^3. At full extension the post-evaluation tube (D = 20 mm, "
            f"d = 10 mm) gives a translational stiffness (det K_CA)^(1/3) of {k.min():.3g} to {k.max():.3g} N/m on this "
            f"front, so O3 = 1/(det K_CA) lies between {O3.min():.3g} and {O3.max():.3g} m^3/N^3: it is small because of "
            "its unit, not because a term vanishes, and it varies along the front like O1 and O2 (the hypervolume "
            "scales each objective to [0, 1] over the front).")


def _mass_note(result, found: dict) -> str:
    """Why the selected design's link mass differs from Table 7.9's 77.7 g, from the run's own numbers."""
    density = result.design.links[0].density
    seed_design = ply_design(RCubeGeometry(*(v / 1e3 for v in TABLE_7_3[0][1:4])), SEED_PLIES, SEED_RATIO, density=density)
    ours = result.plies.counts[result.ply_choice]
    at_seed_ratio = ply_design(result.design.geometry, ours, SEED_RATIO, density=density)
    seed_g, seed_plies = 1e3 * seed_design.total_link_mass(), int(sum(a + b + 2 * c for a, b, c in SEED_PLIES))
    our_plies = int(sum(a + b + 2 * c for a, b, c in np.asarray(ours).reshape(3, 3)))
    return (f"Both at {density:g} kg/m^3 (the density Table 7.9's 77.7 g implies for Table 7.8's values read as "
            f"diameters; read as radii, as the seed's stiffness evaluation and D - d = ply stack imply, the same tubes "
            f"weigh {4 * seed_g:.1f} g). The seed's {seed_plies} plies at d/D = {SEED_RATIO} give {seed_g:.1f} g; our "
            f"{our_plies} plies give {1e3 * at_seed_ratio.total_link_mass():.1f} g at d/D = {SEED_RATIO} and "
            f"{1e3 * result.design.total_link_mass():.1f} g at our d/D = {found['ratio']:.4f}: the difference is the ply "
            "choice (our stiffness model) and the ratio.")


def _side_by_side(result, found: dict) -> Table:
    """The selected design against the seed's final design (Tables 7.2, 7.8, 7.9)."""
    sel, specs, seed = found["selected"], found["specifications"], RCUBE_FINAL
    rows = [
        ["l1 [mm] (Table 7.8)", 111.7, 1e3 * sel["l1"], ""], ["l2 [mm]", 74.1, 1e3 * sel["l2"], ""],
        ["l3 [mm]", 121.8, 1e3 * sel["l3"], ""], ["q_max [deg] (Table 7.2)", seed["q_max_deg"], sel["q_max_deg"], ""],
        ["diameter ratio d/D (§7.3)", 0.768, found["ratio"], "Tables 7.7-7.8 use 0.75; 0.768 is the minimum for an upper d/D limit of 0.9034 (0.7636 at 0.90)"],
        ["total link mass [g] (Table 7.9)", seed["link_mass_g"], specs.get("total_link_mass_g"), _mass_note(result, found)],
        [DEFLECTION_LOCKED, seed["max_deflection_mm"], specs.get("max_deflection_locked_mm"),
         "seed: 'below'; the seed's evaluation"],
        [DEFLECTION_FREE, None, specs.get("max_deflection_mm"), "not given by the seed; the physical deflection"],
    ]
    return Table("side_by_side", "Selected design against the seed's final design", ["quantity", "seed", "ours", "note"], rows)


def optimization_step(ctx: Context) -> Outcome:
    """Chapters 6-7: NSGA-II synthesis, selection, weighted-sum swarm, cross-section ratio, plies, final design."""
    settings = _chain_settings(ctx.settings.optimization_effort)
    result = run_chain(ctx.settings.seed, settings, progress=lambda step, done, total: ctx.update(done, total))
    out = ctx.work_dir / f"optimization_{ctx.settings.scale}"
    write_chain(out, result)
    found = chain_summary(result)
    sel = found["selected"]
    shortest, constraint_text = _shortest_table(found)
    tables = [_side_by_side(result, found), shortest]
    for stem, title, note in (
            ("table_7_2_front", "Pareto front of the kinematic synthesis (Table 7.2 layout)", _o3_text(result)),
            ("table_7_3_post_evaluation", "Post-evaluation of the front (Table 7.3 layout)",
             "S_f is the Frobenius norm of chain 1's 6 x 6 K_C1, whose entries are in N/m, N and N m/rad (SI); "
             "omega_n = ||M_C1^-1 K_C1A||_F is in 1/s^2."),
            ("table_7_5_weighted_rms", "Weighted RMS selection (Table 7.5 layout)", ""),
            ("table_7_6_7_plies", "Ply front (Tables 7.6-7.7 layout)",
             "link<k>_0, _90, _45: plies at 0, 90 and +-45 deg (as many at -45 as at +45); D, d from the ply stack."),
            ("table_7_8_final_design", "Final design (Table 7.8 layout)", ""),
            ("table_7_9_specifications", "Specifications (Table 7.9 layout)", "")):
        tables.append(_csv_table(out / f"{stem}.csv", stem, title, note))
    return Outcome(
        summary=f"Front of {found['front_size']} solutions (hypervolume {found['hypervolume']:.4g}); selected l1, l2, l3 = "
                f"{1e3 * sel['l1']:.1f}, {1e3 * sel['l2']:.1f}, {1e3 * sel['l3']:.1f} mm, d/D = {found['ratio']:.3f}.",
        paragraphs=[f"Effort: {ctx.settings.optimization_effort} (synthesis population {settings.population}, "
                    f"{settings.generations} generations; the seed-size run is the full form). Results are reproducible "
                    "from the seed. Before NSGA-II, the shortest feasible design is found by a direct constrained "
                    "minimization of l1 + l2 + l3 (SciPy SLSQP from seeded starts, checked by its KKT conditions) and "
                    "placed in the initial populations, so the front reaches it.", constraint_text],
        tables=tables, figures=_optimization_figures(out, result, found),
        numbers={"front_size": found["front_size"], "hypervolume": found["hypervolume"], "selected": sel,
                 "shortest": found["shortest"], "constrained_minimum": found["constrained_minimum"],
                 "ratio": found["ratio"], "specifications": found["specifications"]},
    )


def steps() -> list[Step]:
    return [
        Step("device", "The device (§5.1, Table 7.8)", device_step),
        Step("kinematics", "Kinematics and workspace (§5.1, Tables 7.2-7.3)", kinematics_step),
        Step("final_design", "Final design: stiffness, inertia, modes (Tables 7.8-7.9, eq. 7.6-7.13)", final_design_step),
        Step("maps", "CubeWorkspace maps of the metrics (§7.5, Figures 7.5-7.19)", maps_step),
        Step("optimization", "Optimization chain (ch. 6-7, Tables 7.1-7.9)", optimization_step),
    ]


TITLE = "Modified R-CUBE: impedance-oriented optimal design (seed 001)"
INTRO = ("Gorgulu (2018), end to end: kinematics and workspace, virtual-joint-method stiffness with composite links, "
         "Cartesian inertia and modes, workspace maps of the performance metrics, and the optimization chain, with the "
         "seed's printed numbers side by side with ours.")


def run(settings: RCubeSettings, work_dir, progress=None):
    from hapticdesign.studies.study import run_pipeline

    return run_pipeline("rcube", TITLE, INTRO, steps(), settings, work_dir, progress)
