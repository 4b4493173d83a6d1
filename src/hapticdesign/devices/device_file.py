"""Devices of one's own: load a device file (YAML, TOML or JSON) into a Device.

The file format is described in docs/device-files.md and validated by :mod:`.schema`; the
geometry becomes a :class:`~hapticdesign.devices.builder.ChainBuilder` (:mod:`.builder`, shared
with the URDF reader). Inertial parameters keep the seed's names (seed 000 Table 2.3).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

import numpy as np
from pydantic import ValidationError

from hapticdesign.analysis.stiffness.link import rigidities
from hapticdesign.analysis.stiffness.sections import Tube
from hapticdesign.devices.builder import ChainBuilder, DHRowTemplate, FrameTemplate, assemble_device
from hapticdesign.devices.schema import HOME_POSITION, ActuatorSpec, DeviceFileSpec, body_frame, motor_terms
from hapticdesign.errors import UserError
from hapticdesign.files import QUOTE_LIMIT, quote
from hapticdesign.model.actuators import Actuator
from hapticdesign.model.device import Device, build_mechanism
from hapticdesign.model.inertia import BodyInertia, tube_body
from hapticdesign.model.elastic import Elasticity, ElasticLink
from hapticdesign.model.loops import ClosedLoops, LoopClosure
from hapticdesign.model.mechanism import JointType, Mechanism
from hapticdesign.model.params_io import read_mapping
from hapticdesign.workload import require_device_size


def device_from_spec(spec: DeviceFileSpec) -> Device:
    """The Device described by a validated device file; a ``home`` with a handle ``position`` is the pose the
    inverse kinematics reaches from the home of the joint values (0 where not given) on its assembly branch."""
    device = _device(spec, _closed_loops(spec))
    position = spec.home.get(HOME_POSITION)
    if isinstance(position, list):
        device = _device(spec, home_at(device, position))
    return device


def home_at(device: Device, position: list[float]) -> ClosedLoops:
    """The device's loops with their home (and assembly guess) moved to the pose that puts the handle at
    ``position``: the configuration space's inverse kinematics, continued from the home of the joint values."""
    from hapticdesign.analysis.configuration import configuration_of  # the loop solver, for such files only

    space = configuration_of(device)
    try:
        q_a = space.inverse_kinematics(position)
    except UserError as exc:
        raise UserError(f"home.{HOME_POSITION}: {exc}") from None
    loops = device.mechanism.loops
    full = space.full(q_a)
    return replace(loops, home=tuple(float(v) for v in q_a), assembly=tuple(float(full[k]) for k in loops.passive))


def _device(spec: DeviceFileSpec, loops: ClosedLoops) -> Device:
    """The Device of the file with the given loops (their home and assembly)."""
    builder = chain_builder(spec, loops)
    kinematic = {**spec.parameters, "g": spec.g}
    link_bodies = link_body_inertias(spec, build_mechanism(builder, tuple((k, float(v)) for k, v in kinematic.items())))
    return assemble_device(
        spec.name,
        spec.description,
        kinematic,
        builder,
        {b.name: link_bodies[b.name] if b.link is not None else b.inertia() for b in spec.bodies},
        tuple(j.damping for j in spec.joints if j.actuated),
        _actuators(spec),
        tuple(None if j.limits is None else (float(j.limits[0]), float(j.limits[1])) for j in spec.joints
              if j.actuated),
        _elasticity(spec),
        spec.reference or "",
    )


def link_body_inertias(spec: DeviceFileSpec, mechanism: Mechanism,
                       sections: Mapping[str, Tube] | None = None) -> dict[str, BodyInertia]:
    """The inertias of the file's bodies that are links (``bodies: - {name: b, link: l}``): the link's tube from its
    start frame to its end frame (:func:`~hapticdesign.model.inertia.tube_body`), with the section of ``sections``
    (by link name) where given, else the file's, and the geometry of ``mechanism`` (the two frames are one rigid
    piece, so any pose gives the same vector; q = 0 is taken)."""
    links = {link.name: link for link in spec.links}
    q = np.zeros(mechanism.n_dof)
    out = {}
    for body in spec.bodies:
        if body.link is None:
            continue
        link = links[body.link]
        start = mechanism.frame_pose(q, link.start)
        axis = start[:3, :3].T @ (mechanism.frame_pose(q, link.end)[:3, 3] - start[:3, 3])
        if not np.linalg.norm(axis) > 0.0:
            raise UserError(f"link {link.name}: frames {link.start!r} and {link.end!r} coincide (zero length)")
        section = (sections or {}).get(link.name, link.section)
        out[body.name] = tube_body(axis, section.D, section.d, link.material.density)
    return out


def chain_builder(spec: DeviceFileSpec, loops: ClosedLoops) -> ChainBuilder:
    """The mechanism builder of a validated device file (its geometry, for any parameter values), with ``loops``
    (the file's own, :func:`_closed_loops`, or those with another home, :func:`home_at`)."""
    return ChainBuilder(
        coordinates=tuple(j.name for j in spec.joints),
        joint_types=tuple(JointType(j.type) for j in spec.joints),
        dh=tuple(
            DHRowTemplate(name, row.a, row.alpha, row.s, row.theta) for row, name in zip(spec.dh, spec.dh_names())
        ),
        frames=tuple(
            FrameTemplate(f.name, None if f.parent == "base" else f.parent, tuple(f.transforms)) for f in spec.frames
        ),
        bodies=tuple((b.name, body_frame(spec, b)) for b in spec.bodies),
        end_effector=spec.end_effector,
        loops=loops,
    )


