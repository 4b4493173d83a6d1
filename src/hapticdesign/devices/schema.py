"""Device file schema: pydantic models and the value grammar of a device file (docs/device-files.md).

A device file is data, never code. Geometric values are *affine expressions*, parsed by the tiny
grammar below (no ``eval``, no SymPy):

    expression := [sign] term (sign term)*
    term       := number | [number '*'] atom ['/' number]
    atom       := name | 'pi'

where ``name`` is a kinematic parameter (``l2``, a constant of the geometry) or a joint coordinate
(``theta3``). Examples: ``0.3``, ``l2``, ``-l2a``, ``-pi/2``, ``2*pi/3``, ``-theta3``,
``theta5 - pi/2`` (seed 000 Table 2.5), ``theta1 - theta2`` (a parallelogram coupling, eq. 2.38-2.43).
An expression evaluates to ``offset + sum_k c_k q_k``: the :class:`~hapticdesign.model.transforms.JointValue`
of an elementary transform.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from typing import Annotated, Literal

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, InstanceOf, model_validator

from hapticdesign.analysis.stiffness.materials import LAMINATE_DENSITY, MATERIALS, LinkModuli, isotropic, laminate
from hapticdesign.analysis.stiffness.sections import Tube
from hapticdesign.devices.builder import BODY_NAME_PATTERN, IDENTIFIER_PATTERN, LinearExpr, TransformSpec
from hapticdesign.errors import UserError
from hapticdesign.model.inertia import SEED_FIELDS, BodyInertia, check_body
from hapticdesign.model.loops import component_indices, handle_position
from hapticdesign.model.transforms import Axis

RESERVED = ("pi", "g", "base")
_NUMBER = r"(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_TOKEN = re.compile(rf"\s*(?:(?P<number>{_NUMBER})|(?P<name>[A-Za-z_]\w*)|(?P<op>[-+*/]))")


def _tokens(text: str) -> list[tuple[str, str]]:
    out, pos, text = [], 0, text.rstrip()
    while pos < len(text):
        match = _TOKEN.match(text, pos)
        if match is None:
            raise ValueError(f"cannot read {text!r} at {text[pos:].strip()!r}")
        kind = match.lastgroup
        out.append((kind, match.group(kind)))
        pos = match.end()
    return out


_TERM_SHAPES = ("n", "a", "n*a", "a/n", "n*a/n", "n/n")


def parse_expression(text: str) -> LinearExpr:
    """Parse an affine expression of the grammar in the module docstring."""
    usage = f"{text!r} is not an affine expression such as 0.3, l2, -pi/2, 2*pi/3 or theta5 - pi/2"
    terms: list[tuple[float, list[tuple[str, str]]]] = []
    sign, pending, current = 1.0, False, []
    for kind, token in _tokens(text):
        if kind == "op" and token in "+-":
            if current:
                terms.append((sign, current))
                current = []
            elif pending or terms:
                raise ValueError(usage)
            sign, pending = (-1.0 if token == "-" else 1.0), True
        else:
            current.append((kind, token))
    if not current:
        raise ValueError(usage)
    terms.append((sign, current))
    constant, linear = 0.0, {}
    for sign, term in terms:
        shape = "".join({"number": "n", "name": "a"}.get(kind, token) for kind, token in term)
        if shape not in _TERM_SHAPES:
            raise ValueError(usage)
        numbers = [float(token) for kind, token in term if kind == "number"]
        atom = next((token for kind, token in term if kind == "name"), None)
        coef = sign * (numbers[0] if shape[0] == "n" else 1.0)
        if shape.endswith("/n"):
            if numbers[-1] == 0.0:
                raise ValueError(f"{text!r}: division by zero")
            coef /= numbers[-1]
        if atom is None:
            constant += coef
        elif atom == "pi":
            constant += coef * math.pi
        else:
            linear[atom] = linear.get(atom, 0.0) + coef
    return LinearExpr(constant, tuple((k, v) for k, v in linear.items() if v != 0.0))


def _expression(value: object) -> LinearExpr:
    if isinstance(value, LinearExpr):
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ValueError(f"expected a number or an expression such as -pi/2 or l2, got {value!r}")
    if isinstance(value, str):
        return parse_expression(value)
    if not math.isfinite(value):
        raise ValueError(f"expected a finite number, got {value!r}")
    return LinearExpr(float(value))


def _constant(value: object) -> float:
    """A number; strings are parsed too, because YAML 1.1 reads ``1e-3`` (no dot) as a string."""
    expr = _expression(value)
    if expr.terms:
        raise ValueError(f"{value!r} must be a number (pi-multiples allowed), not depend on {', '.join(expr.names)}")
    if not math.isfinite(expr.constant):
        raise ValueError(f"expected a finite number, got {value!r}")
    return expr.constant


def _name(value: object) -> object:
    return str(value) if isinstance(value, int) and not isinstance(value, bool) else value


Expression = Annotated[LinearExpr, BeforeValidator(_expression)]
HOME_POSITION = "position"
"""The key of ``home`` that gives the handle's home position instead of joint values."""
Number = Annotated[float, BeforeValidator(_constant)]
Identifier = Annotated[str, Field(pattern=IDENTIFIER_PATTERN)]
Name = Annotated[str, BeforeValidator(_name), Field(min_length=1, max_length=200)]
BodyName = Annotated[str, BeforeValidator(_name), Field(pattern=BODY_NAME_PATTERN, max_length=64)]
AXES = {"Rx": Axis.RX, "Ry": Axis.RY, "Rz": Axis.RZ, "tx": Axis.TX, "ty": Axis.TY, "tz": Axis.TZ}


