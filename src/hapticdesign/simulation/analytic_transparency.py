"""Transparency without running the loop: the wall joint linearized at the start pose (seed 000 §4.2.2-4.2.3).

In a transparency run every joint follows a path (the chirp, or held at 0), so nothing is fed back: the
transmitted torque ``tau_M = tau_h + tau_imp - tau_f`` (eq. 4.1) is the plant's inverse dynamics along
the path minus the torque the digital side computed from samples of that path and held. With the
moving joints ``m`` (the wall joint; every joint in type 2, all on the same chirp ``s(t)``) and the
pose ``q0 + s m`` (``q0 = 0``, where the paths start), the wall joint's row of eq. 2.50 is, to first
order about the pose at rest,

    tau_M = J s'' + b s' + k s - ZOH[ z^-N (c s'' + g s - K (s - q_eq) - B s') ] + const

with ``J = H_w(q0) m`` (plus the hand's mass), ``b`` the damping row times ``m`` (plus the hand's),
``k = dG_w/ds`` (plus the hand's stiffness), ``c = s_H H_model,w(q0) m`` and ``g = s_G dG_model,w/ds``
of the compensator's model (its modelling error included), ``N`` samples of computation delay and
``ZOH`` the sample-and-hold of period ``T`` (the sensors read ``s, s', s''`` of the path at the
instants, as the simulation's sensors do for a prescribed joint). Coriolis terms are quadratic in the
velocity and vanish to first order. The linearization is exact when the wall joint's torque along
the motion is affine in ``(s, s', s'')`` for the plant and the model (:func:`linear_along`): always in
type 1 for a joint whose row does not depend on its own angle (joint 1 of the Phantom), and for LN = 0
designs in type 2.

Two readings of the same linear system, on the same bins and band as :func:`.transparency.transparency`:

- ``bandwidth_hz``, the estimate: ``Z = S_q,tau / S_q,q`` (:func:`.transparency.impedance`) is linear in
  the torque, so ``Z_M = J Z[s''] + b Z[s'] + k Z[s] - c Z[h s''] - (g - K) Z[h s] + B Z[h s']`` with
  ``Z[x] = S_s,x / S_s,s`` of the chirp and of its sampled, delayed and held copies ``h x``: six spectra,
  computed once per chirp and timing (:func:`signal_spectra`). It equals the simulated estimate
  wherever the linearization is exact.
- ``steady_bandwidth_hz``, the frequency response felt in steady sinusoidal motion (python-control):
  ``Z(jw) = J (jw)^2 + b jw + k + ZOH(jw) e^(-jwNT) (K - g + B jw - c (jw)^2)`` with the held sequence's
  fundamental ``ZOH(jw) = (1 - e^(-jwT)) / (jwT)``.

They differ because the estimate's record is not periodic: the chirp ends at full speed
(``s'(L) = 2 pi f1 A``, 28 rad/s for the seed's chirp). Over one rectangular window the transform of a
derivative is ``jw`` times the transform plus the jump ``x(L) - x(0)``, and the estimate divides that
jump by the chirp's spectrum, which is smallest at the first bins (swept in the first instants). The
jumps of the continuous inertia ``J s''`` and of the held ``c h s''`` cancel only for an exact inertial
compensator without delay; otherwise the first bins leave the band (a 10 % modelling error or no
inertial compensator: the estimate exits at 0.1 Hz, the steady-state response at 1.4 and 1.8 Hz).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import control
import numpy as np

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.config import (
    LoopConfig, compensator_device, hand_matrices, plant_damping, plant_friction, rest_pose,
)
from hapticdesign.simulation.paths import Chirp
from hapticdesign.simulation.transparency_estimate import (TransparencyResult, band_of, check_request, first_exit,
                                                           impedance, segment_length)

SIGNALS = ("acc", "vel", "pos", "held_acc", "held_vel", "held_pos")
"""The chirp's ``s'', s', s`` at every plant step and their sampled, delayed, held copies."""
SLOPE_STEP = 1e-5


@dataclass(frozen=True)
class TransparencyLoop:
    """The wall joint along the motion: plant ``J, b, k`` and compensator ``c, g`` (module docstring)."""

    inertia: float
    damping: float
    spring: float
    compensated_inertia: float
    compensated_spring: float
    exact: bool


@dataclass(frozen=True)
class AnalyticTransparencyResult(TransparencyResult):
    """The estimate (``bandwidth_hz``, as simulated) and the steady-state response beside it."""

    z_steady: np.ndarray
    steady_bandwidth_hz: float | None
    exact: bool

    def as_dict(self) -> dict:
        return {**super().as_dict(), "steady_bandwidth_hz": self.steady_bandwidth_hz, "analytic_exact": self.exact}


def moving_joints(n_dof: int, sim_type: int, wall_joint: int) -> np.ndarray:
    """1 for the joints on the chirp, 0 for the held ones."""
    m = np.ones(n_dof) if sim_type == 2 else np.zeros(n_dof)
    m[wall_joint] = 1.0
    return m


class _Row:
    """One device's equations of motion (its compiled model and parameters, looked up once) along the
    motion ``q = rest + s m`` of the wall joint ``w`` (``rest``: :func:`~.config.rest_pose`)."""

    def __init__(self, device: Device, w: int, m: np.ndarray, rest: np.ndarray) -> None:
        self.model, self.pi = dynamics_of(device), device.standard_parameters()
        self.w, self.m, self.rest = w, m, rest

    def poses(self, s: np.ndarray) -> np.ndarray:
        return self.rest + np.multiply.outer(np.ravel(s), self.m)

    def inertia(self, s: np.ndarray) -> np.ndarray:
        """``H_w(q) m`` at each ``s``."""
        return self.model.H(self.poses(s), self.pi)[:, self.w] @ self.m

    def coriolis(self, s: np.ndarray) -> np.ndarray:
        """The wall joint's Coriolis and centrifugal torque at unit rate ``q' = m``."""
        q = self.poses(s)
        rates = np.broadcast_to(self.m, q.shape)
        return (self.model.inverse(q, rates, np.zeros_like(q), self.pi) - self.model.G(q, self.pi))[:, self.w]

    def gravity(self, s: np.ndarray) -> np.ndarray:
        return self.model.G(self.poses(s), self.pi)[:, self.w].reshape(np.shape(s))

    def spring(self) -> float:
        """``dG_w / ds`` at ``s = 0`` by a central difference over ``+-1e-5`` rad (G is a trigonometric
        polynomial of the angles: truncation and round-off both about 1e-11 of G's scale)."""
        low, high = self.gravity(np.array([-SLOPE_STEP, SLOPE_STEP]))
        return float((high - low) / (2 * SLOPE_STEP))


def linear_along(rows: tuple[_Row, _Row], switches: np.ndarray, amplitude: float,
                 loop: tuple[float, float, float, float]) -> bool:
    """True when the wall joint's torque of the plant and of the compensator is affine in ``(s, s', s'')``
    along the motion over the chirp's range (nine poses, unit rates, relative 1e-9 of the largest term)."""
    j, k, c, g = loop
    s = np.linspace(-abs(amplitude), abs(amplitude), 9)
    size = max(abs(j), abs(c), (abs(k) + abs(g)) * abs(amplitude), 1e-12)
    for row, inertia, spring, scale in ((rows[0], j, k, np.ones(3)), (rows[1], c, g, switches)):
        error = (np.abs(scale[0] * row.inertia(s) - inertia) + np.abs(scale[1] * row.coriolis(s))
                 + np.abs(scale[2] * (row.gravity(s) - row.gravity(np.zeros(1))) - spring * s))
        if error.max() > 1e-9 * size:
            return False
    return True


def transparency_loop(device: Device, sim_type: int, wall_joint: int, config: LoopConfig,
                      amplitude: float) -> TransparencyLoop:
    """The wall joint's loop along the chirp at the start pose (module docstring)."""
    if config.counts is not None:
        raise UserError("the analytic method has no encoder quantization (not linear): use the simulation")
    if np.any(plant_friction(device, config)[1] > 0):
        raise UserError("the analytic method has no Coulomb friction (not linear): use the simulation")
    w, n = wall_joint, device.n_dof
    m = moving_joints(n, sim_type, w)
    switches = np.array(config.switches, dtype=float)
    rest = rest_pose(device)
    plant, model = _Row(device, w, m, rest), _Row(compensator_device(device, config), w, m, rest)
    hand_mass, hand_damping, hand_stiffness = hand_matrices(device, config.loop.hand, rest)
    damping = plant_damping(device, config)
    zero = np.zeros(1)
    j, c = float(plant.inertia(zero)[0]), switches[0] * float(model.inertia(zero)[0])
    k, g = plant.spring(), switches[2] * model.spring()
    exact = linear_along((plant, model), switches, amplitude, (j, k, c, g))
    return TransparencyLoop(j + float(hand_mass[w] @ m), float((damping + hand_damping)[w] @ m),
                            k + float(hand_stiffness[w] @ m), float(c), float(g), exact)


@lru_cache(maxsize=8)
def signal_spectra(chirp: Chirp, step: float, sub: int, delay: int, seconds: float | None,
                   window: str) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The bins and ``Z[x] = S_s,x / S_s,s`` of each of :data:`SIGNALS` (module docstring), estimated as the
    simulation estimates its impedances: the record of every plant step over the sweep, the same segment
    and window. The sensors' sample ``k`` reads the path at ``k T`` and the torque held from then on uses
    sample ``max(k - N, 0)``, as the loop's delay line does."""
    steps = int(round(chirp.sweep_time / step))
    t = np.arange(steps + 1) * step
    pos, vel, acc = chirp.sample(t)
    instants = np.arange(0, steps + 1, sub)
    read = instants[np.maximum(np.arange(instants.size) - delay, 0)]

    def held(x: np.ndarray) -> np.ndarray:
        return np.repeat(x[read], sub)[: steps + 1]

    records = {"acc": acc, "vel": vel, "pos": pos, "held_acc": held(acc), "held_vel": held(vel), "held_pos": held(pos)}
    fs = 1.0 / step
    seconds, nperseg = segment_length(seconds, chirp, fs, steps + 1)
    spectra = {}
    for name in SIGNALS:
        f, spectra[name] = impedance(pos, records[name], fs, nperseg, window)
    keep = band_of(f, chirp, seconds)
    return f[keep], {name: z[keep] for name, z in spectra.items()}


def steady_response(loop: TransparencyLoop, frequency: np.ndarray, period: float, delay: int, stiffness: float,
                    wall_damping: float) -> np.ndarray:
    """``Z(jw)`` felt in steady sinusoidal motion: the plant's ``J s^2 + b s + k`` plus the digital side's
    ``z^-N (K - g + B s - c s^2)`` on the samples of ``(s, s', s'')``, held (module docstring)."""
    w = 2 * np.pi * np.asarray(frequency, dtype=float)
    plant = control.tf([loop.inertia, loop.damping, loop.spring], [1.0])
    lag = control.tf([1.0], [1.0] + [0.0] * delay, period)
    law = control.tf([-loop.compensated_inertia, wall_damping, stiffness - loop.compensated_spring], [1.0])
    hold = (1 - np.exp(-1j * w * period)) / (1j * w * period)
    return plant(1j * w) + hold * lag(np.exp(1j * w * period)) * law(1j * w)


def analytic_transparency(
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
) -> AnalyticTransparencyResult:
    """:func:`.transparency.transparency` from the linearized loop: the estimate the simulation makes and the
    steady-state response (module docstring). ``equilibrium`` only shifts the torque by a constant, which
    the estimate removes (its spectra are of the detrended record)."""
    chirp, cfg = check_request(device, sim_type, stiffness, chirp, config)
    if not 0 <= wall_joint < device.n_dof:
        raise UserError(f"unknown joint {wall_joint + 1}; the device has joints 1..{device.n_dof}")
    if not math.isfinite(equilibrium):
        raise UserError("the wall equilibrium must be finite")
    delay = cfg.loop.delay
    if delay * cfg.loop.period >= chirp.sweep_time:
        raise UserError(f"the sensor delay ({delay} samples) must be shorter than the sweep "
                        f"({chirp.sweep_time:g} s)")
    wall_damping = cfg.loop.wall_damping
    loop = transparency_loop(device, sim_type, wall_joint, cfg, chirp.amplitude)
    f, z = signal_spectra(chirp, cfg.step, cfg.steps_per_sample(), delay, segment_seconds, window)
    z_d = stiffness * z["pos"] + wall_damping * z["vel"]
    z_m = (loop.inertia * z["acc"] + loop.damping * z["vel"] + loop.spring * z["pos"]
           - loop.compensated_inertia * z["held_acc"] + (stiffness - loop.compensated_spring) * z["held_pos"]
           + wall_damping * z["held_vel"])
    steady = steady_response(loop, f, cfg.loop.period, delay, stiffness, wall_damping)
    z_steady_d = stiffness + 1j * wall_damping * 2 * np.pi * f
    gain_db = 20 * np.log10(np.abs(z_m / z_d))
    steady_db = 20 * np.log10(np.abs(steady / z_steady_d))
    return AnalyticTransparencyResult(f, z_d, z_m, first_exit(f, gain_db, band_db), band_db, {}, steady,
                                      first_exit(f, steady_db, band_db), loop.exact)
