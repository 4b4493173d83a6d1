"""Device: a mechanism builder plus named parameters in the seed's names.

A device couples kinematic parameters (lengths, ``g``) that shape the mechanism with the
inertial parameters of its bodies (seed 000 Table 2.3 names: ``m2``, ``r2ax``, ``Ixy3a``, ...).
Overrides by name return a new device; unknown names and non-finite values are refused.

Actuators and joint limits (:mod:`hapticdesign.model.actuators`) ride along: ``damping`` is the
total viscous damping per coordinate (joints plus the diagonal of the actuators' ``b a a^T``),
``damping_matrix`` the whole matrix (off-diagonal terms from motors that turn a combination of
coordinates), ``friction`` the Coulomb friction of the motors with the combinations they turn,
``reflected_inertia`` the constant ``sum n^2 J_r a a^T`` added to H (seed 000 eq. 2.50), ``limits``
each coordinate's range or ``None``. ``elasticity``
(:mod:`hapticdesign.model.elastic`) names the elastic links and joint springs, when given.

A device knows no file format and owns no analysis: :func:`hapticdesign.devices.loading.load_device`
reads one from a file, and :mod:`hapticdesign.analysis.dynamics.device` gives its equations of motion.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property, lru_cache

import numpy as np

from hapticdesign.errors import PhysicalConsistencyWarning, UserError
from hapticdesign.model.actuators import (
    Actuator, Limits, Transmission, damping_matrix, full_turn, limit_warnings, motor_limit_warnings, reflected_inertia_matrix, transmission_of,
    transmission,
)
from hapticdesign.model.elastic import Elasticity
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

BoundsRow = tuple[tuple[float, float], tuple[float, float], tuple[float, float], float]
"""One body's practical bounds: (mass), (mass-centre coordinates), (moments) as lower, upper, and the
products' magnitude (:class:`hapticdesign.analysis.linearity.bounds.BodyBounds`'s fields)."""


@dataclass(frozen=True)
class PresetData:
    """What a device's source knows beyond its mechanism (seed 000's Phantom presets give the seed's); the
    generic engines read it here instead of knowing a device by its name.

    ``loop_settings`` is the loop settings its commands use by default (``practice``, or ``seed``: seed 000's
    settings and performance criteria); ``bounds`` its bodies' practical bounds for the linearity searches (none:
    the generic ones); ``dependents`` the seed's dependent variables of LN = 0 and ``pivots`` the standard
    parameters pivoted for them (none: chosen by the search)."""

    loop_settings: str = "practice"
    bounds: Mapping[str, BoundsRow] = field(default_factory=dict)
    dependents: tuple[str, ...] = ()
    pivots: tuple[str, ...] = ()


@dataclass(frozen=True)
class Device:
    """A device definition: name, kinematic parameter defaults, mechanism builder, parameter values."""

    name: str
    description: str
    kinematic: tuple[str, ...]
    builder: MechanismBuilder = field(compare=False, repr=False)
    params: Mapping[str, float] = field(default_factory=dict)
    damping: tuple[float, ...] = ()
    actuators: tuple[Actuator, ...] = ()
    limits: tuple[Limits, ...] = ()
    elasticity: Elasticity | None = None
    reference: str = ""
    """The published device a device file derives from (its ``reference:``), "" for one that is its own."""
    preset_data: PresetData = field(default_factory=PresetData, compare=False, repr=False)

    # -- parameters ---------------------------------------------------------------------------
    @property
    def mechanism(self) -> Mechanism:
        return build_mechanism(self.builder, self.kinematic_values())

    @property
    def n_dof(self) -> int:
        """Independent coordinates: the actuated joints (passive joints of closed loops are solved)."""
        return self.mechanism.n_actuated

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
        """A copy with some parameters replaced; unknown names, non-finite values, negative masses and a
        negative ``g`` raise."""
        if not isinstance(overrides, Mapping):
            raise UserError(f"parameter overrides must be a mapping of names to numbers, got {type(overrides).__name__}")
        known = set(self.parameter_names())
        masses = {seed_parameter_name("m", b) for b in self.body_names}
        merged = dict(self.params)
        for key, value in overrides.items():
            if key not in known:
                close = [k for k in known if k.lower() == str(key).lower()]
                hint = f" (did you mean {close[0]}?)" if close else ""
                raise UserError(f"unknown parameter name {key!r} for device {self.name}{hint}")
            if isinstance(value, (bool, np.bool_)):
                raise UserError(f"parameter {key}: {value!r} is not a number")
            try:
                val = float(value)
            except (TypeError, ValueError):
                raise UserError(f"parameter {key}: {value!r} is not a number") from None
            if not math.isfinite(val):
                raise UserError(f"parameter {key}: value must be finite, got {value!r}")
            if key in masses and val < 0:
                raise UserError(f"parameter {key}: negative mass {val:g} (a mass must be >= 0)")
            if key == "g" and val < 0:
                raise UserError(f"parameter g: gravity must be >= 0 m/s^2 (it points down the base z axis), got {val:g}")
            merged[key] = val
        return replace(self, params=merged)

    def body(self, name: str) -> BodyInertia:
        return BodyInertia(**{f: float(self.params.get(seed_parameter_name(f, name), 0.0)) for f in SEED_FIELDS})

    def seed_parameters(self) -> np.ndarray:
        """Seed-convention inertial parameters, (bodies, 10)."""
        return np.array([[float(self.params.get(seed_parameter_name(f, b), 0.0)) for f in SEED_FIELDS] for b in self.body_names])

    def standard_parameters(self) -> np.ndarray:
        """Standard inertial parameters, flat (10 x bodies,), in the regressor's column order (a fresh copy).

        Refuses parameters whose standard form overflows or holds a negative mass."""
        return self._standard.copy()

    @cached_property
    def _standard(self) -> np.ndarray:
        """:meth:`standard_parameters`, computed once per device value (the analyses ask for it often)."""
        seed = self.seed_parameters()
        with np.errstate(over="ignore", invalid="ignore"):
            standard = standard_from_seed(seed).ravel()
        if not np.all(np.isfinite(standard)):
            raise UserError(f"the inertial parameters of {self.name} overflow (m r or m r^2 is not a finite number)")
        if np.any(seed[:, 0] < 0):
            body = self.body_names[int(np.argmax(seed[:, 0] < 0))]
            raise UserError(f"body {body} of {self.name} has a negative mass")
        return standard

    def check(self, strict: bool = False) -> list[str]:
        """Physical consistency of every body; errors raise, triangle-inequality breaks warn."""
        reports = [check_body(b, self.body(b)) for b in self.body_names]
        found = require_consistent(reports, strict)
        for message in found:
            warnings.warn(message, PhysicalConsistencyWarning, stacklevel=2)
        return found

    # -- actuators and limits -----------------------------------------------------------------
    @property
    def reflected_inertia(self) -> np.ndarray:
        """``sum n^2 J_r a a^T`` (n_dof x n_dof; kg m^2 or kg), added to H; zeros without actuators."""
        return reflected_inertia_matrix(self.actuators, self.n_dof)

    @property
    def damping_matrix(self) -> np.ndarray:
        """The viscous damping matrix: ``diag(damping)`` plus the off-diagonal part of the motors' ``b a a^T``."""
        coupled = damping_matrix(self.actuators, self.n_dof)
        return np.diag(np.asarray(self.damping, dtype=float)) + coupled - np.diag(np.diag(coupled))

    @property
    def transmission(self) -> Transmission | None:
        """The motors' compliant transmissions over the coordinates (:class:`~hapticdesign.model.actuators.
        Transmission`), or None when the motors are rigid (no actuator states a ``transmission_stiffness``)."""
        return transmission_of(self.actuators, self.n_dof)

    @property
    def friction(self) -> tuple[np.ndarray, np.ndarray]:
        """The motors' Coulomb friction: ``(A, f)`` with ``A`` (k x n_dof) the combinations the k motors with
        friction turn and ``f`` (k,) their friction (N m or N): torque ``sum_k f_k sign(a_k^T qd) a_k``."""
        rubbing = tuple(a for a in self.actuators if a.coulomb > 0)
        return transmission(rubbing, self.n_dof), np.array([a.coulomb for a in rubbing], dtype=float)

    def joint_limits(self) -> tuple[Limits, ...]:
        """Each coordinate's range ``(low, high)`` in rad or m, or ``None`` where none is given."""
        return self.limits or (None,) * self.n_dof

    def joint_ranges(self) -> tuple[tuple[float, float], ...]:
        """Ranges for sampling poses (LN regions, metric maps): limits, else the full turn ``[-pi, pi]``."""
        return tuple(full_turn(span) for span in self.joint_limits())

    def limit_warnings(self, q: np.ndarray) -> list[str]:
        """One message per coordinate of ``q`` outside its limits, and per motor outside its travel (values
        outside are allowed)."""
        names = self.mechanism.actuated_coordinates
        return (limit_warnings(np.ravel(q), self.joint_limits(), names)
                + motor_limit_warnings(q, self.actuators, names))


@lru_cache(maxsize=64)
def build_mechanism(builder: MechanismBuilder, kinematic: tuple[tuple[str, float], ...]) -> Mechanism:
    """The mechanism of one geometry (cached: devices that differ only in inertial parameters share it)."""
    return builder(dict(kinematic))