def _transform(value: object) -> TransformSpec:
    if isinstance(value, TransformSpec):
        return value
    if not isinstance(value, dict) or len(value) != 1:
        raise ValueError(f"a transform is one pair such as 'Rz: theta3' or 'tz: l3a', got {value!r}")
    (key, raw), = value.items()
    if key not in AXES:
        raise ValueError(f"unknown transform {key!r}; use one of {', '.join(AXES)}")
    return TransformSpec(AXES[key], _expression(raw))


Transform = Annotated[TransformSpec, BeforeValidator(_transform)]


class _FileModel(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class JointSpec(_FileModel):
    """An independent coordinate: its name, type, viscous damping (N m s/rad or N s/m) and optional
    range ``limits: [low, high]`` (rad or m; the default region of LN and of metric maps)."""

    name: Identifier
    type: Literal["revolute", "prismatic"] = "revolute"
    damping: Annotated[Number, Field(ge=0.0)] = 0.0
    limits: tuple[Number, Number] | None = None
    actuated: bool = True


class ActuatorSpec(_FileModel):
    """A motor on ``joint``, or on the affine combination ``drives`` of actuated coordinates (such as
    ``theta2 + theta3``; :mod:`hapticdesign.model.actuators`): rotor inertia [kg m^2], transmission
    ratio (rotor rad per joint rad or m), Coulomb friction (N m or N) and viscous damping on the side of
    what it turns, and optional ``limits`` of its travel (of ``drives``, in joint units); the motor's
    continuous and peak torque (N m at the motor) and its encoder's counts per revolution and
    quadrature factor, where known; ``transmission_stiffness`` the stiffness between the motor and what it turns,
    at the joint side (N m/rad or N/m; absent: rigid), given for every actuator or none."""

    joint: Identifier | None = None
    drives: Expression | None = None
    limits: tuple[Number, Number] | None = None
    rotor_inertia: Annotated[Number, Field(ge=0.0)] = 0.0
    gear_ratio: Annotated[Number, Field(gt=0.0)] = 1.0
    coulomb: Annotated[Number, Field(ge=0.0)] = 0.0
    damping: Annotated[Number, Field(ge=0.0)] = 0.0
    torque_continuous: Annotated[Number, Field(gt=0.0)] | None = None
    torque_peak: Annotated[Number, Field(gt=0.0)] | None = None
    encoder_cpr: Annotated[int, Field(strict=True, gt=0, le=10**9)] | None = None
    quadrature: Literal[1, 2, 4] = 4
    transmission_stiffness: Annotated[Number, Field(gt=0.0)] | None = None

    @model_validator(mode="after")
    def _reflected_finite(self) -> "ActuatorSpec":
        """The rotor inertia reflected through the ratio and the largest coefficient of ``drives``,
        ``rotor_inertia gear_ratio^2 c^2``, must be a finite number (it enters the mass matrix)."""
        reflected = self.rotor_inertia * self.gear_ratio ** 2 * MAX_COEFFICIENT ** 2
        if not math.isfinite(reflected):
            raise ValueError(f"the actuator of {self.joint or self.drives}: rotor_inertia {self.rotor_inertia:g} "
                             f"reflected through gear_ratio {self.gear_ratio:g} overflows (rotor_inertia x "
                             "gear_ratio^2 must be a finite number)")
        return self


def _components(value: object) -> tuple[int, ...]:
    if isinstance(value, tuple) and all(isinstance(v, int) for v in value):
        return value
    if not isinstance(value, (str, list, tuple)):
        raise ValueError(f"close: expected position, pose or a list such as [x, z], got {value!r}")
    return component_indices(value if isinstance(value, str) else [str(v) for v in value])


class LoopSpec(_FileModel):
    """A loop closure (:mod:`hapticdesign.model.loops`): ``frames`` coincide in the ``close`` components."""

    frames: tuple[Name, Name]
    close: Annotated[tuple[int, ...], BeforeValidator(_components)]


class DHRowSpec(_FileModel):
    """One row of a seed-000 DH table (eq. 2.26): frames ``body<name>`` and ``link<name>``."""

    name: BodyName | None = None
    a: Expression = LinearExpr()
    alpha: Expression = LinearExpr()
    s: Expression = LinearExpr()
    theta: Expression = LinearExpr()


class FrameSpec(_FileModel):
    """A frame placed on ``parent`` by a sequence of elementary transforms."""

    name: Identifier
    parent: Name = "base"
    transforms: list[Transform] = Field(min_length=1)


class BodySpec(_FileModel):
    """A rigid body on ``frame`` with the seed's inertial parameters (Table 2.3), or the tube or rod of an elastic
    ``link`` (its mass and inertia follow the link's length, section and material density:
    :func:`hapticdesign.model.inertia.tube_body`)."""

    name: BodyName
    frame: Name | None = None
    link: BodyName | None = None
    m: Number = 0.0
    rx: Number = 0.0
    ry: Number = 0.0
    rz: Number = 0.0
    Ixx: Number = 0.0
    Iyy: Number = 0.0
    Izz: Number = 0.0
    Ixy: Number = 0.0
    Ixz: Number = 0.0
    Iyz: Number = 0.0

    def inertia(self) -> BodyInertia:
        return BodyInertia(**{f: getattr(self, f) for f in SEED_FIELDS})


SECTIONS = {"tube": ("D", "d"), "rod": ("D",)}
"""Cross-section shapes of a link and their dimensions (m): a tube's outer and inner diameters, a rod's
diameter (eq. 5.162-5.165; a rod is a tube with ``d = 0``)."""
_MATERIAL_USAGE = (f"a material is one of {', '.join(MATERIALS)}, {{E: ..., G: ...}} (or {{E: ..., nu: ...}}, Pa; "
                   "optional density: kg/m^3) or {laminate: [a, b, c, d]} (M55J plies at 0, 90, -45, 45 degrees; "
                   f"optional density, default {LAMINATE_DENSITY:g} kg/m^3)")


def _section(value: object) -> Tube:
    if isinstance(value, Tube):
        return value
    if not isinstance(value, dict) or value.get("shape") not in SECTIONS:
        shape = value.get("shape") if isinstance(value, dict) else None
        known = ", ".join(SECTIONS)
        raise ValueError(f"unknown section shape {shape!r}; use {known}: {{shape: tube, D: 0.02, d: 0.016}} or "
                         "{shape: rod, D: 0.01} (diameters in m)")
    wanted = SECTIONS[value["shape"]]
    extra = [k for k in value if k != "shape" and k not in wanted]
    missing = [k for k in wanted if k not in value]
    if extra or missing:
        problem = f"unknown key {extra[0]!r}" if extra else f"missing {missing[0]!r}"
        raise ValueError(f"{problem}: a {value['shape']} section takes {', '.join(wanted)} (m)")
    try:
        return Tube(_constant(value["D"]), _constant(value.get("d", 0.0)))
    except UserError as exc:
        raise ValueError(str(exc)) from None


def _material(value: object) -> LinkModuli:
    if isinstance(value, LinkModuli):
        return value
    if isinstance(value, str):
        if value not in MATERIALS:
            raise ValueError(f"unknown material {value!r}; {_MATERIAL_USAGE}")
        return MATERIALS[value]
    try:
        if (isinstance(value, dict) and set(value) - {"density"} == {"laminate"}
                and isinstance(value["laminate"], list)):
            density = _density(value.get("density", LAMINATE_DENSITY))
            return replace(laminate(tuple(_constant(n) for n in value["laminate"])), density=density)
        if isinstance(value, dict) and "E" in value and set(value) <= {"E", "G", "nu", "density"}:
            G = _constant(value["G"]) if "G" in value else None
            density = _density(value["density"]) if "density" in value else None
            return isotropic(_constant(value["E"]), G, _constant(value.get("nu", 0.3)), density)
    except UserError as exc:
        raise ValueError(str(exc)) from None
    raise ValueError(_MATERIAL_USAGE)


def _density(value: object) -> float:
    density = _constant(value)
    if not density > 0.0:
        raise ValueError(f"a material's density must be positive (kg/m^3), got {density:g}")
    return density


class LinkSpec(_FileModel):
    """An elastic link (seed 001 §5.2): a straight beam from frame ``from`` to frame ``to`` (no joint
    between them) with a cross-section and a material (:mod:`hapticdesign.model.elastic`)."""

    name: BodyName
    start: Name = Field(alias="from")
    end: Name = Field(alias="to")
    section: Annotated[InstanceOf[Tube], BeforeValidator(_section)]
    material: Annotated[InstanceOf[LinkModuli], BeforeValidator(_material)]


class DeviceFileSpec(_FileModel):
    """A whole device file; cross references are checked after the fields (:func:`_check`)."""

    name: Name
    description: str = ""
    reference: Name | None = None
    """The published device this file derives from (``falcon``, ``phantom-premium``): the spec sheet shows that
    device's published numbers beside this file's (:data:`hapticdesign.studies.spec_page.VENDOR`)."""
    parameters: dict[Identifier, Number] = {}
    g: Annotated[Number, Field(ge=0.0)] = 9.81
    joints: list[JointSpec] = Field(min_length=1)
    dh: list[DHRowSpec] = []
    frames: list[FrameSpec] = []
    bodies: list[BodySpec] = Field(min_length=1)
    end_effector: Name | None = None
    actuators: list[ActuatorSpec] = []
    loops: list[LoopSpec] = []
    assembly: dict[Identifier, Number] = {}
    home: dict[Identifier, Number | list[Number]] = {}
    links: list[LinkSpec] = []
    joint_stiffness: dict[Identifier, Annotated[Number, Field(gt=0.0)]] = {}

    def dh_names(self) -> list[str]:
        return [row.name or str(i + 1) for i, row in enumerate(self.dh)]

    @model_validator(mode="after")
    def _cross_references(self) -> "DeviceFileSpec":
        _check(self)
        return self


def _check(spec: DeviceFileSpec) -> None:
    """Names, references, joint usage and body consistency; raises ValueError naming the field."""
    coordinates = [j.name for j in spec.joints]
    kinds = {j.name: j.type for j in spec.joints}
    seen: set[str] = set()
    for where, name in [("joints", c) for c in coordinates] + [("parameters", p) for p in spec.parameters]:
        if name in RESERVED:
            raise ValueError(f"{where}: {name!r} is reserved (pi, g = gravity, base = the base frame)")
        if name in seen:
            raise ValueError(f"{where}: name {name!r} is used twice")
        seen.add(name)
    used = {c: False for c in coordinates}

    def check_expr(where: str, expr: LinearExpr, motion: str | None) -> None:
        for name in expr.names:
            if name not in seen:
                raise ValueError(
                    f"{where}: unknown name {name!r} (coordinates: {', '.join(coordinates)}; "
                    f"parameters: {', '.join(spec.parameters) or 'none'})"
                )
            if name in kinds:
                if motion is None:
                    raise ValueError(f"{where}: must be constant, it cannot depend on coordinate {name}")
                wanted = "revolute" if motion == "rotation" else "prismatic"
                if kinds[name] != wanted:
                    raise ValueError(f"{where}: {kinds[name]} coordinate {name} cannot drive a {motion}")
                used[name] = True

    frames = ["base"]
    for i, (row, name) in enumerate(zip(spec.dh, spec.dh_names())):
        check_expr(f"dh[{i}].a", row.a, None)
        check_expr(f"dh[{i}].alpha", row.alpha, None)
        check_expr(f"dh[{i}].s", row.s, "translation")
        check_expr(f"dh[{i}].theta", row.theta, "rotation")
        frames += [f"body{name}", f"link{name}"]
    for i, frame in enumerate(spec.frames):
        if frame.parent not in frames:
            raise ValueError(
                f"frames[{i}] ({frame.name}): unknown parent {frame.parent!r} "
                f"(frames defined before it: {', '.join(frames)})"
            )
        for k, t in enumerate(frame.transforms):
            check_expr(f"frames[{i}] ({frame.name}).transforms[{k}]", t.value,
                       "rotation" if t.axis.is_rotation else "translation")
        frames.append(frame.name)
    duplicated = sorted({f for f in frames if frames.count(f) > 1})
    if duplicated:
        raise ValueError(f"frame {duplicated[0]!r} is defined twice (DH rows define body<name> and link<name>)")
    idle = [c for c, flag in used.items() if not flag]
    if idle:
        raise ValueError(f"joints: coordinate {idle[0]} drives no transform")
    for i, body in enumerate(spec.bodies):
        if any(other.name == body.name for other in spec.bodies[:i]):
            raise ValueError(f"bodies[{i}]: body name {body.name!r} is used twice")
        if body.link is not None:
            _check_link_body(spec, i, body)
            continue
        if body.frame is None:
            raise ValueError(f"bodies[{i}] ({body.name}): give its frame (with m, rx, ..., Iyz) or the link it is "
                             "(link: name)")
        if body.frame not in frames:
            raise ValueError(f"bodies[{i}] ({body.name}): unknown frame {body.frame!r} (frames: {', '.join(frames)})")
        report = check_body(body.name, body.inertia())
        if report.error:
            raise ValueError(f"bodies[{i}]: {report.error}")
    if spec.end_effector is not None and spec.end_effector not in frames:
        raise ValueError(f"end_effector: unknown frame {spec.end_effector!r}")
    _check_limits_and_actuators(spec, coordinates)
    _check_loops(spec, frames)
    _check_links(spec, frames)


def _check_link_body(spec: DeviceFileSpec, i: int, body: BodySpec) -> None:
    """A body that is a link's tube: the link exists and has a density; no frame or inertial values of its own."""
    given = [f for f in ("frame", *SEED_FIELDS) if f in body.model_fields_set]
    if given:
        raise ValueError(f"bodies[{i}] ({body.name}): a body on a link takes its frame, mass and inertia from the link "
                         f"(remove {given[0]})")
    links = {link.name: link for link in spec.links}
    if body.link not in links:
        raise ValueError(f"bodies[{i}] ({body.name}): unknown link {body.link!r} (links: {', '.join(links) or 'none'})")
    if links[body.link].material.density is None:
        raise ValueError(f"bodies[{i}] ({body.name}): link {body.link}'s material has no density (give "
                         "material: {E: ..., G: ..., density: ...} in kg/m^3)")
    if any(other.link == body.link for other in spec.bodies[:i]):
        raise ValueError(f"bodies[{i}] ({body.name}): link {body.link} already has a body")


def body_frame(spec: DeviceFileSpec, body: BodySpec) -> str:
    """The frame a body is attached to: its own, or its link's start frame."""
    if body.link is None:
        return body.frame
    return next(link.start for link in spec.links if link.name == body.link)


def _check_links(spec: DeviceFileSpec, frames: list[str]) -> None:
    """Link names and frames, joint springs on actuated joints (the geometry is checked when built)."""
    for i, link in enumerate(spec.links):
        if any(other.name == link.name for other in spec.links[:i]):
            raise ValueError(f"links[{i}]: link name {link.name!r} is used twice")
        for key, frame in (("from", link.start), ("to", link.end)):
            if frame not in frames:
                raise ValueError(f"links[{i}].{key}: unknown frame {frame!r} (frames: {', '.join(frames)})")
    actuated = [j.name for j in spec.joints if j.actuated]
    for name in spec.joint_stiffness:
        if name not in actuated:
            raise ValueError(f"joint_stiffness: {name!r} is not an actuated joint (actuated: {', '.join(actuated)}; "
                             "passive joints are free)")


def _check_loops(spec: DeviceFileSpec, frames: list[str]) -> None:
    """Passive joints, loops, assembly and home refer to each other consistently (squareness: model.loops)."""
    passive = [j.name for j in spec.joints if not j.actuated]
    actuated = [j.name for j in spec.joints if j.actuated]
    for i, joint in enumerate(spec.joints):
        if not joint.actuated and (joint.damping or joint.limits is not None):
            raise ValueError(f"joints[{i}] ({joint.name}): a passive joint takes no damping or limits (not supported)")
    for i, actuator in enumerate(spec.actuators):
        on_passive = [name for name in motor_terms(actuator) if name in passive]
        if on_passive:
            raise ValueError(f"actuators[{i}].{'joint' if actuator.drives is None else 'drives'}: {on_passive[0]} is "
                             "passive (actuated: false)")
    if passive and not spec.loops:
        raise ValueError(f"joints: passive joint {passive[0]} needs loops: [{{frames: [a, b], close: ...}}] to close")
    if spec.loops and not passive:
        raise ValueError("loops: no passive joint to solve (mark the loop's unactuated joints actuated: false)")
    for i, loop in enumerate(spec.loops):
        for frame in loop.frames:
            if frame not in frames:
                raise ValueError(f"loops[{i}].frames: unknown frame {frame!r} (frames: {', '.join(frames)})")
    for name in spec.assembly:
        if name not in passive:
            raise ValueError(f"assembly: {name!r} is not a passive joint (passive: {', '.join(passive) or 'none'})")
    missing = [name for name in passive if name not in spec.assembly]
    if missing:
        raise ValueError(f"assembly: give a value near the intended branch at home for passive joint {missing[0]}")
    for name, value in spec.home.items():
        if isinstance(value, list):
            if name != HOME_POSITION:
                raise ValueError(f"home.{name}: a joint's home value is one number (a handle position is "
                                 f"home: {{{HOME_POSITION}: [x, y, z]}})")
            if len(value) != 3:
                raise ValueError(f"home.{HOME_POSITION}: a handle position is 3 numbers [x, y, z] (m), got {len(value)}")
            try:
                handle_position(value, f"home.{HOME_POSITION}")
            except UserError as exc:
                raise ValueError(str(exc)) from None
        elif name not in actuated:
            raise ValueError(f"home: {name!r} is not an actuated joint (actuated: {', '.join(actuated)})")
    if spec.home and not spec.loops:
        raise ValueError("home: only a device with loops has a home of its own (a tree's home is q = 0)")


def _check_limits_and_actuators(spec: DeviceFileSpec, coordinates: list[str]) -> None:
    """Joint ranges with low < high; one actuator at most per joint, on a joint of the file."""
    for i, joint in enumerate(spec.joints):
        if joint.limits is not None and not joint.limits[0] < joint.limits[1]:
            raise ValueError(f"joints[{i}] ({joint.name}).limits: need low < high, got [{joint.limits[0]:g}, "
                             f"{joint.limits[1]:g}]")
    driven: list[dict[str, float]] = []
    for i, actuator in enumerate(spec.actuators):
        if (actuator.joint is None) == (actuator.drives is None):
            raise ValueError(f"actuators[{i}]: give either joint (the coordinate it turns) or drives (an affine "
                             "combination of coordinates such as theta2 + theta3)")
        if actuator.joint is not None and actuator.joint not in coordinates:
            raise ValueError(f"actuators[{i}].joint: unknown joint {actuator.joint!r} (joints: {', '.join(coordinates)})")
        terms = motor_terms(actuator)
        if not terms:
            raise ValueError(f"actuators[{i}].drives: the combination names no coordinate")
        if any(not abs(c) <= MAX_COEFFICIENT for c in terms.values()):
            raise ValueError(f"actuators[{i}].drives: coefficients must be finite and at most {MAX_COEFFICIENT:g} in size")
        unknown = [name for name in terms if name not in coordinates]
        if unknown:
            raise ValueError(f"actuators[{i}].drives: unknown joint {unknown[0]!r} (joints: {', '.join(coordinates)})")
        if actuator.limits is not None and not actuator.limits[0] < actuator.limits[1]:
            raise ValueError(f"actuators[{i}].limits: need low < high, got [{actuator.limits[0]:g}, "
                             f"{actuator.limits[1]:g}]")
        if (actuator.torque_continuous is not None and actuator.torque_peak is not None
                and actuator.torque_peak < actuator.torque_continuous):
            raise ValueError(f"actuators[{i}].torque_peak: {actuator.torque_peak:g} N m is below torque_continuous "
                             f"{actuator.torque_continuous:g} N m")
        if actuator.joint is not None and terms in driven:
            raise ValueError(f"actuators[{i}].joint: joint {actuator.joint} has two actuators (give one per joint)")
        driven.append(terms)
    rows = np.array([[terms.get(name, 0.0) for name in coordinates] for terms in driven])
    if driven and np.linalg.matrix_rank(rows) < len(driven):
        raise ValueError("actuators: two motors turn the same joint or dependent combinations of joints (give one "
                         "motor per independent combination)")


MAX_COEFFICIENT = 1000.0
"""Largest coefficient of a motor's combination of joints (its square multiplies the reflected inertia)."""


def motor_terms(actuator: ActuatorSpec) -> dict[str, float]:
    """The coordinates an actuator turns with their coefficients (``{joint: 1}`` for a motor on one joint)."""
    if actuator.drives is None:
        return {actuator.joint: 1.0}
    return dict(actuator.drives.terms)
