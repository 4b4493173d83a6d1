"""Design variables of a device file: what an optimization may change, and the device at chosen values.

A design variable is named as in a study file (issue 23):

- a ``parameters`` name of the file (geometry: a length, a motor spacing), m or rad;
- an inertial parameter by its seed name (seed 000 Table 2.3: ``m2``, ``r2x``, ``Ixx2``, ...) of a body the
  file gives by its parameters;
- ``links.<link>.D`` or ``links.<link>.d``: the outer or inner diameter (m) of an elastic link's section
  (``d`` of a tube only; a rod has ``D``);
- ``actuators.<joint>.<field>`` (or ``actuators.<k>.<field>``, ``k`` the 0-based place of the actuator in the
  file, for a motor that ``drives`` a combination): a numeric field of a motor, one of :data:`ACTUATOR_FIELDS`.

:class:`DesignSpace` reads and validates the file once and builds its device once. Each variable applies its value
by the one rule of its kind (:meth:`Variable.apply`, into an :class:`Applied` design); :meth:`DesignSpace.device`
builds the device of an applied design from the file's (no file is read again and no schema is run again) and
:meth:`DesignSpace.batch_values` the arrays of many. Each value is checked as the file's own validation checks it
(a finite number, ``D > d >= 0``, ``gear_ratio > 0``, a body's physical consistency, the loops closing at home,
...), and an invalid design raises a one-line :class:`UserError`. Bodies
that are links (``bodies: - {name: b, link: l}``) follow the lengths and sections: their mass and inertia are
computed again (:func:`~hapticdesign.devices.device_file.link_body_inertias`) whenever a parameter or a section
changes. :meth:`DesignSpace.batch_values` gives the same numbers and refusals for a whole generation of designs at
once, as the arrays the compiled kernels take (:class:`~hapticdesign.analysis.design_batch.DesignValues`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

import numpy as np
from pydantic import ValidationError

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.design_batch import DesignBatch, DesignValues
from hapticdesign.analysis.metrics import force
from hapticdesign.analysis.stiffness.device import LENGTH_TOLERANCE, check_elasticity
from hapticdesign.analysis.stiffness.link import rigidities, tube_rigidities
from hapticdesign.analysis.stiffness.sections import Tube
from hapticdesign.devices.device_file import (
    actuated_index,
    actuator_from_spec,
    chain_builder,
    describe_validation_error,
    device_from_spec,
    home_at,
    link_body_inertias,
    spec_from_mapping,
)
from hapticdesign.devices.schema import HOME_POSITION, ActuatorSpec, DeviceFileSpec
from hapticdesign.errors import UserError
from hapticdesign.files import quote
from hapticdesign.model.actuators import Transmission, damping_matrix
from hapticdesign.model.device import Device
from hapticdesign.model.elastic import Elasticity, ElasticLink
from hapticdesign.model.inertia import SEED_FIELDS, check_body, seed_parameter_name, standard_from_seed, tube_seed
from hapticdesign.model.params_io import read_mapping

ACTUATOR_FIELDS = ("rotor_inertia", "gear_ratio", "coulomb", "damping", "torque_continuous", "torque_peak",
                   "transmission_stiffness")
"""The numeric fields of a motor a design variable may change (units as in the device file)."""
ACTUATOR_UNITS = {"rotor_inertia": ("kg m^2", "kg m^2"), "gear_ratio": ("1", "rad/m"), "coulomb": ("N m", "N"),
                  "damping": ("N m s/rad", "N s/m"), "torque_continuous": ("N m", "N m"), "torque_peak": ("N m", "N m"),
                  "transmission_stiffness": ("N m/rad", "N/m")}
"""Units of :data:`ACTUATOR_FIELDS` on a revolute and on a prismatic joint (the torques are the motor's own)."""
MOTOR_SETS = 4096
"""Distinct sets of motor values whose matrices :meth:`DesignSpace.batch_values` keeps (a study's discrete ratios are
a few; continuous motor variables give one per design, so the cache starts again past this many)."""


@dataclass(frozen=True)
class Variable:
    """One design variable: its name, what it changes (``parameter``, ``inertial``, ``section``, ``actuator``),
    the place it changes (a parameter or body name, a link's or an actuator's index) and the field."""

    name: str
    kind: str
    target: str | int
    field: str = ""

    def file_value(self, spec: DeviceFileSpec, params: Mapping[str, float]) -> float:
        """Its value in the device file ``spec`` whose parameters are ``params`` (NaN for an actuator field the file
        leaves unset)."""
        if self.kind in ("parameter", "inertial"):
            return float(params[self.name])
        if self.kind == "section":
            return float(getattr(spec.links[self.target].section, self.field))
        value = getattr(spec.actuators[self.target], self.field)
        return math.nan if value is None else float(value)

    def unit(self, spec: DeviceFileSpec) -> str:
        """Its unit in the device file ``spec``: a parameter's rad where a rotation (a frame's Rx, Ry, Rz or a DH row's
        alpha, theta) reads it, else m; an inertial parameter's kg, m or kg m^2; a section's m; a motor field's unit
        on the joint it drives (revolute: N m, prismatic: N; :data:`ACTUATOR_FIELDS`)."""
        if self.kind == "parameter":
            rotations = [t.value for frame in spec.frames for t in frame.transforms if t.axis.is_rotation]
            rotations += [e for row in spec.dh for e in (row.alpha, row.theta)]
            return "rad" if any(self.name in e.names for e in rotations) else "m"
        if self.kind == "inertial":
            field = next(f for f in SEED_FIELDS if seed_parameter_name(f, self.target) == self.name)
            return "kg" if field == "m" else "m" if field.startswith("r") else "kg m^2"
        if self.kind == "section":
            return "m"
        actuator = spec.actuators[self.target]
        joints = {j.name: j.type for j in spec.joints}
        driven = [actuator.joint] if actuator.joint else list(actuator.drives.names)
        prismatic = any(joints.get(name) == "prismatic" for name in driven)
        return ACTUATOR_UNITS[self.field][prismatic]

    def write(self, data: dict, value: float) -> None:
        """Write ``value`` where the variable sits in the device file's mapping ``data`` (a design written back)."""
        if self.kind == "parameter":
            data["parameters"][self.name] = value
        elif self.kind == "inertial":
            body = next(b for b in data["bodies"] if str(b["name"]) == self.target)
            body[next(f for f in SEED_FIELDS if seed_parameter_name(f, self.target) == self.name)] = value
        elif self.kind == "section":
            data["links"][self.target]["section"][self.field] = value
        else:
            data["actuators"][self.target][self.field] = value

    def apply(self, design: "Applied", value: float) -> None:
        """Apply ``value`` to one ``design``: the one rule of this variable's kind, which both the device of
        :meth:`DesignSpace.device` and the arrays of :meth:`DesignSpace.batch_values` are built from."""
        if self.kind in ("parameter", "inertial"):
            design.params[self.name] = value
            if self.kind == "inertial":
                design.bodies.add(self.target)
            else:
                design.geometry.add(self.name)
        elif self.kind == "section":
            design.sections.setdefault(self.target, {})[self.field] = value
        else:
            design.motors.setdefault(self.target, {})[self.field] = value


@dataclass
class Applied:
    """One design's values (:meth:`DesignSpace.applied`), by what they change: parameters (geometry) and inertial
    parameters by name, the names of the changed geometry parameters and bodies, the sections' diameters and the
    motors' fields by link and actuator index."""

    params: dict[str, float] = field(default_factory=dict)
    geometry: set[str] = field(default_factory=set)
    bodies: set[str] = field(default_factory=set)
    sections: dict[int, dict[str, float]] = field(default_factory=dict)
    motors: dict[int, dict[str, float]] = field(default_factory=dict)

    @property
    def motor_key(self) -> tuple:
        """The motors' changes as a key (actuator index and its changed fields, sorted)."""
        return tuple(sorted((k, tuple(sorted(f.items()))) for k, f in self.motors.items()))


class Motors(NamedTuple):
    """A design's motors (:meth:`DesignSpace._motors`): the actuators and the joints' damping of its device, and
    what the batched kernels take of them: the reflected inertia, the damping matrix ``B``, ``A^-1`` (None unless
    one motor per coordinate) and ``n_k tau_k`` per torque kind (None where a motor lacks it)."""

    actuators: tuple
    damping: tuple
    reflected: np.ndarray
    damping_matrix: np.ndarray
    motor_map: np.ndarray | None
    torques: dict
    transmission: Transmission | None


class DesignSpace:
    """The design variables ``names`` of the device file ``source`` (a path or its parsed mapping)."""

    def __init__(self, source: str | Path | Mapping, names: Iterable[str]):
        where = "device file" if isinstance(source, Mapping) else str(source)
        if isinstance(source, Mapping):
            data = dict(source)
        else:
            path = Path(source)
            if path.suffix.lower() == ".urdf":
                raise UserError(f"{where}: design variables need a device file (YAML, TOML or JSON), not a URDF file")
            data = read_mapping(path)
        self.spec: DeviceFileSpec = spec_from_mapping(data, where)
        try:
            self.base: Device = device_from_spec(self.spec)
        except UserError as exc:
            raise UserError(f"{where}: {exc}") from None
        self.variables: tuple[Variable, ...] = tuple(self._variable(str(name)) for name in names)
        taken = [v.name for v in self.variables]
        twice = sorted({n for n in taken if taken.count(n) > 1})
        if twice:
            raise UserError(f"design variable {twice[0]} is given twice")
        self.names: tuple[str, ...] = tuple(taken)
        self._index = actuated_index(self.spec)
        self._joint_damping = np.array([j.damping for j in self.spec.joints if j.actuated], dtype=float)
        self.link_bodies = any(b.link is not None for b in self.spec.bodies)
        """Whether bodies are links (``bodies: - {link: ...}``), whose masses follow lengths and sections."""
        self.cache: dict[str, object] = {}
        """What a caller builds once per space (the batched kernels' structure, ...)."""
        position = self.spec.home.get(HOME_POSITION)
        self.home_position = np.array(position, dtype=float) if isinstance(position, list) else None
        """The handle's home position of a device whose file gives one: each design's home follows it
        (:meth:`_home_follows`; the batched kernels reach it first)."""

    # -- names --------------------------------------------------------------------------------
    def _variable(self, name: str) -> Variable:
        spec, base = self.spec, self.base
        if name in spec.parameters:
            return Variable(name, "parameter", name)
        bodies = {seed_parameter_name(f, b.name): b for b in spec.bodies for f in SEED_FIELDS}
        if name in bodies:
            body = bodies[name]
            if body.link is not None:
                raise UserError(f"design variable {name}: body {body.name} is link {body.link}'s tube, its mass and "
                                f"inertia follow the link (vary links.{body.link}.D or .d, or the lengths)")
            return Variable(name, "inertial", body.name)
        parts = name.split(".")
        if len(parts) == 3 and parts[0] == "links":
            return self._section(name, parts[1], parts[2])
        if len(parts) == 3 and parts[0] == "actuators":
            return self._actuator(name, parts[1], parts[2])
        known = ", ".join(spec.parameters) or "none"
        raise UserError(f"unknown design variable {quote(name)} for device {base.name}: use a parameter ({known}), an "
                        "inertial parameter by its seed name (such as m2), links.<link>.D or .d, or "
                        "actuators.<joint>.<field>")

    def _section(self, name: str, link: str, field: str) -> Variable:
        links = [entry.name for entry in self.spec.links]
        if link not in links:
            raise UserError(f"design variable {name}: device {self.base.name} has no link {link!r} (links: "
                            f"{', '.join(links) or 'none'})")
        wanted = ("D", "d") if self.spec.links[links.index(link)].section.d > 0.0 else ("D",)
        if field not in wanted:
            raise UserError(f"design variable {name}: link {link}'s section has {' and '.join(wanted)} (m)"
                            + ("" if "d" in wanted else "; a rod has no inner diameter"))
        return Variable(name, "section", links.index(link), field)

    def _actuator(self, name: str, which: str, field: str) -> Variable:
        actuators = self.spec.actuators
        by_joint = {a.joint: k for k, a in enumerate(actuators) if a.joint is not None}
        if which in by_joint:
            k = by_joint[which]
        elif which.isdigit() and int(which) < len(actuators):
            k = int(which)
        else:
            known = ", ".join([*by_joint, *(str(k) for k, a in enumerate(actuators) if a.joint is None)]) or "none"
            raise UserError(f"design variable {name}: device {self.base.name} has no actuator {which!r} (actuators "
                            f"by joint or place: {known})")
        if field not in ACTUATOR_FIELDS:
            raise UserError(f"design variable {name}: an actuator's variable is one of {', '.join(ACTUATOR_FIELDS)}")
        return Variable(name, "actuator", k, field)

    def defaults(self) -> dict[str, float]:
        """Each variable's value in the file (NaN for an actuator field the file leaves unset)."""
        return {v.name: v.file_value(self.spec, self.base.params) for v in self.variables}

    # -- designs ------------------------------------------------------------------------------
    def checked_values(self, values: Mapping[str, float]) -> dict[str, float]:
        """``values`` as floats, each of a variable of this space and a finite number (one-line UserError)."""
        out = {}
        for name, raw in values.items():
            if name not in self.names:
                raise UserError(f"{name!r} is not a design variable of this study (variables: {', '.join(self.names)})")
            out[name] = _number(name, raw)
        return out

    def applied(self, values: Mapping[str, float]) -> Applied:
        """``values`` (variable name to number) applied, each by its variable's rule (:meth:`Variable.apply`), and
        checked as the device file's validation checks them: a known name and a finite number, each changed body's
        physical consistency, each changed section (``D > d >= 0``) and motor (its fields, ``torque_peak`` not below
        ``torque_continuous``). Raises a one-line UserError for a design the device file refuses."""
        by_name = {v.name: v for v in self.variables}
        design = Applied()
        for name, value in self.checked_values(values).items():
            by_name[name].apply(design, value)
        if design.bodies:
            device = self.base.with_params({name: design.params[name] for name in design.params
                                            if name not in design.geometry})
            for body in sorted(design.bodies):
                report = check_body(body, device.body(body))
                if report.error:
                    raise UserError(report.error)
        self._sections(design.sections)
        self._motors(design.motor_key)
        return design

    def device(self, values: Mapping[str, float]) -> Device:
        """The device with ``values`` (variable name to number) applied (:meth:`applied`); the others keep the
        file's values.

        Raises a one-line UserError for an unknown name, a value that is not a finite number, and a design the
        device file's validation refuses."""
        design = self.applied(values)
        device = self.base.with_params(design.params) if design.params else self.base
        tubes = self._sections(design.sections)
        if design.sections:
            device = replace(device, elasticity=self._elasticity(tubes))
        if design.motors:
            motors = self._motors(design.motor_key)
            device = replace(device, actuators=motors.actuators, damping=motors.damping)
        if design.geometry:
            device = self._home_follows(device)
            self._check_geometry(device)
        if self.link_bodies and (design.geometry or design.sections):
            inertias = link_body_inertias(self.spec, device.mechanism, tubes)
            device = device.with_params({seed_parameter_name(f, body): float(getattr(inertia, f))
                                         for body, inertia in inertias.items() for f in SEED_FIELDS})
        return device

    def _home_follows(self, device: Device) -> Device:
        """A device whose file gives its home as a handle position (``home: {position: ...}``) keeps the handle
        there: the home joint values move with the geometry (the inverse kinematics from the file's home, as the
        file's own loading does), so a design whose loops do not close at the file's joint home is not refused
        for it."""
        position = self.spec.home.get(HOME_POSITION)
        if not isinstance(position, list):
            return device
        return replace(device, builder=chain_builder(self.spec, home_at(device, position)))

    def _sections(self, sections: dict[int, dict[str, float]]) -> dict[str, Tube]:
        """The links' sections with ``sections`` (link index to changed sizes) applied, by link name."""
        out = {}
        for k, spec in enumerate(self.spec.links):
            section = spec.section
            if k in sections:
                sizes = {"D": section.D, "d": section.d, **sections[k]}
                try:
                    section = Tube(sizes["D"], sizes["d"])
                except UserError as exc:
                    raise UserError(f"link {spec.name}: {exc}") from None
            out[spec.name] = section
        return out

    def _elasticity(self, tubes: dict[str, Tube]) -> Elasticity:
        links = tuple(ElasticLink(spec.name, spec.start, spec.end, *rigidities(spec.material, tubes[spec.name]))
                      for spec in self.spec.links)
        joints = self.base.elasticity.joints if self.base.elasticity is not None else ()
        return Elasticity(links, joints)

    def _with_actuators(self, fields: dict[int, dict[str, float]]) -> Device:
        """The file's device with the motors' ``fields`` (actuator index to changed fields), validated as the file's
        own loading validates them."""
        device = self.base
        actuators = list(device.actuators)
        for k, change in fields.items():
            spec = self.spec.actuators[k]
            try:
                checked = ActuatorSpec.model_validate({**dict(spec), **change})
            except ValidationError as exc:
                raise UserError(f"actuators[{k}].{describe_validation_error(exc)}") from None
            if (checked.torque_continuous is not None and checked.torque_peak is not None
                    and checked.torque_peak < checked.torque_continuous):
                raise UserError(f"actuators[{k}].torque_peak: {checked.torque_peak:g} N m is below torque_continuous "
                                f"{checked.torque_continuous:g} N m")
            actuators[k] = actuator_from_spec(checked, self._index)
        damping = self._joint_damping + np.diag(damping_matrix(tuple(actuators), len(self._joint_damping)))
        return replace(device, actuators=tuple(actuators), damping=tuple(float(b) for b in damping))

    def batch_values(self, designs: Sequence[Mapping[str, float]], batch: DesignBatch) -> DesignValues:
        """What :meth:`device` gives each of ``designs``, as the arrays of many designs ``batch`` takes
        (:class:`~hapticdesign.analysis.design_batch.DesignValues`): the same numbers and the same refusals, with
        the links' bodies and sections computed for all designs at once and each distinct set of motor values built
        once. A design the device file refuses keeps the file's values and says why."""
        count, base = len(designs), self.base
        column = {name: k for k, name in enumerate(batch.names)}
        kinematic = np.tile(batch.p0, (count, 1))
        seed_file = base.seed_parameters()
        diameters_file = np.array([[link.section.D, link.section.d] for link in self.spec.links]).reshape(-1, 2)
        seed, diameters = np.tile(seed_file, (count, 1, 1)), np.tile(diameters_file, (count, 1, 1))
        refused: list[str | None] = [None] * count
        motors: list[tuple] = [()] * count
        seed_place = {seed_parameter_name(f, body): (b, k) for b, body in enumerate(base.body_names)
                      for k, f in enumerate(SEED_FIELDS)}
        for d, values in enumerate(designs):
            try:
                design = self.applied(values)
            except UserError as exc:
                refused[d] = str(exc)
                continue
            for name, value in design.params.items():
                if name in design.geometry:
                    kinematic[d, column[name]] = value
                else:
                    seed[(d, *seed_place[name])] = value
            for k, sizes in design.sections.items():
                for name, value in sizes.items():
                    diameters[d, k, ("D", "d").index(name)] = value
            motors[d] = design.motor_key
        pairs = [(link.start, link.end) for link in self.spec.links]
        vectors = batch.frame_vectors(batch.offsets(kinematic), pairs)
        lengths = np.linalg.norm(vectors[:, :, 0], axis=-1)
        for d, k in zip(*np.nonzero(lengths <= LENGTH_TOLERANCE)):
            if refused[d] is None:
                link = self.spec.links[k]
                refused[d] = f"link {link.name}: frames {link.start!r} and {link.end!r} coincide (zero length)"
                kinematic[d], vectors[d] = batch.p0, batch.frame_vectors(batch.offsets(batch.p0), pairs)[0]
        rigidity = np.zeros((count, len(self.spec.links), 3))
        for k, link in enumerate(self.spec.links):
            rigidity[:, k] = np.stack(tube_rigidities(link.material, diameters[:, k, 0], diameters[:, k, 1]), axis=-1)
        if self.link_bodies:
            rows = {name: b for b, name in enumerate(base.body_names)}
            links = {link.name: k for k, link in enumerate(self.spec.links)}
            for body in self.spec.bodies:
                if body.link is not None:
                    k = links[body.link]
                    seed[:, rows[body.name]] = tube_seed(vectors[:, k, 0], diameters[:, k, 0], diameters[:, k, 1],
                                                         self.spec.links[k].material.density)
        with np.errstate(over="ignore", invalid="ignore"):
            standard = standard_from_seed(seed).reshape(count, -1)
        for d in np.flatnonzero(~np.all(np.isfinite(standard), axis=1)):
            if refused[d] is None:
                refused[d] = f"the inertial parameters of {base.name} overflow (m r or m r^2 is not a finite number)"
        built = [self._motors(key) for key in motors]
        torques = {which: None if any(b.torques[which] is None for b in built)
                   else np.array([b.torques[which] for b in built]) for which in ("continuous", "peak")}
        inverse = None if any(b.motor_map is None for b in built) else np.array([b.motor_map for b in built])
        compliant = [b.transmission is not None for b in built]
        if any(compliant) and not all(compliant):
            raise UserError("design variables may change a transmission_stiffness, not add or remove one")
        transmission = Transmission(*(np.array(x) for x in zip(*(b.transmission for b in built)))) if all(
            compliant) and built else None
        return DesignValues(kinematic, standard, np.array([b.reflected for b in built]),
                            np.array([b.damping_matrix for b in built]),
                            inverse, torques, rigidity, refused, transmission,
                            np.array([damping_matrix(b.actuators, base.n_dof) for b in built]))

    def _motors(self, key: tuple) -> "Motors":
        """The motors with the changes ``key`` (:attr:`Applied.motor_key`), built and validated once per distinct
        set."""
        motors = self.cache.setdefault("motors", {})
        if key not in motors:
            if len(motors) >= MOTOR_SETS:
                motors.clear()
            device = self._with_actuators({k: dict(f) for k, f in key}) if key else self.base
            motors[key] = Motors(device.actuators, device.damping, device.reflected_inertia, device.damping_matrix,
                                 force.motor_map(device),
                                 {which: force.torque_limits(device, which) for which in ("continuous", "peak")},
                                 device.transmission)
        return motors[key]

    @staticmethod
    def _check_geometry(device: Device) -> None:
        """What the file's loading checks of a geometry: the links' frames apart, the loops closing at home."""
        mechanism = device.mechanism
        if device.elasticity is not None:
            check_elasticity(mechanism, device.elasticity)
        configuration_of(device)


def _number(name: str, value: object) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise UserError(f"design variable {name}: {value!r} is not a number")
    value = float(value)
    if not math.isfinite(value):
        raise UserError(f"design variable {name}: value must be finite, got {value!r}")
    return value


def design_space(source: str | Path | Mapping, names: Iterable[str]) -> DesignSpace:
    """The design variables ``names`` of the device file ``source`` (see the module docstring)."""
    return DesignSpace(source, names)
