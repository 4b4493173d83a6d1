"""What a sampled-data simulation is configured with and what it returns (seed 000 §4.1.1).

Shared by the fast loop (:mod:`.loop`, :mod:`.kernel`) and the independent SciPy loop
(:mod:`.reference`), so that neither imports the other. Defaults follow the seed: plant step
1e-4 s, sample period 1 ms, perfect sensors (condition ix), no modelling error (condition vi), no
hand (condition vii), safety switch at 0.06 rad (Fig. 4.7).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from hapticdesign.analysis.kinematics import jacobian
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device

STATUS_COMPLETED = 0
STATUS_EXCURSION = 1
STATUS_DIVERGED = 2


@dataclass(frozen=True)
class Wall:
    """Virtual wall on one joint: spring ``stiffness`` (N m/rad), optional ``damping``, ``equilibrium``."""

    joint: int = 0
    stiffness: float = 1.0
    damping: float = 0.0
    equilibrium: float = 0.01


@dataclass(frozen=True)
class Compensator:
    """Inverse dynamics of a model device; ``error_percent`` scales its inertial parameters (§4.1.1.2)."""

    inertial: bool = True
    coriolis: bool = True
    gravity: bool = True
    error_percent: float = 0.0


@dataclass(frozen=True)
class Sensors:
    """Sampling period ``T``, optional encoder counts per revolution and delay in samples."""

    period: float = 1e-3
    counts_per_revolution: int | None = None
    delay_samples: int = 0


@dataclass(frozen=True)
class Hand:
    """Linear hand at the handle: mass (kg), damping (N s/m), stiffness (N/m), off by default.

    Mapped to the joints through the translational Jacobian at the start pose (a linearized grasp).
    """

    mass: float = 0.0
    damping: float = 0.0
    stiffness: float = 0.0


@dataclass(frozen=True)
class LoopConfig:
    """Everything but the device and the joint motions."""

    duration: float = 5.0
    step: float = 1e-4
    sensors: Sensors = field(default_factory=Sensors)
    compensator: Compensator = field(default_factory=Compensator)
    wall: Wall = field(default_factory=Wall)
    damping: tuple[float, ...] | None = None
    safety_limit: float | None = 0.06
    hand: Hand | None = None
    record_stride: int | None = None
    stop_excursion: float | None = None

    def steps_per_sample(self) -> int:
        if not (self.step > 0 and math.isfinite(self.step)):
            raise UserError(f"the plant step must be positive, got {self.step}")
        period = self.sensors.period
        if not (period > 0 and math.isfinite(period)):
            raise UserError(f"the sample period must be positive, got {period}")
        ratio = period / self.step
        if abs(ratio - round(ratio)) > 1e-9 * ratio or round(ratio) < 1:
            raise UserError(f"the plant step {self.step} s does not divide the sample period {period} s")
        return int(round(ratio))


@dataclass
class Trace:
    """Recorded signals (rows every ``stride`` plant steps) and how the run ended.

    ``peak`` is the largest excursion of the wall joint from its start, checked at every plant
    step (not only at the recorded rows); ``end_time`` is when the run ended (early when it
    diverged or reached the excursion stop)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    u: np.ndarray
    tau_f: np.ndarray
    tau_imp: np.ndarray
    tau_c: np.ndarray
    status: int
    trip_time: float | None
    peak: float = math.nan
    end_time: float = math.nan

    @property
    def diverged(self) -> bool:
        return self.status == STATUS_DIVERGED

    @property
    def stopped_at_excursion(self) -> bool:
        return self.status == STATUS_EXCURSION

    @property
    def tripped(self) -> bool:
        return self.trip_time is not None


def model_device(device: Device, error_percent: float) -> Device:
    """The compensator's device: every inertial parameter times ``1 - error_percent / 100``."""
    if not math.isfinite(error_percent) or error_percent > 100:
        raise UserError(f"error percentage must be a finite number <= 100, got {error_percent}")
    if error_percent == 0:
        return device
    factor = 1.0 - error_percent / 100.0
    return device.with_params({k: device.params.get(k, 0.0) * factor for k in device.inertial_names()})


def hand_matrices(device: Device, hand: Hand | None, q0: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hand mass, damping and stiffness in joint space: ``x J_v^T J_v`` at the start pose ``q0``."""
    n = len(q0)
    if hand is None:
        return np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    if min(hand.mass, hand.damping, hand.stiffness) < 0:
        raise UserError("hand mass, damping and stiffness must be non-negative")
    jv = jacobian(device.mechanism, q0)[:3]
    jtj = jv.T @ jv
    return hand.mass * jtj, hand.damping * jtj, hand.stiffness * jtj
