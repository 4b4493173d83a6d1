"""Device: a mechanism builder plus named parameters in the seed's names.

A device couples kinematic parameters (lengths, ``g``) that shape the mechanism with the
inertial parameters of its bodies (seed 000 Table 2.3 names: ``m2``, ``r2ax``, ``Ixy3a``, ...).
Overrides by name return a new device; unknown names and non-finite values are refused.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from hapticdesign.errors import PhysicalConsistencyWarning, UserError
from hapticdesign.model.inertia import (
    SEED_FIELDS,
    BodyInertia,
    check_body,
    require_consistent,
    seed_parameter_name,
    standard_from_seed,
)
from hapticdesign.model.mechanism import Mechanism

MechanismBuilder = Callable[[Mapping[str, float]], Mechanism]


@dataclass(frozen=True)
class Device:
    """A device definition: name, kinematic parameter defaults, mechanism builder, parameter values."""

    name: str
    description: str
    kinematic: tuple[str, ...]
    builder: MechanismBuilder = field(compare=False, repr=False)
    params: Mapping[str, float] = field(default_factory=dict)
    damping: tuple[float, ...] = ()

    @classmethod
    def from_file(cls, path) -> "Device":
        """A device from a device file (YAML, TOML, JSON) or a URDF file (see docs/device-files.md)."""
        from pathlib import Path

        from hapticdesign.devices.device_file import load_device_file

        return load_device_file(Path(path))

    # -- parameters ---------------------------------------------------------------------------
    @property
    def mechanism(self) -> Mechanism:
        return _build(self.builder, self.kinematic_values())

    @property
    def n_dof(self) -> int:
        return self.mechanism.n_dof

    @property
    def body_names(self) -> tuple[str, ...]:
        return self.mechanism.body_names

    def kinematic_values(self) -> tuple[tuple[str, float], ...]:
        return tuple((k, float(self.params[k])) for k in self.kinematic)

    def inertial_names(self) -> list[str]:
        return [seed_parameter_name(f, b) for b in self.body_names for f in SEED_FIELDS]

    def parameter_names(self) -> list[str]:
        return list(self.kinematic) + self.inertial_names()

    def with_params(self, overrides: Mapping[str, float]) -> "Device":
        """A copy with some parameters replaced; unknown names and non-finite values raise."""
        known = set(self.parameter_names())
        merged = dict(self.params)
        for key, value in overrides.items():
            if key not in known:
                close = [k for k in known if k.lower() == str(key).lower()]
                hint = f" (did you mean {close[0]}?)" if close else ""
                raise UserError(f"unknown parameter name {key!r} for device {self.name}{hint}")
            try:
                val = float(value)
            except (TypeError, ValueError):
                raise UserError(f"parameter {key}: {value!r} is not a number") from None
            if not math.isfinite(val):
                raise UserError(f"parameter {key}: value must be finite, got {value!r}")
            merged[key] = val
        return Device(self.name, self.description, self.kinematic, self.builder, merged, self.damping)

    def body(self, name: str) -> BodyInertia:
        return BodyInertia(**{f: float(self.params.get(seed_parameter_name(f, name), 0.0)) for f in SEED_FIELDS})

    def seed_parameters(self) -> np.ndarray:
        """Seed-convention inertial parameters, (bodies, 10)."""
        return np.array([[float(self.params.get(seed_parameter_name(f, b), 0.0)) for f in SEED_FIELDS] for b in self.body_names])

    def standard_parameters(self) -> np.ndarray:
        """Standard inertial parameters, flat (10 x bodies,), in the regressor's column order."""
        return standard_from_seed(self.seed_parameters()).ravel()

    def check(self, strict: bool = False) -> list[str]:
        """Physical consistency of every body; errors raise, triangle-inequality breaks warn."""
        reports = [check_body(b, self.body(b)) for b in self.body_names]
        found = require_consistent(reports, strict)
        for message in found:
            warnings.warn(message, PhysicalConsistencyWarning, stacklevel=2)
        return found

    # -- dynamics -----------------------------------------------------------------------------
    @property
    def model(self):
        """The compiled regressor model of the equations of motion (cached per geometry)."""
        from hapticdesign.analysis.dynamics.model import DynamicsModel

        return _model(DynamicsModel, self.builder, self.kinematic_values())

    def H(self, q: np.ndarray) -> np.ndarray:
        return self.model.H(q, self.standard_parameters())

    def C(self, q: np.ndarray) -> np.ndarray:
        return self.model.C(q, self.standard_parameters())

    def C_cvt(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        return self.model.C_cvt(q, qd, self.standard_parameters())

    def G(self, q: np.ndarray) -> np.ndarray:
        return self.model.G(q, self.standard_parameters())

    def inverse_dynamics(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        return self.model.inverse(q, qd, qdd, self.standard_parameters())

    def forward_dynamics(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return self.model.forward(q, qd, tau, self.standard_parameters())


@lru_cache(maxsize=64)
def _build(builder: MechanismBuilder, kinematic: tuple[tuple[str, float], ...]) -> Mechanism:
    return builder(dict(kinematic))


@lru_cache(maxsize=16)
def _model(cls, builder: MechanismBuilder, kinematic: tuple[tuple[str, float], ...]):
    return cls(_build(builder, kinematic))
