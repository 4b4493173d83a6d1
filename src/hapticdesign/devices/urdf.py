"""Import of kinematic trees (serial chains in particular) from URDF into a Device.

URDF conventions (ROS wiki, "urdf/XML"): a joint places its child link's frame on the parent
link's frame by ``origin`` (translation ``xyz``, then fixed-axis roll-pitch-yaw ``rpy``, i.e. the
rotation ``Rz(yaw) Ry(pitch) Rx(roll)``) followed by the joint motion along/about ``axis``
(default ``1 0 0``) expressed in the joint frame. Mapping to elementary transforms:

- origin: ``tx ty tz Rz Ry Rx`` (zero entries are omitted);
- axis ``+-x``, ``+-y``, ``+-z``: one transform ``R*(+-q)`` or ``t*(+-q)``;
- any other unit axis ``a = (sin b cos c, sin b sin c, cos b)``: the motion about ``a`` is
  ``Rz(c) Ry(b) . Rz(q) . Ry(-b) Rz(-c)`` (conjugation of the z motion by the rotation that
  takes z onto ``a``), likewise with ``tz(q)`` for prismatic joints;
- ``continuous`` joints are revolute, ``fixed`` joints add constant transforms only;
- ``<limit lower= upper=>`` of a revolute or prismatic joint becomes the coordinate's range (both
  attributes needed; URDF's defaults of 0 would make an empty range, so a missing one means none);
- ``<mimic joint= multiplier= offset=>``: the joint value is ``offset + multiplier * q_joint``,
  a coupling as in the device files.

Inertia: URDF gives the inertia tensor about the mass centre in the ``<inertial><origin>`` frame,
``xyz`` being the mass centre in the link frame. The link frame is the body frame; the seed's
parameters (seed 000 Table 2.3) are ``r = xyz`` and the tensor about the mass centre in link axes,
``I = R_rpy I_urdf R_rpy^T``, with the seed's products ``Ixy = -I[0, 1]``, ``Ixz = -I[0, 2]``,
``Iyz = -I[1, 2]``. The root link is fixed to the base and does not enter the dynamics; it gets no
body. Links without ``<inertial>`` are massless. Gravity is ``g = 9.81`` along ``-z`` of the root.
"""

from __future__ import annotations

import keyword
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from hapticdesign.devices.builder import (
    BODY_NAME,
    IDENTIFIER,
    ChainBuilder,
    FrameTemplate,
    LinearExpr,
    TransformSpec,
    assemble_device,
)
from hapticdesign.errors import UserError
from hapticdesign.files import quote, read_text
from hapticdesign.model.device import Device
from hapticdesign.model.inertia import BodyInertia, check_body
from hapticdesign.model.mechanism import JointType
from hapticdesign.model.transforms import Axis
from hapticdesign.workload import require_device_size

SUPPORTED = {"revolute": JointType.REVOLUTE, "continuous": JointType.REVOLUTE, "prismatic": JointType.PRISMATIC}
_ALIGN_TOL = 1e-12


def _floats(element: ET.Element | None, attribute: str, count: int, default: float, where: str) -> list[float]:
    text = element.get(attribute) if element is not None else None
    if text is None:
        return [default] * count
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        raise UserError(f"{where}: {attribute}={text!r} is not {count} numbers") from None
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise UserError(f"{where}: {attribute}={text!r} is not {count} finite numbers")
    return values


