"""Chapter 4 steps of the ``phantom`` study: rendering the default design, the 1-DOF stability check,
and the campaigns behind Tables 4.4 and 4.6 (seed 000 §4.1-4.2)."""

from __future__ import annotations

import hashlib
import inspect
import warnings
from pathlib import Path

import numpy as np

from hapticdesign.analysis.linearity.form import device_form
from hapticdesign.errors import PhysicalConsistencyWarning
from hapticdesign.files import csv_rows, write_atomically
from hapticdesign.model.inertia import SEED_FIELDS, seed_parameter_name
from hapticdesign.analysis.sampled_loop import SampledLoop, joint_limit
from hapticdesign.simulation.boundary import simulated_boundary
from hapticdesign.simulation.campaign import (
    CampaignOptions,
    load_cases,
    read_designs,
    run_campaign,
    summarize,
)
from hapticdesign.simulation.config import LoopConfig, Wall, rest_pose
from hapticdesign.simulation.impedance import Criteria, impedance_range, type_paths
from hapticdesign.simulation.loop import simulate
from hapticdesign.simulation.paths import Chirp
from hapticdesign.simulation.transparency import transparency
from hapticdesign.studies.phantom_explorer import campaign_explorer
from hapticdesign.studies.plots import plt
from hapticdesign.studies.seed_reference import (
    AGREEMENT,
    TABLE_4_4,
    TABLE_4_6,
    appendix_c_designs,
)
from hapticdesign.studies.steps import (
    Context,
    NotAvailable,
    Outcome,
    Table,
    figure_from_files,
    figure_from_matplotlib,
)


def wall_response(device, stiffness: float, duration: float = 5.0, step: float = 0.01):
    """The type 1 wall experiment of the stable-range searches (Table 4.2-4.3) on joint 1: every joint starts at
    the device's rest pose (0 for an open chain, ``home`` for a closed loop), the others held there, and the
    wall's spring rests ``step`` from joint 1's start."""
    rest = rest_pose(device)
    wall = Wall(0, stiffness, equilibrium=float(rest[0]) + step)
    return simulate(device, LoopConfig(duration=duration, wall=wall), type_paths(1, device.n_dof, 0, rest))


