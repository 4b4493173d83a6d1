"""Commands ``impedance-range``, ``transparency``, ``stability-boundary`` and ``campaign`` (seed 000 ch. 4)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np
import typer

from hapticdesign.interface.options import DEVICE, FORCE, FORCE_HINT, JSON_OUT, PARAMS, PRESET, QUIET, STRICT
from hapticdesign.errors import UserError
from hapticdesign.interface.common import (joint_units, note, parse_vector, print_json, progress_bar,
                                           user_errors, write_atomically)
from hapticdesign.workload import allow_large



def _sim_type(value: int) -> int:
    if value not in (1, 2):
        raise UserError(f"--type must be 1 or 2, got {value}")
    return value


# Options shared by the device-level commands.
PERIOD = typer.Option(1e-3, help="Sample period T of the digital side [s].")
STEP = typer.Option(1e-4, help="Plant integration step [s]; must divide the period.")
STEP_CONTROL = typer.Option(
    "auto", help="fixed (RK4 at --step, the seed's), adaptive (RK4 over several plant steps within a sample period "
                 "while its local error estimate stays below 1e-9) or auto (fixed for open chains, adaptive for "
                 "closed-loop devices).")
COUNTS = typer.Option(None, help="Encoder counts per revolution (position quantization); none by default.")
DELAY = typer.Option(0, help="Sensor delay in samples.")
ERROR = typer.Option(0.0, help="Compensator modelling error in percent (scales its inertial parameters).")
INERTIAL = typer.Option(True, "--inertial/--no-inertial", help="Keep the inertial term H qdd of --compensation full.")
CORIOLIS = typer.Option(True, "--coriolis/--no-coriolis", help="Keep the Coriolis term C qd^2 of --compensation full.")
GRAVITY = typer.Option(True, "--gravity/--no-gravity", help="Keep the gravity term G of --compensation.")
WALL_DAMPING = typer.Option(0.0, help="Virtual wall damper [N m s/rad; N s/m for a Cartesian wall].")
WALL_DIRECTION = typer.Option(
    None, help="Cartesian wall: its direction x,y,z at the handle (K in N/m, damper in N s/m, equilibrium and "
               "criteria in m along it; --joint is the joint left free). Default: a wall on --joint.")


HAND_MASS = typer.Option(0.0, help="Hand mass at the handle [kg] (off by default).")
HAND_DAMPING = typer.Option(0.0, help="Hand damping at the handle [N s/m].")
HAND_STIFFNESS = typer.Option(0.0, help="Hand stiffness at the handle [N/m].")


SETTINGS = typer.Option(
    None, help="Loop settings: practice (1 kHz, one sample of delay, backward-difference velocity, gravity "
               "compensation; every other device's default) or seed (full inverse-dynamics compensation, no delay, "
               "sampled velocity; the default of the seed's Phantom presets). The options below change single ones.")
COMPENSATION = typer.Option(None, help="none, gravity or full (inverse dynamics with the sampled acceleration); "
                                       "default: the --settings' own.")
VELOCITY = typer.Option(None, help="The wall damper's velocity: difference (backward difference of positions) or "
                                   "sampled; default: the --settings' own.")
HOLD = typer.Option(None, help="Joints held fixed under the limit method (e.g. 2,3); default: every joint free.")


def seed_settings(device, settings: Optional[str]) -> bool:
    """Whether a command uses the seed's settings: asked for, or by default where the device's source says so
    (:attr:`~hapticdesign.model.device.PresetData.loop_settings`: the seed's Phantom presets); ``device`` None is a
    bare loop, practice's."""
    if settings not in (None, "practice", "seed"):
        raise UserError(f"--settings must be practice or seed, got {settings!r}")
    if settings is not None:
        return settings == "seed"
    return device is not None and device.preset_data.loop_settings == "seed"


def sampled_loop(seed: bool, period: float, delay: Optional[int], velocity: Optional[str],
                 compensation: Optional[str], error_percent: float, wall_damping: float, hand_mass: float = 0.0,
                 hand_damping: float = 0.0, hand_stiffness: float = 0.0, held: tuple[int, ...] = ()):
    """The one loop record of a command's options: the seed's or practice's settings with the options given."""
    from hapticdesign.analysis.sampled_loop import Hand, SampledLoop

    changes = {"period": period, "error_percent": error_percent, "wall_damping": wall_damping,
               "hand": Hand.optional(hand_mass, hand_damping, hand_stiffness), "held": held,
               **{k: v for k, v in (("delay", delay), ("velocity", velocity), ("compensation", compensation))
                  if v is not None}}
    return SampledLoop.seed(**changes) if seed else SampledLoop(**changes)


def impedance_range_command(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    sim_type: int = typer.Option(1, "--type", help="Seed's criteria: 1 other joints held at 0; 2 driven at "
                                                   "0.52 sin(3 pi t)."),
    joint: str = typer.Option("1", help="Joint carrying the virtual wall (1-based or coordinate name)."),
    equilibrium: Optional[float] = typer.Option(
        None, help="Wall equilibrium from the start [rad, or m along --wall-direction]: where the wall holds the "
                   "device and the limit is taken. Default: 0 (the home pose, as spec) for the limit method, the "
                   "seed's 0.01 step for the seed's criteria."),
    wall_direction: Optional[str] = WALL_DIRECTION,
    settings: Optional[str] = SETTINGS,
    method: Optional[str] = typer.Option(
        None, help="limit (the stability limit of the sampled loop at the wall's equilibrium, every joint free: "
                   "practice's default), or the seed's performance criteria (overshoot, settling) on runs: fast "
                   "(doubling + bisection; the seed presets' default), linear (K = 1, 2, 3, ...) or analytic (the "
                   "exact linear response, no ODE integration)."),
    resolution: Optional[float] = typer.Option(
        None, help="Stiffness grid R, 2R, 3R ... [N m/rad, N/m for a prismatic joint or a Cartesian wall]; "
                   "reports k_min and k_max on it. Default: the integer grid 1, 2, 3 ..."),
    k_limit: int = typer.Option(200, help="Largest stiffness tried [N m/rad, or N/m]."),
    overshoot: float = typer.Option(0.012, help="Overshoot limit, peak excursion from the start, for the seed's "
                                                "0.01 step [rad]; the limits scale with --equilibrium."),
    settle_tolerance: float = typer.Option(0.002, help="Settled: within this of the equilibrium at the end, for "
                                                       "the seed's 0.01 step [rad]."),
    settle_window: float = typer.Option(0.5, help="Final window checked for settling [s]."),
    safety: float = typer.Option(0.06, help="Safety switch excursion for the seed's 0.01 step [rad] (Figure 4.7)."),
    true_boundary: bool = typer.Option(False, "--true-boundary", help="Also bisect the oscillation-growth boundary "
                                       "(the limit method: simulated with the file's dry friction and quantization)."),
    duration: float = typer.Option(5.0, help="Simulated time per stiffness [s]."),
    period: float = PERIOD, step: float = STEP, step_control: str = STEP_CONTROL, counts: Optional[int] = COUNTS,
    delay: Optional[int] = typer.Option(None, help="Sensor delay in samples (default: the --settings' own)."),
    velocity: Optional[str] = VELOCITY, compensation: Optional[str] = COMPENSATION, error_percent: float = ERROR,
    wall_damping: float = WALL_DAMPING, hand_mass: float = HAND_MASS, hand_damping: float = HAND_DAMPING,
    hand_stiffness: float = HAND_STIFFNESS, hold: Optional[str] = HOLD,
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Maximum stable impedance of a virtual wall on a joint or at the handle (seed 000 §4.1.2-4.1.3).

    Practice's default is the stability limit of the sampled loop; the seed's Phantom presets keep the seed's
    settings and performance criteria. The output states the settings and the verdict used."""
    from hapticdesign.analysis.stiffness.drive import compliances
    from hapticdesign.simulation.config import LoopConfig, unit_direction
    from hapticdesign.simulation.impedance import Criteria, impedance_range
    from hapticdesign.simulation.loop import joint_index

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        from hapticdesign.devices.loading import resolve_device

        dev = resolve_device(preset, device, params, strict=strict)
        seed = seed_settings(dev, settings)
        method = method or ("fast" if seed else "limit")
        if equilibrium is None:
            equilibrium = 0.0 if method == "limit" else 0.01
        held = () if hold is None else tuple(joint_index(dev, j) for j in hold.replace(" ", "").split(",") if j)
        loop = sampled_loop(seed, period, delay, velocity, compensation, error_percent, wall_damping, hand_mass,
                            hand_damping, hand_stiffness, held)
        limit = method == "limit"  # runs no plant steps of its own: the step is the period
        config = LoopConfig(duration=duration, step=loop.period if limit else step, loop=loop, counts=counts,
                            step_control=step_control)
        direction = None if wall_direction is None else parse_vector(wall_direction, 3, "wall-direction")
        wall_joint = joint_index(dev, joint)
        result = impedance_range(dev, _sim_type(sim_type), method, k_limit,
                                 Criteria(overshoot, settle_tolerance, settle_window, safety), config, wall_joint,
                                 equilibrium, resolution, direction, true_boundary and not limit,
                                 simulate=true_boundary and limit)
        compliance = compliances(dev)
        out = {"device": dev.name, "type": sim_type, "joint": wall_joint + 1,
               **({} if direction is None else {"wall_direction": unit_direction(direction).tolist()}),
               "settings": loop.as_dict(), "compliance": compliance if limit else "rigid", **result.as_dict()}
        unit = {"stiffness": "N/m", "position": "m"} if direction is not None else joint_units(dev)[wall_joint]
        out["units"] = {"k_max": unit["stiffness"], "k_min": unit["stiffness"], "peak_at_first_unstable": unit["position"],
                        "stopped_at_first_unstable": "s"}
        if json_out:
            print_json(out)
            return
        lowest = "" if out["k_min"] is None else f", lowest passing {out['k_min']:g}"
        where = "the handle" if direction is not None else f"joint {out['joint']}"
        if method == "limit":
            softest = ("" if not out["k_limit_lower"] else f"; springs below {out['k_limit_lower']:.6g} "
                       f"{unit['stiffness']} are unstable too: gravity pulls the handle off the wall")
            typer.echo(f"{dev.name}, wall at {where}: maximum stable impedance {out['k_max']:g} {unit['stiffness']} "
                       f"on the grid{lowest} (stability limit {out['k_limit_exact']:.6g} {unit['stiffness']} at "
                       f"the wall's equilibrium{softest})")
        else:
            typer.echo(f"{dev.name}, type {sim_type}, {where}: maximum stable impedance "
                       f"{out['k_max']:g} {unit['stiffness']}{lowest} (first failure: {out['criterion']}; "
                       f"{out['simulations']} simulations)")
        typer.echo(f"verdict: {out['verdict']}")
        typer.echo(f"settings: {loop.describe()}")
        typer.echo("drive: " + ("rigid" if out["compliance"] == "rigid" else f"the compliance of the {compliance}")
                   + ("" if limit or compliance == "rigid" else " left out (the simulated plant is rigid; the limit "
                                                                "method models it)"))
        if true_boundary:
            what = "simulated with dry friction and quantization" if method == "limit" else "oscillation-growth"
            found = out["k_true_boundary"]
            typer.echo(f"{what} boundary: " + ("none found (unbounded)" if found is None else
                                                 f"{found:.4g} {unit['stiffness']}"))


def transparency_command(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    sim_type: int = typer.Option(1, "--type", help="1: chirp on the wall joint only; 2: chirp on every joint."),
    joint: str = typer.Option("1", help="Joint carrying the virtual wall (1-based or coordinate name)."),
    stiffness: float = typer.Option(4.0, help="Virtual wall stiffness K [N m/rad]."),
    amplitude: float = typer.Option(0.3, help="Chirp amplitude [rad]."),
    f0: float = typer.Option(0.1, help="Chirp start frequency [Hz]."),
    f1: float = typer.Option(15.0, help="Chirp end frequency [Hz]."),
    sweep: float = typer.Option(10.0, help="Chirp sweep time [s] (linear sweep)."),
    band: float = typer.Option(3.0, help="Transparency band [dB]."),
    response: Optional[Path] = typer.Option(None, help="Write the frequency response (CSV) here."),
    method: str = typer.Option("simulation", help="simulation (run the loop) or analytic (the loop linearized at the "
                                                  "start pose: the same estimate, plus the steady-state response)."),
    period: float = PERIOD, step: float = STEP, step_control: str = STEP_CONTROL, counts: Optional[int] = COUNTS,
    delay: int = DELAY,
    compensation: Optional[str] = typer.Option(None, help="none, gravity or full (inverse dynamics with the sampled "
                                                          "acceleration; the seed's, the default)."),
    error_percent: float = ERROR, inertial: bool = INERTIAL, coriolis: bool = CORIOLIS, gravity: bool = GRAVITY,
    wall_damping: float = WALL_DAMPING, hand_mass: float = HAND_MASS, hand_damping: float = HAND_DAMPING,
    hand_stiffness: float = HAND_STIFFNESS,
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Transparency bandwidth of one joint: G_T = Z_M / Z_D leaves +-3 dB (seed 000 §4.2.2, eq. 4.1-4.2)."""
    from hapticdesign.simulation.config import Compensator, LoopConfig
    from hapticdesign.simulation.loop import joint_index
    from hapticdesign.simulation.paths import Chirp
    from hapticdesign.simulation.transparency import stable_limit, transparency
    from hapticdesign.simulation.transparency_estimate import check_request

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        _check_chirp(amplitude, f0, f1, sweep, period)
        from hapticdesign.devices.loading import resolve_device

        dev = resolve_device(preset, device, params, strict=strict)
        loop = sampled_loop(True, period, delay, None, compensation, error_percent, wall_damping, hand_mass,
                            hand_damping, hand_stiffness)
        config = LoopConfig(duration=sweep, step=step, step_control=step_control, loop=loop, counts=counts,
                            compensator=Compensator(inertial, coriolis, gravity))
        if not (band > 0):
            raise UserError(f"--band must be positive, got {band}")
        if method not in ("simulation", "analytic"):
            raise UserError(f"--method must be 'simulation' or 'analytic', got {method!r}")
        check_request(dev, _sim_type(sim_type), stiffness, Chirp(amplitude, f0, f1, sweep), config)
        from hapticdesign.interface.commands.transparency_adapter import bandwidth_note, finite_or_none

        unit = joint_units(dev)[joint_index(dev, joint)]
        limit = stable_limit(dev, _sim_type(sim_type), joint_index(dev, joint), config)
        if limit is not None and stiffness > limit:
            note(f"warning: K = {stiffness:g} {unit['stiffness']} is above joint {joint_index(dev, joint) + 1}'s stable "
                 f"limit {limit:.4g} {unit['stiffness']} (its sampled loop, linearized at the start pose, grows): the "
                 "transparency is that of an unstable wall", quiet)
        result = transparency(dev, _sim_type(sim_type), stiffness, Chirp(amplitude, f0, f1, sweep), config,
                              joint_index(dev, joint), band_db=band, method=method)
        if response is not None:
            write_atomically(response, result.response_table())
        why = bandwidth_note(result.bandwidth_hz, band, f1, stiffness, limit, unit["stiffness"])
        out = {"device": dev.name, "type": sim_type, "joint": joint_index(dev, joint) + 1,
               "stiffness": stiffness, **result.as_dict(), **({"bandwidth_note": why} if why else {}),
               "stable_limit": finite_or_none(limit),
               "units": {"stiffness": unit["stiffness"], "stable_limit": unit["stiffness"], "bandwidth_hz": "Hz",
                         "band_db": "dB"}}
        if json_out:
            print_json(out)
            return
        bw = out["bandwidth_hz"]
        text = f"{bw:.3f} Hz" if bw is not None else f"beyond {f1:g} Hz"
        extra = ""
        if "steady_bandwidth_hz" in out:
            steady = out["steady_bandwidth_hz"]
            extra = f" (steady state: {f'{steady:.3f} Hz' if steady is not None else f'beyond {f1:g} Hz'})"
        typer.echo(f"{dev.name}, type {sim_type}, joint {out['joint']}, K = {stiffness:g} N m/rad: "
                   f"transparency bandwidth {text}{extra}")


def _check_chirp(amplitude: float, f0: float, f1: float, sweep: float, period: float) -> None:
    """The chirp options of ``transparency``: a moving joint, 0 <= f0 < f1 <= Nyquist, a finite sweep."""
    if not (np.isfinite(amplitude) and amplitude != 0):
        raise UserError(f"--amplitude must be a finite, non-zero angle, got {amplitude}")
    if not (np.isfinite(sweep) and sweep > 0):
        raise UserError(f"--sweep must be a positive number of seconds, got {sweep}")
    if not (np.isfinite(f0) and np.isfinite(f1) and 0 <= f0 < f1):
        raise UserError(f"--f0 and --f1 must be finite with 0 <= f0 < f1, got {f0:g} and {f1:g}")
    if period > 0 and np.isfinite(period) and f1 > 0.5 / period:
        raise UserError(f"--f1 {f1:g} Hz is beyond the Nyquist frequency {0.5 / period:g} Hz of --period {period:g} s")


def _check_scale(**values: float) -> None:
    """Refuse magnitudes outside the loop's :data:`~hapticdesign.analysis.sampled_loop.SCALE_RANGE` (zero allowed
    where a flag may be off)."""
    from hapticdesign.analysis.sampled_loop import SCALE_RANGE

    lo, hi = SCALE_RANGE
    for name, value in values.items():
        if value != 0 and not (lo <= abs(value) <= hi):
            raise UserError(f"--{name.replace('_', '-')} {value:g} is outside the range this model is computed for "
                            f"({lo:g} to {hi:g} in SI units)")


def _finite_or_none(value: float | None) -> float | None:
    return value if value is None or np.isfinite(value) else None


def stability_boundary_command(
    inertia: float = typer.Option(..., help="Inertia J [kg m^2]."),
    damping: float = typer.Option(..., help="Viscous damping b [N m s/rad]."),
    period: float = PERIOD,
    settings: Optional[str] = typer.Option(
        None, help="Loop settings: practice (1 kHz, one sample of delay, backward-difference velocity, gravity "
                   "compensation, which a 1-DOF mass-damper has no gravity for; the default) or seed (full "
                   "inverse-dynamics compensation, no delay, sampled velocity). The options below change single ones."),
    delay: Optional[int] = typer.Option(None, help="Sensor delay in samples (default: the --settings' own)."),
    velocity: Optional[str] = VELOCITY, compensation: Optional[str] = COMPENSATION,
    error_percent: float = typer.Option(
        0.0, help="Compensator modelling error E [%]: it feeds (1 - E/100) J qdd forward (needs --compensation full)."),
    wall_damping: float = typer.Option(0.0, help="Virtual damper B [N m s/rad]."),
    substeps: int = typer.Option(10, help="Plant steps per sample in the simulation."),
    samples: int = typer.Option(4000, help="Samples per simulation of the growth test."),
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Exact vs simulated stiffness limit of a 1-DOF mass-damper under a sampled spring (check of seed 000 ch. 4).

    The loop settings are every command's (practice's by default, --settings seed for the seed's); the output
    states them."""
    from hapticdesign.analysis.sampled_loop import compensated_limit, joint_limit
    from hapticdesign.simulation.boundary import simulated_boundary

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        if substeps < 1 or samples < 40:
            raise UserError("--substeps must be at least 1 and --samples at least 40")
        if not (np.isfinite(inertia) and inertia > 0 and np.isfinite(period) and period > 0):
            raise UserError(f"--inertia and --period must be positive numbers, got {inertia:g} and {period:g}")
        _check_scale(inertia=inertia, damping=damping, period=period, wall_damping=wall_damping)
        loop = sampled_loop(seed_settings(None, settings or "practice"), period, delay, velocity, compensation,
                            error_percent, wall_damping)
        if error_percent and loop.compensation != "full":
            raise UserError("--error-percent needs --compensation full (it scales the compensator's inertia)")
        if damping * period / substeps > inertia:
            raise UserError(f"the plant step --period / --substeps = {period / substeps:.3g} s is longer than the "
                            f"plant's time constant J/b = {inertia / damping:.3g} s; raise --substeps")
        if 0 < damping * period / inertia < 1e-9:
            raise UserError(f"the damping over one sample, b T / J = {damping * period / inertia:.3g}, is too small to "
                            "resolve in double precision (below 1e-9); give --damping 0 for an undamped plant")
        if loop.delay >= samples // 4:
            raise UserError(f"--delay ({loop.delay} samples) must be shorter than a quarter of --samples ({samples}) "
                            "for the growth test to see the loop respond")
        exact = joint_limit(inertia, damping, loop)
        limit = (compensated_limit(inertia, damping, period, loop.fraction)
                 if loop.compensation == "full" and loop.delay == 0 and wall_damping == 0 else None)
        closed = None if limit is None else limit.stiffness
        simulated = simulated_boundary(inertia, damping, loop, samples=samples, substeps=substeps)
        unbounded = [name for name, v in (("exact", exact), ("closed_form", closed), ("simulated", simulated))
                     if v is not None and not np.isfinite(v)]
        out = {"k_max_exact": _finite_or_none(exact), "k_max_closed_form": _finite_or_none(closed),
               "closed_form_bound": None if limit is None else limit.bound,
               "k_max_simulated": _finite_or_none(simulated),
               "relative_difference": (simulated - exact) / exact
               if np.isfinite(exact) and np.isfinite(simulated) and exact != 0 else None,
               "two_b_over_t": 2 * damping / period, "error_percent": error_percent, "settings": loop.as_dict(),
               "units": {"k_max_exact": "N m/rad", "k_max_closed_form": "N m/rad", "k_max_simulated": "N m/rad",
                         "relative_difference": "dimensionless", "two_b_over_t": "N m/rad", "error_percent": "%"}}
        if unbounded:
            out["note"] = (f"k_max {', '.join(unbounded)}: no stiffness up to the search cap destabilizes the loop "
                           "(unbounded; null in JSON)")
        if json_out:
            print_json(out)
            return
        form = "" if limit is None else f", closed form {_stiffness_text(closed)} ({limit.bound})"
        typer.echo(f"exact {_stiffness_text(exact)}{form}, simulated {_stiffness_text(simulated)} "
                   f"(2b/T = {2 * damping / period:.6g})")
        typer.echo(f"settings: {loop.describe()}")


def _stiffness_text(value: float) -> str:
    return f"{value:.6g} N m/rad" if np.isfinite(value) else "unbounded (no stiffness destabilizes the loop)"


def _group_errors(text: str | None) -> tuple[tuple[str, float], ...]:
    """``--group-errors "mass=5,centre=2,inertia=5"`` as ``(("mass", 5.0), ...)``."""
    if not text:
        return ()
    pairs = []
    for item in text.replace(" ", "").split(","):
        name, sep, value = item.partition("=")
        try:
            pairs.append((name, float(value)))
        except ValueError:
            raise UserError(f"--group-errors: expected group=percent pairs such as mass=5,inertia=5, got {item[:40]!r}") from None
        if not sep:
            raise UserError(f"--group-errors: expected group=percent pairs such as mass=5,inertia=5, got {item[:40]!r}")
    return tuple(pairs)


def campaign_command(
    designs: Path = typer.Option(..., help="Design CSV: level, ln, ln_H, ln_C, ln_G and every inertial parameter."),
    out: Path = typer.Option(..., help="Output folder (cases/, results.csv, summary.csv, summary.md, figures/)."),
    scheduler: Optional[str] = typer.Option(None, help="Dask scheduler address; local processes by default."),
    workers: Optional[int] = typer.Option(None, help="Local worker processes (default: all cores)."),
    preset: Optional[str] = PRESET,
    k_limit: int = typer.Option(200, help="Largest stiffness tried [N m/rad]."),
    duration: float = typer.Option(5.0, help="Simulated time per stiffness [s] (seed: 5)."),
    stiffness: float = typer.Option(4.0, help="Wall stiffness of the transparency runs [N m/rad] (seed: 4)."),
    sweep: float = typer.Option(10.0, help="Chirp sweep time [s] (seed: 10)."),
    f1: float = typer.Option(15.0, help="Chirp end frequency [Hz] (seed: 15)."),
    method: str = typer.Option("simulation", help="Cases by simulation or analytic (the loop linearized at the start "
                                                  "pose, no loop run: exact for type 1 and LN = 0)."),
    counts: Optional[int] = COUNTS,
    delay: int = DELAY,
    error_percent: float = ERROR,
    group_errors: Optional[str] = typer.Option(
        None, help="Compensator error per parameter group [%], e.g. mass=5,centre=2,inertia=5 (groups: mass, "
                   "centre, inertia)."),
    error_seed: Optional[int] = typer.Option(
        None, help="Random sign per parameter for --group-errors (numpy default_rng seed); all -1 without."),
    coulomb: Optional[str] = typer.Option(None, help="Coulomb friction in the plant per joint [N m], comma-separated; "
                                                     "the device's by default."),
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Both criteria and both types over a design set; resumable (seed 000 §4.1.4, §4.2.4)."""
    import os

    from hapticdesign.devices.registry import preset as preset_device
    from hapticdesign.interface.report.index import write_folder_index
    from hapticdesign.simulation.campaign import CampaignOptions, load_cases, read_designs, run_campaign, summarize
    from hapticdesign.simulation.config import Compensator, LoopConfig, compensator_device
    from hapticdesign.simulation.paths import Chirp

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        if workers is not None and workers < 1:
            raise UserError("--workers must be at least 1")
        if workers is not None and workers > (os.cpu_count() or 1) and not force:
            raise UserError(f"--workers {workers} is more than the {os.cpu_count() or 1} cores of this machine; "
                            "add --force to start them anyway")
        if k_limit < 1:
            raise UserError("--k-limit must be at least 1")
        if not (np.isfinite(duration) and duration > 0 and np.isfinite(stiffness) and stiffness > 0):
            raise UserError("--duration and --stiffness must be positive")
        _check_chirp(0.3, 0.1, f1, sweep, 1e-3)
        if duration <= 0.5:
            raise UserError(f"--duration ({duration:g} s) must be longer than the 0.5 s settle window")
        if method not in ("simulation", "analytic"):
            raise UserError(f"--method must be 'simulation' or 'analytic', got {method!r}")
        friction = None if coulomb is None else tuple(float(v) for v in parse_vector(coulomb, None, "coulomb"))
        if friction is not None and any(v < 0 for v in friction):
            raise UserError("--coulomb: friction torques must be >= 0")
        conditions = LoopConfig(duration=duration, loop=sampled_loop(True, 1e-3, delay, None, None, error_percent, 0.0),
                                counts=counts, coulomb=friction,
                                compensator=Compensator(group_errors=_group_errors(group_errors), error_seed=error_seed))
        compensator_device(preset_device(preset or "phantom-3dof"), conditions)  # bad groups fail now
        options = CampaignOptions(preset or "phantom-3dof", k_limit, stiffness, Chirp(0.3, 0.1, f1, sweep), duration,
                                  method=method, conditions=conditions)
        with progress_bar(not (quiet or json_out)) as report:
            advance = (lambda done, total: report("campaign cases", done, total)) if report else None
            counts = run_campaign(designs, out, options, scheduler, workers, advance, quiet=quiet)
        index = write_folder_index(out, f"Campaign {designs.name}", (
            f"{options.method.capitalize()} campaign of the designs in {designs.name} on {options.preset}: both "
            "criteria and both types (seed 000 §4.1.4, §4.2.4); one JSON file per case in cases/."),
            [out / name for name in ("results.csv", "summary.csv", "summary.md")]
            + sorted((out / "figures").iterdir()))
        if json_out:
            chosen = read_designs(designs, options.preset)
            print_json({**counts, "out": str(out), "index": str(index),
                        "tables": [str(out / name) for name in ("results.csv", "summary.csv", "summary.md")],
                        "figures": sorted(str(f) for f in (out / "figures").iterdir()),
                        "summary": summarize(chosen, load_cases(chosen, out), options)})
            return
        typer.echo(f"{counts['cases']} cases: {counts['run']} run, {counts['skipped']} already done; "
                   f"tables and figures in {out}, listed in {index}")


def register(app: typer.Typer) -> None:
    app.command("impedance-range")(impedance_range_command)
    app.command("transparency")(transparency_command)
    app.command("stability-boundary")(stability_boundary_command)
    app.command("campaign")(campaign_command)