def _rotation(rpy: list[float]) -> np.ndarray:
    """URDF fixed-axis roll-pitch-yaw: ``Rz(yaw) Ry(pitch) Rx(roll)``."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def _const(axis: Axis, value: float) -> TransformSpec:
    return TransformSpec(axis, LinearExpr(float(value)))


def _origin_transforms(origin: ET.Element | None, where: str) -> list[TransformSpec]:
    xyz = _floats(origin, "xyz", 3, 0.0, where)
    roll, pitch, yaw = _floats(origin, "rpy", 3, 0.0, where)
    steps = [(Axis.TX, xyz[0]), (Axis.TY, xyz[1]), (Axis.TZ, xyz[2]), (Axis.RZ, yaw), (Axis.RY, pitch), (Axis.RX, roll)]
    return [_const(a, v) for a, v in steps if v != 0.0]


def _motion_transforms(axis: list[float], value: LinearExpr, prismatic: bool, where: str) -> list[TransformSpec]:
    """The joint motion along/about a unit axis, as elementary transforms (module docstring)."""
    a = np.asarray(axis, dtype=float)
    norm = float(np.linalg.norm(a))
    if norm == 0.0:
        raise UserError(f"{where}: axis must be a non-zero vector")
    a = a / norm
    along = (Axis.TX, Axis.TY, Axis.TZ) if prismatic else (Axis.RX, Axis.RY, Axis.RZ)
    for k in range(3):
        if abs(abs(a[k]) - 1.0) <= _ALIGN_TOL:
            sign = math.copysign(1.0, a[k])
            signed = LinearExpr(sign * value.constant, tuple((n, sign * c) for n, c in value.terms))
            return [TransformSpec(along[k], signed)]
    tilt, heading = math.acos(max(-1.0, min(1.0, a[2]))), math.atan2(a[1], a[0])
    align = [_const(Axis.RZ, heading), _const(Axis.RY, tilt)]
    undo = [_const(Axis.RY, -tilt), _const(Axis.RZ, -heading)]
    return [t for t in align if t.value.constant != 0.0] + [TransformSpec(along[2], value)] + [
        t for t in undo if t.value.constant != 0.0
    ]


def _inertia(link: ET.Element, where: str) -> BodyInertia | None:
    inertial = link.find("inertial")
    if inertial is None:
        return None
    mass_element = inertial.find("mass")
    (mass,) = _floats(mass_element, "value", 1, 0.0, f"{where} <mass>")
    origin = inertial.find("origin")
    xyz = _floats(origin, "xyz", 3, 0.0, f"{where} <inertial><origin>")
    rotation = _rotation(_floats(origin, "rpy", 3, 0.0, f"{where} <inertial><origin>"))
    tensor = inertial.find("inertia")
    i = {k: _floats(tensor, k, 1, 0.0, f"{where} <inertia>")[0] for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
    local = np.array([[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]], [i["ixz"], i["iyz"], i["izz"]]])
    link_axes = rotation @ local @ rotation.T
    return BodyInertia(
        m=mass, rx=xyz[0], ry=xyz[1], rz=xyz[2],
        Ixx=link_axes[0, 0], Iyy=link_axes[1, 1], Izz=link_axes[2, 2],
        Ixy=-link_axes[0, 1], Ixz=-link_axes[0, 2], Iyz=-link_axes[1, 2],
    )


def _parse(text: str, source: str) -> ET.Element:
    if "<!DOCTYPE" in text or "<!ENTITY" in text:  # URDF needs neither; entities can expand without bound
        raise UserError(f"{source}: document type declarations and entities are not allowed in URDF files")
    try:
        robot = ET.fromstring(text)
    except ET.ParseError as exc:
        raise UserError(f"{source}: malformed URDF ({exc})") from None
    if robot.tag != "robot":
        raise UserError(f"{source}: the root element must be <robot>, got <{robot.tag}>")
    return robot


def _joint_tree(robot: ET.Element, source: str) -> tuple[dict[str, ET.Element], str, list[ET.Element]]:
    """Links by name, the root link and the joints depth-first from the root (document order)."""
    links: dict[str, ET.Element] = {}
    for link in robot.findall("link"):
        name = link.get("name")
        if not name or name in links:
            raise UserError(f"{source}: every <link> needs a unique name (got {quote(name)})")
        if not BODY_NAME.match(name):
            raise UserError(f"{source}: link name {quote(name)} must consist of letters, digits and '_' "
                            "(it names the body's parameters, e.g. m<link>)")
        links[name] = link
    children: dict[str, list[ET.Element]] = {name: [] for name in links}
    parent_of: dict[str, str] = {}
    names: set[str] = set()
    for joint in robot.findall("joint"):
        name = joint.get("name")
        if not name or name in names:
            raise UserError(f"{source}: every <joint> needs a unique name (got {quote(name)})")
        if not IDENTIFIER.match(name) or keyword.iskeyword(name):
            raise UserError(f"{source}: joint name {quote(name)} must be an identifier (letters, digits, '_', "
                            "not starting with a digit): it names a coordinate")
        names.add(name)
        ends = [(role, joint.find(role)) for role in ("parent", "child")]
        parent, child = (e.get("link") if e is not None else None for _, e in ends)
        for (role, _), link in zip(ends, (parent, child)):
            if link not in links:
                raise UserError(f"{source}: joint {name!r}: unknown {role} link {link!r}")
        if child in parent_of:
            raise UserError(f"{source}: link {child!r} has two parent joints (only trees can be imported)")
        parent_of[child] = parent
        children[parent].append(joint)
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        raise UserError(f"{source}: expected one root link, found {len(roots)} ({', '.join(roots) or 'a cycle'})")
    root = roots[0]
    if "base" in links and root != "base":
        raise UserError(f"{source}: only the root link may be called 'base'")
    order: list[ET.Element] = []
    stack = list(reversed(children[root]))
    while stack:
        joint = stack.pop()
        order.append(joint)
        stack.extend(reversed(children[_child(joint)]))
    if len(order) != len(names):
        raise UserError(f"{source}: the joints do not form a tree rooted at {root!r}")
    return links, root, order


def _child(joint: ET.Element) -> str:
    return joint.find("child").get("link")


def _axis(joint: ET.Element, where: str) -> list[float]:
    axis = joint.find("axis")
    if axis is None or axis.get("xyz") is None:
        return [1.0, 0.0, 0.0]
    return _floats(axis, "xyz", 3, 0.0, where)


def device_from_urdf(text: str, source: str = "URDF", g: float = 9.81) -> Device:
    """Import a URDF document; coordinates follow the joints depth-first from the root link."""
    robot = _parse(text, source)
    require_device_size(source, len(robot.findall("joint")), len(robot.findall("link")), 0)
    links, root, order = _joint_tree(robot, source)
    coordinates: list[str] = []
    types: list[JointType] = []
    damping: list[float] = []
    limits: list[tuple[float, float] | None] = []
    for joint in order:
        kind, where = joint.get("type"), f"{source}: joint {joint.get('name')!r}"
        if kind != "fixed" and kind not in SUPPORTED:
            raise UserError(f"{where}: type {kind!r} is not supported (use revolute, continuous, prismatic or fixed)")
        if kind != "fixed" and joint.find("mimic") is None:
            coordinates.append(joint.get("name"))
            types.append(SUPPORTED[kind])
            damping.append(_floats(joint.find("dynamics"), "damping", 1, 0.0, where)[0])
            limits.append(_limits(joint, where) if kind != "continuous" else None)
    if not coordinates:
        raise UserError(f"{source}: no movable joint (revolute, continuous or prismatic) to import")

    frames = [] if root == "base" else [FrameTemplate(root, None, ())]
    for joint in order:
        kind, where = joint.get("type"), f"{source}: joint {joint.get('name')!r}"
        transforms = _origin_transforms(joint.find("origin"), where)
        if kind != "fixed":
            value = _joint_value(joint, coordinates, types, where)
            transforms += _motion_transforms(_axis(joint, where), value, SUPPORTED[kind] is JointType.PRISMATIC, where)
        parent = joint.find("parent").get("link")
        frames.append(FrameTemplate(_child(joint), None if parent == "base" else parent, tuple(transforms)))

    inertias = {}
    for name, link in links.items():
        inertia = _inertia(link, f"{source}: link {name!r}")
        if inertia is None or name == root:
            continue
        report = check_body(name, inertia)
        if report.error:
            raise UserError(f"{source}: link {name!r}: {report.error}")
        inertias[name] = inertia

    builder = ChainBuilder(
        coordinates=tuple(coordinates),
        joint_types=tuple(types),
        dh=(),
        frames=tuple(frames),
        bodies=tuple((name, name) for name in inertias),
        end_effector=_child(order[-1]),
    )
    name = robot.get("name") or Path(source).stem
    return assemble_device(name, f"imported from {source}", {"g": g}, builder, inertias, tuple(damping),
                           limits=tuple(limits))


def _limits(joint: ET.Element, where: str) -> tuple[float, float] | None:
    """``<limit lower upper>`` as ``(low, high)``; None unless both are given."""
    element = joint.find("limit")
    if element is None or element.get("lower") is None or element.get("upper") is None:
        return None
    (low,) = _floats(element, "lower", 1, 0.0, f"{where} <limit>")
    (high,) = _floats(element, "upper", 1, 0.0, f"{where} <limit>")
    if not low < high:
        raise UserError(f"{where}: <limit> needs lower < upper, got lower={low:g} upper={high:g}")
    return (low, high)


def _joint_value(joint: ET.Element, coordinates: list[str], types: list[JointType], where: str) -> LinearExpr:
    mimic = joint.find("mimic")
    if mimic is None:
        return LinearExpr(0.0, ((joint.get("name"), 1.0),))
    leader = mimic.get("joint")
    if leader not in coordinates:
        raise UserError(f"{where}: mimic joint {leader!r} is not a movable, independent joint")
    (multiplier,) = _floats(mimic, "multiplier", 1, 1.0, where)
    (offset,) = _floats(mimic, "offset", 1, 0.0, where)
    kind = SUPPORTED[joint.get("type")]
    if types[coordinates.index(leader)] is not kind:
        raise UserError(f"{where}: mimics {leader!r}, a joint of the other type")
    return LinearExpr(offset, ((leader, multiplier),))


def load_urdf(path: Path, g: float = 9.81) -> Device:
    """Import a URDF file (see :func:`device_from_urdf`)."""
    path = Path(path)
    return device_from_urdf(read_text(path, "URDF file"), str(path), g)