def default_design(ctx: Context) -> Outcome:
    """Maximum stable impedance (§4.1.2-4.1.3) and transparency bandwidth (§4.2.2-4.2.3), types 1 and 2."""
    device = ctx.settings.device()
    ranges = {t: impedance_range(device, t, k_limit=ctx.settings.k_limit) for t in (1, 2)}
    resolution = 1.0
    if ranges[1].k_max < 1:  # below the seed's integer grid: find the range on a finer one
        resolution = 0.01
        ranges = {t: impedance_range(device, t, k_limit=ctx.settings.k_limit, resolution=resolution) for t in (1, 2)}
    ctx.update(1, 3)
    k = ranges[1].k_max
    seed_stiffness = 4.0
    stiffness = seed_stiffness if k >= seed_stiffness or k == 0 else k
    bands = {t: transparency(device, t, stiffness) for t in (1, 2)}
    ctx.update(2, 3)
    overshoot = Criteria().overshoot_limit
    start = float(rest_pose(device)[0])
    fig, ax = plt.subplots(figsize=(7, 3.8))
    for gain, style in ((k, "-"), (k + resolution, "--")):
        trace = wall_response(device, float(gain))
        ax.plot(trace.t, trace.q[:, 0], style, label=f"K = {gain:g} N m/rad")
    ax.axhline(start + overshoot, color="grey", lw=0.8, ls=":",
               label=f"overshoot limit ({overshoot:g} rad from the start)")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("theta1 [rad]")
    ax.legend()
    wall_fig = figure_from_matplotlib(fig, "wall_response", "Virtual wall on joint 1, type 1",
                                      f"at the maximum stable stiffness and one grid step ({resolution:g} N m/rad) above it")
    fig, ax = plt.subplots(figsize=(7, 3.8))
    for t, result in bands.items():
        ax.semilogx(result.frequency, 20 * np.log10(np.abs(result.g_t)), label=f"type {t}")
    for edge in (3.0, -3.0):
        ax.axhline(edge, color="grey", lw=0.8, ls="--")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|G_T| = |Z_M / Z_D| [dB]")
    ax.legend()
    gt_fig = figure_from_matplotlib(fig, "transparency", "Transparency of the default design (eq. 4.2, Figure 4.18 layout)")
    ctx.update(3, 3)
    rows = [[f"type {t}", ranges[t].k_max, ranges[t].criterion, bands[t].bandwidth_hz] for t in (1, 2)]
    damping = ", ".join(f"{b:.2f}" for b in device.damping)
    if stiffness == seed_stiffness and k < seed_stiffness:
        wall_note = (f"Warning: K = {seed_stiffness:g} N m/rad, the seed's transparency stiffness, is not stable for this "
                     f"design (K_max = {k:g} N m/rad); the bandwidths below are those of an unstable wall.")
    elif stiffness != seed_stiffness:
        wall_note = (f"Transparency is computed at K = {stiffness:g} N m/rad, this design's largest stable stiffness, "
                     f"because the seed's K = {seed_stiffness:g} N m/rad is not stable for it.")
    else:
        wall_note = f"Transparency is computed at the seed's K = {seed_stiffness:g} N m/rad, stable for this design."
    settings = _settings_table(device, LoopConfig(), type_paths(2, device.n_dof)[1])
    same = ranges[1].k_max == ranges[2].k_max
    ln = float(device_form(device).ln(device.standard_parameters()))
    if ln < 1e-12:
        finding = (f"The design is exactly linear (LN = {ln:.1e}), so the seed's finding that linear designs give the "
                   "same results in types 1 and 2 predicts equal columns: " + ("they are equal." if same else "they differ."))
    else:
        finding = f"The design has LN = {ln:.3g}; its type 1 and type 2 results " + ("agree." if same else "differ.")
    return Outcome(
        summary=f"{device.name}: maximum stable impedance {ranges[1].k_max:g} / {ranges[2].k_max:g} N m/rad and "
                f"transparency bandwidth {_hz(bands[1].bandwidth_hz)} / {_hz(bands[2].bandwidth_hz)} (type 1 / type 2).",
        paragraphs=[
            f"Settings used: this device's joint damping {damping} N m s/rad (the seed's Table 4.1 has 0.50, 0.50, "
            "0.35 for the Phantom), plant step 1e-4 s, 1 kHz sampling with zero-order hold, wall equilibrium 0.01 rad "
            "(Table 4.2), overshoot limit 0.012 rad of excursion from the start (checked at every plant step), "
            "settling within 5 s, safety switch at 0.06 rad; transparency with a 0.3 rad chirp from 0.1 to 15 Hz over "
            f"10 s. Stiffness grid: {resolution:g} N m/rad" + (" (the seed's integer scan)." if resolution == 1 else
                                                                 " (no integer stiffness is stable)."),
            wall_note,
            finding,
        ],
        tables=[settings, Table("default_design", "Joint 1 of the design", ["simulation", "K_max [N m/rad]",
                                                                                "limiting criterion", "bandwidth [Hz]"], rows)],
        figures=[wall_fig, gt_fig],
        numbers={"k_max_type1": ranges[1].k_max, "k_max_type2": ranges[2].k_max, "resolution": resolution,
                 "transparency_stiffness": stiffness,
                 "bandwidth_hz_type1": bands[1].bandwidth_hz, "bandwidth_hz_type2": bands[2].bandwidth_hz},
    )


def _settings_table(device, config, driven) -> Table:
    """Seed 000 Tables 4.1-4.3 and 4.5 beside the values the simulation engine used."""
    criteria, chirp = Criteria(), Chirp()
    equilibrium = inspect.signature(impedance_range).parameters["equilibrium"].default
    rows = [
        ["joint damping [N m s/rad] (Table 4.1)", "0.50, 0.50, 0.35", ", ".join(f"{b:.2f}" for b in device.damping)],
        ["wall equilibrium [rad] (Table 4.2)", 0.01, equilibrium],
        ["type 2 path of joints 2, 3 [rad] (Table 4.3)", "0.52 sin(3 pi t)",
         f"{driven.amplitude:g} sin({driven.omega / np.pi:g} pi t)"],
        ["overshoot limit [rad] (§4.1.3)", 0.012, criteria.overshoot_limit],
        ["safety switch [rad] (Figure 4.7)", 0.06, criteria.safety_limit],
        ["sample period [s] / plant step [s]", "0.001 / 0.0001", f"{config.loop.period:g} / {config.step:g}"],
        ["chirp (Table 4.5)", "0.3 rad, 0.1-15 Hz, 10 s",
         f"{chirp.amplitude:g} rad, {chirp.f0:g}-{chirp.f1:g} Hz, {chirp.sweep_time:g} s"],
    ]
    return Table("settings", "Simulation settings: the seed's (Tables 4.1-4.3, 4.5) beside the engine's",
                 ["setting", "seed", "used here"], rows)