def _elasticity(spec: DeviceFileSpec) -> Elasticity | None:
    """The file's elastic links (rigidities of their section and material, eq. 4.59) and joint springs."""
    if not spec.links and not spec.joint_stiffness:
        return None
    links = tuple(ElasticLink(link.name, link.start, link.end, *rigidities(link.material, link.section))
                  for link in spec.links)
    return Elasticity(links, tuple((name, float(k)) for name, k in spec.joint_stiffness.items()))


def _closed_loops(spec: DeviceFileSpec) -> ClosedLoops:
    """Passive joints, closures, assembly guess and home of a file (a tree's: none, and home 0)."""
    names = [j.name for j in spec.joints]
    return ClosedLoops(
        passive=tuple(k for k, j in enumerate(spec.joints) if not j.actuated),
        closures=tuple(LoopClosure(tuple(loop.frames), tuple(loop.close)) for loop in spec.loops),
        assembly=tuple(float(spec.assembly[j.name]) for j in spec.joints if not j.actuated),
        home=tuple(float(_joint_home(spec, name)) for name, j in zip(names, spec.joints) if j.actuated),
    )


def _joint_home(spec: DeviceFileSpec, name: str) -> float:
    """The home value the file gives joint ``name`` (0 where none; a handle position is no joint value)."""
    value = spec.home.get(name, 0.0)
    return 0.0 if isinstance(value, list) else value


def _actuators(spec: DeviceFileSpec) -> tuple[Actuator, ...]:
    """The file's actuators with 0-based indices among the actuated joints (in the order of ``joints``)."""
    index = actuated_index(spec)
    return tuple(actuator_from_spec(a, index) for a in spec.actuators)


def actuated_index(spec: DeviceFileSpec) -> dict[str, int]:
    """Each actuated joint's 0-based place among the actuated joints (in the order of ``joints``)."""
    return {j.name: k for k, j in enumerate(j for j in spec.joints if j.actuated)}


def actuator_from_spec(a: ActuatorSpec, index: dict[str, int]) -> Actuator:
    """One actuator of a file, its coordinates numbered by ``index`` (:func:`actuated_index`)."""
    terms = tuple((index[name], float(c)) for name, c in motor_terms(a).items())
    coupling = () if a.drives is None else terms
    offset = 0.0 if a.drives is None else float(a.drives.constant)
    limits = None if a.limits is None else (float(a.limits[0]), float(a.limits[1]))
    return Actuator(terms[0][0], a.rotor_inertia, a.gear_ratio, a.coulomb, a.damping, coupling, offset, limits,
                    a.torque_continuous, a.torque_peak, a.encoder_cpr, a.quadrature, a.transmission_stiffness)


def _location(loc: tuple) -> str:
    out = ""
    for part in loc:
        part = part if isinstance(part, int) or len(str(part)) <= QUOTE_LIMIT else quote(str(part))
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def describe_validation_error(exc: ValidationError) -> str:
    """One line naming the field path of the first problem (and how many more there are)."""
    errors = exc.errors()
    first = errors[0]
    if first["type"] == "extra_forbidden":
        message = "unknown key"
    elif first["type"] == "missing":
        message = "missing required field"
    elif first["type"] == "value_error":
        message = str(first["ctx"]["error"])
    else:
        message = first["msg"]
    where = _location(tuple(p for p in first["loc"] if not str(p).startswith("function-")))
    more = f" (and {len(errors) - 1} more problem{'s' if len(errors) > 2 else ''})" if len(errors) > 1 else ""
    return f"{where}: {message}{more}" if where else f"{message}{more}"


def spec_from_mapping(data: object, source: str = "device file") -> DeviceFileSpec:
    """Validate a parsed device file; problems raise a one-line UserError."""
    if not isinstance(data, dict):
        raise UserError(f"{source}: expected a mapping with keys such as name, joints, dh, frames, bodies")
    require_device_size(source, *(len(data[key]) if isinstance(data.get(key), list) else 0
                                  for key in ("joints", "frames", "loops")))
    try:
        return DeviceFileSpec.model_validate(data)
    except ValidationError as exc:
        raise UserError(f"{source}: {describe_validation_error(exc)}") from None


def device_from_mapping(data: object, source: str = "device file") -> Device:
    """Validate a parsed device file and build its Device; problems raise a one-line UserError."""
    spec = spec_from_mapping(data, source)
    try:
        return device_from_spec(spec)
    except UserError as exc:
        raise UserError(f"{source}: {exc}") from None


def load_device_file(path: Path) -> Device:
    """Load a device file: ``.yaml``/``.yml``/``.toml``/``.json`` (docs/device-files.md)."""
    path = Path(path)
    return device_from_mapping(read_mapping(path), str(path))
