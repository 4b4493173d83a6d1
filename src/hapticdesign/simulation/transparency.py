"""Transparency bandwidth of one joint (seed 000 §4.2.2-4.2.3, eq. 4.1-4.2).

The wall joint follows a linear chirp (0.3 rad, 0.1-15 Hz over 10 s); type 1 holds the other
joints at 0, type 2 drives every joint with the same chirp (Table 4.5). Recorded at the plant
step: ``tau_h`` (the torque that moves the device along the path: its inverse dynamics and joint
damping), ``tau_f`` (held compensator torque), ``tau_imp`` (held torque of the implemented wall),
``tau_D = K (q - q_eq) + B qd`` (the ideal wall, continuous), and the transmitted torque
``tau_M = tau_h + tau_imp - tau_f`` (eq. 4.1), which is the torque the user's motion source
supplies. Impedances ``Z = S_q,tau / S_q,q`` (cross-spectrum over auto-spectrum, Welch);
``G_T = Z_M / Z_D`` (eq. 4.2); the bandwidth is where ``|G_T|`` first leaves +-3 dB.

With perfect compensation ``G_T = 1 + j b w / K``, so the joint damping alone sets the
bandwidth to ``K / (2 pi b)`` (1.27 Hz for K = 4 N m/rad, b = 0.5 N m s/rad).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.analytic import AnalyticProblem, linear_loop
from hapticdesign.simulation.analytic_transparency import analytic_transparency
from hapticdesign.simulation.boundary import growth_onset
from hapticdesign.simulation.config import LoopConfig, Wall, rest_pose
from hapticdesign.simulation.criteria import Criteria, require_closed
from hapticdesign.simulation.loop import simulate
from hapticdesign.simulation.paths import Chirp, Held, Path
from hapticdesign.simulation.transparency_estimate import (
    TransparencyResult,
    band_of,
    check_request,
    first_exit,
    impedance,
    segment_length,
)


def chirp_paths(n_dof: int, sim_type: int, wall_joint: int, chirp: Chirp,
                rest: np.ndarray | None = None) -> dict[int, Path]:
    """Type 1: the chirp on the wall joint, the others held at 0; type 2: the chirp on every joint (Table 4.5);
    about ``rest`` instead of 0 when given (a closed-loop device's home, :func:`~.config.rest_pose`)."""
    centre = np.zeros(n_dof) if rest is None else np.asarray(rest, dtype=float)
    return {j: (replace(chirp, offset=float(centre[j])) if (j == wall_joint or sim_type == 2) else Held(float(centre[j])))
            for j in range(n_dof)}


def transparency(
    device: Device,
    sim_type: int = 1,
    stiffness: float = 4.0,
    chirp: Chirp | None = None,
    config: LoopConfig | None = None,
    wall_joint: int = 0,
    equilibrium: float = 0.0,
    segment_seconds: float | None = None,
    window: str = "boxcar",
    band_db: float = 3.0,
    method: str = "simulation",
) -> TransparencyResult:
    """Transparency bandwidth of ``wall_joint`` for simulation type 1 or 2 (seed §4.2.2).

    By default the spectra use one rectangular segment spanning the whole sweep (0.1 Hz
    resolution): a chirp is not stationary, and tapered, overlapping Welch segments under-weight
    the low frequencies swept near the ends of the record. ``method="analytic"`` answers from the
    wall joint's loop linearized at the start pose, with the same estimate, band and bins
    (:mod:`.analytic_transparency`: no loop is run; exact for type 1 and for LN = 0).

    The joints move about :func:`~.config.rest_pose` (0, or a closed-loop device's home) and the wall's
    spring rests at ``equilibrium`` from it.
    """
    if method not in ("simulation", "analytic"):
        raise UserError(f"the transparency method must be 'simulation' or 'analytic', got {method!r}")
    if method == "analytic":
        return analytic_transparency(device, sim_type, stiffness, chirp, config, wall_joint, equilibrium,
                                     segment_seconds, window, band_db)
    chirp, base = check_request(device, sim_type, stiffness, chirp, config)
    rest = rest_pose(device)
    spring_rest = float(rest[wall_joint]) + equilibrium
    cfg = replace(base, duration=chirp.sweep_time, safety_limit=None, stop_excursion=None, record_stride=1,
                  wall=Wall(wall_joint, stiffness, equilibrium=spring_rest))
    trace = simulate(device, cfg, chirp_paths(device.n_dof, sim_type, wall_joint, chirp, rest))
    require_closed(trace, f"the type {sim_type} chirp")
    q = trace.q[:, wall_joint]
    tau_m = trace.tau_c[:, wall_joint]
    tau_d = stiffness * (q - spring_rest) + cfg.loop.wall_damping * trace.qd[:, wall_joint]
    fs = 1.0 / cfg.step
    seconds, nperseg = segment_length(segment_seconds, chirp, fs, len(q))
    f, z_d = impedance(q, tau_d, fs, nperseg, window)
    _, z_m = impedance(q, tau_m, fs, nperseg, window)
    keep = band_of(f, chirp, seconds)
    f, z_d, z_m = f[keep], z_d[keep], z_m[keep]
    gain_db = 20 * np.log10(np.abs(z_m / z_d))
    signals = {
        "t": trace.t, "q": q, "tau_h": tau_m + trace.u[:, wall_joint], "tau_f": trace.tau_f[:, wall_joint],
        "tau_imp": trace.tau_imp[:, wall_joint], "tau_D": tau_d, "tau_M": tau_m,
    }
    return TransparencyResult(f, z_d, z_m, first_exit(f, gain_db, band_db), band_db, signals)


LIMIT_REL_TOL = 1e-9
"""Relative width the wall joint's stable limit is bisected to."""
LIMIT_DOUBLINGS = 60
"""Doublings of the first estimate the search for the stable limit tries before it calls the wall stable for every
stiffness."""
LIMIT_STEP = 0.01
"""The spring's rest from the start (Table 4.2), where the loop is linearized for the stable limit."""


def stable_limit(device: Device, sim_type: int, wall_joint: int, config: LoopConfig) -> float | None:
    """The stiffness at which the wall joint's sampled loop starts to grow: the loop linearized where the wall holds
    the joint (the spring's rest, :data:`LIMIT_STEP` from the start pose), its growth boundary
    (:meth:`~hapticdesign.simulation.analytic.AnalyticProblem.grows`: its one-sample map's spectral radius reaches 1;
    with full inertial compensation and no delay the seed's 1-DOF closed form ``b^2 / H_ww``, seed 000 §4.1.2).
    ``inf`` when no stiffness makes it grow, None where the linearization does not decide it (encoder counts, Coulomb
    friction, a type 2 motion coupled to the wall joint)."""
    if not linear_loop(device, config):
        return None
    problem = AnalyticProblem(device, sim_type, wall_joint, LIMIT_STEP, Criteria(), config)
    if not problem.growth_is_exact:
        return None
    first = problem.estimate()
    return growth_onset(problem.grows, 0.0, first, LIMIT_REL_TOL, first * 2.0 ** LIMIT_DOUBLINGS)