def _hz(value) -> str:
    return "above 15 Hz" if value is None else f"{value:.2f} Hz"


def boundary(ctx: Context) -> Outcome:
    """The check any sampled-data simulator must pass: exact (spectral radius) against simulated boundary
    of a 1-DOF mass-damper under a zero-order-hold spring."""
    cases = [(0.003, 0.5, 1e-3), (0.01, 0.35, 1e-3), (0.003, 0.5, 5e-4)]
    if ctx.settings.scale == "smoke":
        cases = cases[:1]
    rows, worst = [], 0.0
    for i, (j, b, t) in enumerate(cases):
        loop = SampledLoop(period=t, delay=0, velocity="sampled", compensation="none")
        exact, simulated = joint_limit(j, b, loop), simulated_boundary(j, b, loop)
        rel = abs(simulated - exact) / exact
        worst = max(worst, rel)
        rows.append([j, b, t, exact, 2 * b / t, simulated, rel])
        ctx.update(i + 1, len(cases))
    return Outcome(
        summary=f"Simulated and exact stability boundaries agree within {100 * worst:.2f} %.",
        paragraphs=["A 1-DOF inertia J with damping b under a zero-order-hold spring sampled every T (no delay, no "
                    "compensation): the exact limit is the stiffness where the spectral radius of the exactly "
                    "discretized loop reaches 1 (about 2b/T)."],
        tables=[Table("mass_damper", "1-DOF stability boundary", ["J [kg m^2]", "b [N m s/rad]", "T [s]",
                                                                    "K exact [N m/rad]", "2b/T", "K simulated", "relative difference"], rows)],
        numbers={"max_relative_difference": worst},
    )


def _appendix_c_csv(ctx: Context, path: Path, per_level: int) -> None:
    """Appendix C's designs as a campaign design file (link 1 from the built-in default, as eq. 3.33 prints it),
    written as every output is (:func:`~hapticdesign.files.write_atomically`: a link planted at ``path`` is replaced,
    never followed; a named pipe there is refused)."""
    device = ctx.settings.device()
    form = device_form(device)
    names = device.inertial_names()
    first = [seed_parameter_name(f, device.body_names[0]) for f in SEED_FIELDS]
    link1 = {k: float(device.params.get(k, 0.0)) for k in first}
    chosen, seen = [], {}
    for i, d in enumerate(appendix_c_designs()):
        seen[d["level"]] = seen.get(d["level"], 0) + 1
        if seen[d["level"]] <= per_level:
            chosen.append((f"C{i + 1:02d}", d))
    rows = []
    for name, d in chosen:
        params = {**{k: 0.0 for k in names}, **link1, **d["params"]}
        parts = form.parts_seed(np.array([params[k] for k in names]))
        rows.append([name, d["level"], parts.sum(), *parts, *(params[k] for k in names)])
    write_atomically(path, csv_rows(["design", "level", "ln", "ln_H", "ln_C", "ln_G", *names], rows))


def campaign(ctx: Context) -> Outcome:
    """Both criteria and both types over the design sets (rigid-body realizable designs)."""
    designs_csv = ctx.shared.get("designs_csv")
    if designs_csv is None:
        raise NotAvailable("this campaign runs over the design sets, whose step did not finish")
    return _campaign(ctx, designs_csv, "the design sets of the design-set step (every design a realizable rigid body)",
                     explore=True)


def campaign_appendix_c(ctx: Context) -> Outcome:
    """Both criteria and both types over the seed's own printed designs (Appendix C, 5 per level)."""
    per_level = ctx.settings.appendix_c_per_level
    designs_csv = ctx.work_dir / f"appendix_c_{per_level}.csv"
    _appendix_c_csv(ctx, designs_csv, per_level)
    return _campaign(ctx, designs_csv, f"the seed's own Appendix C designs ({per_level} per level; link 1, which "
                                       "Appendix C does not print, as in eq. 3.33). They satisfy eq. 3.28 only: every "
                                       "one breaks the triangle inequality in some link")


