"""Prescribed joint paths: held, sinusoid (seed Table 4.3), linear chirp (seed §4.2.3).

Each path gives position, velocity and acceleration in closed form (the seed differentiates
numerically, eq. 4.3; analytic derivatives are the exact limit of that formula).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hapticdesign.errors import UserError


@dataclass(frozen=True)
class Held:
    """A joint locked at ``value`` (seed Table 4.3, type 1)."""

    value: float = 0.0

    def sample(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        z = np.zeros_like(t)
        return z + self.value, z, z


@dataclass(frozen=True)
class Sine:
    """``amplitude sin(omega t) + offset``; the seed's type 2 uses 0.52 sin(3 pi t) (Table 4.3)."""

    amplitude: float
    omega: float
    offset: float = 0.0

    def sample(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, c = np.sin(self.omega * t), np.cos(self.omega * t)
        a, w = self.amplitude, self.omega
        return self.offset + a * s, a * w * c, -a * w * w * s


@dataclass(frozen=True)
class Chirp:
    """Linear chirp ``A sin(phi(t))``, ``phi = 2 pi (f0 t + (f1 - f0) t^2 / (2 T_s))`` (seed §4.2.3).

    The sine form starts at rest position 0 (or ``offset``, a closed-loop device's home), matching the
    seed's zero initial conditions.
    """

    amplitude: float = 0.3
    f0: float = 0.1
    f1: float = 15.0
    sweep_time: float = 10.0
    offset: float = 0.0

    def __post_init__(self) -> None:
        if not (self.sweep_time > 0 and self.f0 >= 0 and self.f1 > 0):
            raise UserError("chirp: frequencies must be non-negative and the sweep time positive")
        if not all(math.isfinite(v) for v in (self.amplitude, self.f0, self.f1, self.sweep_time, self.offset)):
            raise UserError("chirp: amplitude, frequencies, sweep time and offset must be finite numbers")
        if self.amplitude == 0:
            raise UserError("chirp: the amplitude must not be zero (the joint would not move)")
        if not self.f0 < self.f1:
            raise UserError(f"chirp: the start frequency {self.f0:g} Hz must be below the end frequency {self.f1:g} Hz")

    def sample(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        rate = (self.f1 - self.f0) / self.sweep_time
        phase = 2 * np.pi * (self.f0 * t + 0.5 * rate * t * t)
        dphase = 2 * np.pi * (self.f0 + rate * t)
        ddphase = 2 * np.pi * rate
        a = self.amplitude
        s, c = np.sin(phase), np.cos(phase)
        return self.offset + a * s, a * c * dphase, a * (c * ddphase - s * dphase * dphase)


Path = Held | Sine | Chirp
