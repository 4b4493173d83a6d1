"""What both transparency methods share (seed 000 §4.2.2-4.2.3, eq. 4.1-4.2): the result, the impedance
estimate ``Z = S_q,tau / S_q,q`` (Welch cross- over auto-spectrum), the band of the sweep, the first exit
from +-``band_db`` and the checks of a request. The simulated method is :mod:`.transparency`, the
linearized one :mod:`.analytic_transparency`; both import this module, neither the other's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.signal import csd, welch

from hapticdesign.analysis.sampled_loop import SCALE_RANGE
from hapticdesign.errors import InputError, UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.config import LoopConfig, require_device, require_options
from hapticdesign.simulation.paths import Chirp
from hapticdesign.workload import require_plant_steps


@dataclass(frozen=True)
class TransparencyResult:
    """Frequency response of eq. 4.2 and the bandwidth (``None`` inside the band up to the top)."""

    frequency: np.ndarray
    z_desired: np.ndarray
    z_transmitted: np.ndarray
    bandwidth_hz: float | None
    band_db: float
    signals: dict[str, np.ndarray] = field(repr=False)

    @property
    def g_t(self) -> np.ndarray:
        return self.z_transmitted / self.z_desired

    def as_dict(self) -> dict:
        return {"bandwidth_hz": self.bandwidth_hz, "band_db": self.band_db,
                "z_desired_mean_magnitude": float(np.mean(np.abs(self.z_desired)))}

    def response_table(self) -> str:
        """CSV of the frequency response: frequency, |Z_D|, |Z_M|, |G_T| in dB, phase of G_T."""
        lines = ["frequency_hz,abs_z_desired,abs_z_transmitted,g_t_db,g_t_phase_deg"]
        for f, zd, zm, g in zip(self.frequency, self.z_desired, self.z_transmitted, self.g_t):
            lines.append(f"{f:.6g},{abs(zd):.6g},{abs(zm):.6g},{20 * np.log10(abs(g)):.6g},{np.degrees(np.angle(g)):.6g}")
        return "\n".join(lines) + "\n"


def impedance(q: np.ndarray, tau: np.ndarray, fs: float, nperseg: int, window: str = "boxcar") -> tuple[np.ndarray, np.ndarray]:
    """``Z(f) = S_q,tau(f) / S_q,q(f)`` by Welch's method (seed §4.2.2)."""
    f, s_qt = csd(q, tau, fs=fs, nperseg=nperseg, window=window)
    _, s_qq = welch(q, fs=fs, nperseg=nperseg, window=window)
    return f, s_qt / s_qq


def first_exit(frequency: np.ndarray, gain_db: np.ndarray, band_db: float) -> float | None:
    """First frequency where ``|gain_db|`` reaches ``band_db``, linearly interpolated between bins."""
    outside = np.nonzero(np.abs(gain_db) >= band_db)[0]
    if outside.size == 0:
        return None
    i = int(outside[0])
    if i == 0:
        return float(frequency[0])
    g0, g1 = gain_db[i - 1], gain_db[i]
    target = math.copysign(band_db, g1)
    return float(frequency[i - 1] + (target - g0) / (g1 - g0) * (frequency[i] - frequency[i - 1]))


def check_request(device: Device, sim_type: int, stiffness: float, chirp: Chirp | None,
                  config: LoopConfig | None) -> tuple[Chirp, LoopConfig]:
    """Validate a transparency request; the chirp and configuration it runs with (the seed's by default)."""
    require_device(device)
    require_options(sim_type, config, LoopConfig)
    if chirp is not None and not isinstance(chirp, Chirp):
        raise UserError(f"chirp must be a Chirp, got {type(chirp).__name__}")
    if isinstance(stiffness, bool) or not isinstance(stiffness, (int, float)):
        raise UserError(f"the wall stiffness must be a number, got {stiffness!r}")
    if not (stiffness > 0 and math.isfinite(stiffness)):
        raise InputError(f"the wall stiffness must be positive, got {stiffness}", "stiffness")
    if stiffness > SCALE_RANGE[1]:
        raise InputError(f"the wall stiffness must be at most {SCALE_RANGE[1]:g} (SI units), got {stiffness:g}",
                         "stiffness")
    chirp = chirp or Chirp()
    base = config or LoopConfig()
    base.steps_per_sample()
    base.require_simulated()
    if not chirp.sweep_time >= base.loop.period:
        raise InputError(f"the chirp's sweep time {chirp.sweep_time:g} s is shorter than one sample period "
                         f"({base.loop.period:g} s)", "sweep")
    require_plant_steps(f"a chirp of {chirp.sweep_time:g} s at a plant step of {base.step:g} s",
                        chirp.sweep_time / base.step)
    nyquist = 0.5 / base.loop.period
    if not chirp.f1 <= nyquist:
        raise UserError(f"the chirp's end frequency {chirp.f1:g} Hz is beyond the Nyquist frequency {nyquist:g} Hz "
                        f"of the {base.loop.period:g} s sample period")
    return chirp, base


def segment_length(seconds: float | None, chirp: Chirp, fs: float, samples: int) -> tuple[float, int]:
    """The spectral segment in seconds (default: the whole sweep) and in samples at ``fs`` (at most the record)."""
    seconds = chirp.sweep_time if seconds is None else seconds
    if not (seconds > 0 and math.isfinite(seconds)):
        raise UserError(f"the spectral segment must be positive, got {seconds}")
    return seconds, min(samples, int(round(seconds * fs)))


def band_of(f: np.ndarray, chirp: Chirp, seconds: float) -> np.ndarray:
    """The bins reported: from the chirp's start (or the segment's first bin) to its end frequency."""
    return (f >= max(chirp.f0, 1.0 / seconds)) & (f <= chirp.f1)