def _campaign(ctx: Context, designs_csv: Path, source: str, explore: bool = False) -> Outcome:
    """Run (or resume) a campaign and lay its results beside Tables 4.4, 4.6 and Figures 4.9-4.11, 4.18-4.21; with
    ``explore``, its designs in the design explorer too (:func:`~hapticdesign.studies.phantom_explorer.
    campaign_explorer`)."""
    s = ctx.settings
    digest = hashlib.sha1(Path(designs_csv).read_bytes()).hexdigest()[:12]
    out = ctx.work_dir / f"campaign_{digest}"  # a rerun with the same designs resumes; other designs start afresh
    options = CampaignOptions(preset=s.preset, k_limit=s.k_limit)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicalConsistencyWarning)
        try:
            counts = run_campaign(designs_csv, out, options, workers=s.workers, progress=ctx.update, quiet=True)
        except RuntimeError:  # a local Dask worker that failed to start (seen under heavy load): resume once
            counts = run_campaign(designs_csv, out, options, workers=s.workers, progress=ctx.update, quiet=True)
        designs = read_designs(designs_csv, s.preset)
    cases = load_cases(designs, out)
    summary = summarize(designs, cases, options)
    tables = [_side_by_side(summary, "impedance", TABLE_4_4, "Table 4.4", "N m/rad"),
              _side_by_side(summary, "transparency", TABLE_4_6, "Table 4.6", "Hz"),
              _agreement(summary)]
    figures = [figure_from_files(out / "figures" / stem, stem, title) for stem, title in (
        ("impedance_beeswarm_type1", "Maximum stable impedance against LN, type 1 (Figure 4.9)"),
        ("impedance_type1_vs_type2", "Maximum stable impedance, type 1 against type 2 (Figure 4.10)"),
        ("impedance_agreement", "Same maximum stable impedance in types 1 and 2 (Figure 4.11)"),
        ("transparency_beeswarm_type1", "Transparency bandwidth against LN, type 1 (Figure 4.19)"),
        ("transparency_type1_vs_type2", "Transparency bandwidth, type 1 against type 2 (Figure 4.20)"),
        ("transparency_agreement", "Same transparency bandwidth in types 1 and 2 (Figure 4.21)"),
        ("transparency_frequency_response", "|G_T| against frequency, one design per level (Figure 4.18)"))]
    zero = [r for r in summary if r["level"] == 0.0]
    return Outcome(
        summary=f"{len(designs)} designs, {counts['cases']} simulations ({counts['run']} run now, {counts['skipped']} "
                f"reused from an earlier run).",
        paragraphs=[f"Designs: {source}.",
                    "The seed used 100 designs per level; with fewer designs the ranges are narrower and the means "
                    "less certain. Our simulations follow the seed's stated settings; its Simulink model leaves "
                    "details unstated (see docs/studies.md)."],
        tables=tables, figures=figures,
        numbers={"designs": len(designs), "cases": counts["cases"],
                 "agreement_level0": {r["criterion"]: r["agreement_share"] for r in zero if r["type"] == 1},
                 "summary": summary},
        explorer=campaign_explorer(designs, cases, s.preset) if explore else None,
    )


def _side_by_side(summary, criterion: str, seed_table: dict, name: str, unit: str) -> Table:
    rows = []
    for r in (r for r in summary if r["criterion"] == criterion and r["type"] == 1):
        seed = seed_table.get(r["level"])
        rows.append([r["level"], f"{seed[0]:g} - {seed[1]:g}" if seed else "", seed[2] if seed else None,
                     seed[3] if seed else None, r["n"], _range(r), r["mean"], r["std"]])
    return Table(f"{criterion}_type1", f"{name}, type 1: seed against ours [{unit}]",
                 ["LN", "seed range", "seed mean", "seed 1 sigma", "our designs", "our range", "our mean", "our 1 sigma"],
                 rows, note="The seed's values are for 100 designs per level.")


def _range(row) -> str:
    return "" if row["min"] is None else f"{row['min']:.3g} - {row['max']:.3g}"


def _agreement(summary) -> Table:
    rows = []
    for r in (r for r in summary if r["type"] == 1):
        seed = AGREEMENT[r["criterion"]].get(r["level"])
        rows.append([r["criterion"], r["level"], seed, r["agreement_share"]])
    return Table("agreement", "Share of designs with equal type 1 and type 2 results (Figures 4.11, 4.21)",
                 ["criterion", "LN", "seed share", "our share"], rows,
                 note="The seed's text gives the shares at LN = 0, 0.001 and 2 only.")
