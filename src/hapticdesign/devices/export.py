"""A device for other simulators: MJCF (MuJoCo) with loops as equality constraints, URDF for trees.

``hapticdesign export --format mjcf|urdf`` writes them (:func:`export_text`).

Every frame of the device is a chain of elementary transforms (:mod:`hapticdesign.model.transforms`).
Constant transforms fold into a body's fixed position and orientation; each transform driven by the
coordinates becomes a joint (hinge for ``Rx``/``Ry``/``Rz``, slide for ``tx``/``ty``/``tz``) with its
constant ``a_0`` folded into the fixed part, so every joint is zero at ``q = 0``. The first transform
driven by ``+-q_k`` alone is coordinate ``k``'s joint (named as the coordinate); any other driven
transform (a coupling such as the Phantom's ``q2 - q3``) is a joint of its own, tied to the coordinates
by a fixed tendon held at zero length (MJCF) or by ``<mimic>`` (URDF, one coordinate only). Loops close
with ``connect`` constraints between sites at the two frames (``weld`` for a whole pose; a planar closure
in two components becomes a ``connect`` whose third component holds already, a redundant constraint).
Motors become ``motor`` actuators with the
transmission ratio as ``gear`` and the reflected rotor inertia as ``armature``, on the coordinate's joint or,
for a motor on a combination of coordinates, on a fixed tendon. Names are escaped by the XML writer.

Limits. A coordinate's limits become its joint's ``range`` (MJCF) or ``<limit lower upper>`` (URDF), a
coupled motor's travel the ``range`` of its tendon. A motor with a peak torque ``tau_p`` (N m at the motor)
gets ``ctrlrange`` and ``forcerange`` ``+-tau_p`` (its scalar force, before ``gear``) and, on the joint or
tendon it turns, ``actuatorfrcrange`` ``+-n tau_p`` (the transmission's output); in URDF the joint's
``effort`` is ``n tau_p`` (0 where no motor states a peak torque) and ``velocity`` 0 (a device file states
no speed limit). URDF cannot state a motor on a combination of coordinates: its limits are left out.

MuJoCo refuses moving bodies without mass, and most frames between two joints carry none: the MJCF sets
``<compiler boundmass="1e-9" boundinertia="1e-12">`` (kg, kg m^2), a change far below any device's own.
It also refuses inertias that break the triangle inequality (a file may still hold them, with a warning).

Constraint stiffness. MuJoCo's equality constraints are soft: a violation decays with the time constant
``solref[0]`` (default 0.02 s), which MuJoCo clamps to at least twice the timestep. The MJCF states the
timestep (1 ms, the haptic loop's 1 kHz) and on every equality ``solref`` with twice that time constant and
damping ratio 1, the stiffest setting MuJoCo keeps: a file comment says so, and to scale it with the timestep.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from hapticdesign.errors import UserError
from hapticdesign.files import NOT_TEXT, quote
from hapticdesign.model.device import Device
from hapticdesign.model.mechanism import Mechanism
from hapticdesign.model.transforms import elementary_matrix

BOUND_MASS = 1e-9
BOUND_INERTIA = 1e-12
EQUALITY_IMPEDANCE = "0.9999 0.9999 0.001 0.5 2"
"""MuJoCo's stiffest constraint impedance (its ceiling is 0.9999): a constraint force within about 1e-4 of
the ideal one."""
TIMESTEP = 1e-3
"""The exported timestep (s): the haptic loop's 1 kHz."""
EQUALITY_REFERENCE = f"{2 * TIMESTEP:g} 1"
"""``solref``: time constant twice the timestep (MuJoCo clamps anything shorter), damping ratio 1."""


@dataclass(frozen=True)
class JointRow:
    """A joint of the export and its value ``row . q`` over the device's coordinates."""

    name: str
    row: tuple[float, ...]


@dataclass(frozen=True)
class Export:
    """The file's text and the export's joints in MuJoCo's order (``qpos = T q`` with T's rows)."""

    text: str
    joints: tuple[JointRow, ...]

    def transform(self) -> np.ndarray:
        return np.array([j.row for j in self.joints])


def _fmt(values) -> str:
    return " ".join(f"{float(v):.17g}" for v in np.ravel(values))


def _primaries(mech: Mechanism) -> dict[tuple[str, int], int]:
    """``(frame, transform index) -> coordinate`` of the transform that is each coordinate's own joint."""
    found: dict[int, tuple[str, int]] = {}
    for frame in mech.frames:
        for i, t in enumerate(frame.transforms):
            terms = [(k, c) for k, c in t.value.coefficients if c != 0.0]
            if len(terms) == 1 and abs(terms[0][1]) == 1.0 and terms[0][0] not in found:
                found[terms[0][0]] = (frame.name, i)
    missing = [mech.coordinates[k] for k in range(mech.n_dof) if k not in found]
    if missing:
        raise UserError(f"cannot export: coordinate {missing[0]} drives no transform on its own (with coefficient "
                        "+-1), so it has no joint of its own")
    return {where: k for k, where in found.items()}


class _Tree:
    """The frames as nested bodies: ``segments[frame]`` lists (fixed 4x4, joint or None) in order."""

    def __init__(self, mech: Mechanism):
        self.mech = mech
        self.primary = _primaries(mech)

    def segments(self, frame) -> list[tuple[np.ndarray, tuple | None]]:
        """``(fixed pose, (name, kind, axis, coordinate or None, row))`` per driven transform, then the rest."""
        out, pending = [], np.eye(4)
        for i, t in enumerate(frame.transforms):
            row = t.value.dense(self.mech.n_dof)
            pending = pending @ elementary_matrix(t.axis, t.value.offset)
            if t.value.is_constant:
                continue
            unit = np.eye(3)[int(t.axis) % 3]
            k = self.primary.get((frame.name, i))
            if k is not None:
                joint = (self.mech.coordinates[k], unit * row[k], k, row)
            else:
                joint = (f"{frame.name}__{i}", unit, None, row)
            out.append((pending, ("hinge" if t.axis.is_rotation else "slide", *joint)))
            pending = np.eye(4)
        out.append((pending, None))
        return out


def _pose_attributes(element: ET.Element, pose: np.ndarray) -> None:
    if np.any(pose[:3, 3]):
        element.set("pos", _fmt(pose[:3, 3]))
    if not np.allclose(pose[:3, :3], np.eye(3), atol=0.0, rtol=0.0):
        x, y, z, w = Rotation.from_matrix(pose[:3, :3]).as_quat()
        element.set("quat", _fmt([w, x, y, z]))


def to_mjcf(device: Device) -> Export:
    """The device as an MJCF model, with the home pose as keyframe ``home`` (the loops closed)."""
    mech = device.mechanism
    tree = _Tree(mech)
    root = ET.Element("mujoco", model=device.name)
    ET.SubElement(root, "compiler", angle="radian", boundmass=f"{BOUND_MASS:g}", boundinertia=f"{BOUND_INERTIA:g}")
    ET.SubElement(root, "option", timestep=f"{TIMESTEP:g}", gravity=_fmt(mech.gravity))
    world = ET.SubElement(root, "worldbody")
    element = {"base": world}
    joints: list[JointRow] = []
    couplings: list[tuple[str, np.ndarray]] = []
    reflected = {}
    friction = {}
    damping = dict(zip(mech.actuated_coordinates, device.damping))
    efforts = _joint_efforts(device)
    for actuator in device.actuators:
        if not actuator.coupled:
            name = mech.actuated_coordinates[actuator.joint]
            reflected[name] = actuator.reflected_inertia
            friction[name] = actuator.coulomb
    for frame in mech.frames:
        parent = element[frame.parent or "base"]
        for pose, joint in tree.segments(frame):
            name = frame.name if joint is None else f"{frame.name}__{len(joints)}"
            body = ET.SubElement(parent, "body", name=name)
            _pose_attributes(body, pose)
            if joint is not None:
                kind, jname, axis, k, row = joint
                j = ET.SubElement(body, "joint", name=jname, type=kind, axis=_fmt(axis))
                value = row if k is None else np.eye(mech.n_dof)[k]
                joints.append(JointRow(jname, tuple(float(c) for c in value)))
                if k is None:
                    couplings.append((jname, row))
                elif jname in damping:
                    for key, value in (("armature", reflected.get(jname, 0.0)), ("damping", damping[jname]),
                                       ("frictionloss", friction.get(jname, 0.0))):
                        if value:
                            j.set(key, f"{value:.17g}")
                    span = device.joint_limits()[mech.actuated_coordinates.index(jname)]
                    if span is not None:
                        j.set("range", _fmt(span))
                    if jname in efforts:
                        j.set("actuatorfrcrange", _fmt([-efforts[jname], efforts[jname]]))
            parent = body
        element[frame.name] = parent
    for attachment in mech.bodies:
        b = device.body(attachment.name)
        holder = ET.SubElement(element[attachment.frame], "body", name=f"body_{attachment.name}")
        inertial = ET.SubElement(holder, "inertial", pos=_fmt([b.rx, b.ry, b.rz]), mass=f"{b.m:.17g}")
        inertial.set("fullinertia", _fmt([b.Ixx, b.Iyy, b.Izz, -b.Ixy, -b.Ixz, -b.Iyz]))
    _loops(mech, element, root, couplings)
    _actuators(device, root)
    rows = {j.name: j for j in joints}
    ordered = tuple(rows[j.get("name")] for j in world.iter("joint"))
    keyframe = ET.SubElement(root, "keyframe")
    from hapticdesign.analysis.configuration import configuration_of  # the loop solver, when a device is exported

    home = configuration_of(device).full_home
    ET.SubElement(keyframe, "key", name="home", qpos=_fmt(np.array([j.row for j in ordered]) @ home))
    ET.indent(root)
    return Export(_xml_text(root, device), ordered)


def _output_torque(actuator) -> float | None:
    """``n tau_p``: the peak torque (or force) the transmission delivers, or None without a peak torque."""
    return None if actuator.torque_peak is None else actuator.gear_ratio * actuator.torque_peak


def _joint_efforts(device: Device) -> dict[str, float]:
    """``n tau_p`` per coordinate turned by a motor of its own that states a peak torque."""
    names = device.mechanism.actuated_coordinates
    return {names[a.joint]: _output_torque(a) for a in device.actuators
            if not a.coupled and a.torque_peak is not None}



_STIFFEST = {"solref": EQUALITY_REFERENCE, "solimp": EQUALITY_IMPEDANCE}


def _loops(mech: Mechanism, element: dict, root: ET.Element, couplings) -> None:
    """Couplings as fixed tendons held at zero, loop closures as ``connect`` (or ``weld``) between two sites."""
    tendons = ET.Element("tendon")
    equality = ET.Element("equality")
    for name, row in couplings:
        fixed = ET.SubElement(tendons, "fixed", name=f"coupling_{name}")
        ET.SubElement(fixed, "joint", joint=name, coef="1")
        for k, c in enumerate(row):
            if c and not (mech.coordinates[k] == name):
                ET.SubElement(fixed, "joint", joint=mech.coordinates[k], coef=f"{-c:.17g}")
        ET.SubElement(equality, "tendon", tendon1=f"coupling_{name}", **_STIFFEST)
    for i, closure in enumerate(mech.loops.closures):
        kind = {(0, 1, 2): "connect", (0, 1, 2, 3, 4, 5): "weld"}.get(tuple(closure.components))
        if kind is None and any(c >= 3 for c in closure.components):
            raise UserError(f"cannot export loop {i + 1}: a closure of some rotation components only has no MJCF "
                            "equality (position or the whole pose can be exported)")
        sites = []
        for side, frame in zip("ab", closure.frames):
            site = f"loop{i + 1}_{side}"
            ET.SubElement(element[frame], "site", name=site)
            sites.append(site)
        ET.SubElement(equality, kind or "connect", site1=sites[0], site2=sites[1], **_STIFFEST)
    if len(equality):
        equality.insert(0, ET.Comment(
            f" solref {EQUALITY_REFERENCE}: time constant 2 x timestep ({TIMESTEP:g} s), the stiffest MuJoCo keeps "
            "(it clamps shorter ones); with another timestep, set it to 2 x that timestep "))
    for part in (tendons, equality):
        if len(part):
            root.append(part)


def _actuators(device: Device, root: ET.Element) -> None:
    """A motor per actuator: torque at the motor (ctrl, N m) times ``gear`` at what it turns."""
    if not device.actuators:
        return
    mech = device.mechanism
    part = ET.Element("actuator")
    tendons = root.find("tendon")
    for i, actuator in enumerate(device.actuators):
        name = f"motor{i + 1}"
        motor = ET.Element("motor", name=name, gear=f"{actuator.gear_ratio:.17g}")
        if actuator.coupled:
            if tendons is None:
                tendons = ET.Element("tendon")
                root.insert(list(root).index(root.find("worldbody")) + 1, tendons)
            fixed = ET.SubElement(tendons, "fixed", name=f"drive{i + 1}")
            for key, value in (("armature", actuator.reflected_inertia), ("damping", actuator.damping),
                               ("frictionloss", actuator.coulomb)):
                if value:
                    fixed.set(key, f"{value:.17g}")
            if actuator.limits is not None:
                fixed.set("range", _fmt(np.array(actuator.limits) - actuator.offset))
            if actuator.torque_peak is not None:
                fixed.set("actuatorfrcrange", _fmt([-_output_torque(actuator), _output_torque(actuator)]))
            for k, c in enumerate(actuator.row(device.n_dof)):
                if c:
                    ET.SubElement(fixed, "joint", joint=mech.actuated_coordinates[k], coef=f"{c:.17g}")
            motor.set("tendon", f"drive{i + 1}")
        else:
            motor.set("joint", mech.actuated_coordinates[actuator.joint])
        if actuator.torque_peak is not None:
            motor.set("ctrlrange", _fmt([-actuator.torque_peak, actuator.torque_peak]))
            motor.set("forcerange", _fmt([-actuator.torque_peak, actuator.torque_peak]))
        part.append(motor)
    root.append(part)


def to_urdf(device: Device) -> Export:
    """The device as a URDF robot: a tree only (URDF has no loop closures), each coupled transform a joint that
    ``<mimic>``s the one coordinate it follows (URDF cannot state a combination of two coordinates)."""
    mech = device.mechanism
    if not mech.loops.empty:
        raise UserError(f"cannot export {device.name!r} as URDF: it has closed loops, which URDF cannot describe "
                        "(export it as MJCF)")
    tree = _Tree(mech)
    robot = ET.Element("robot", name=device.name)
    ET.SubElement(robot, "link", name="base")
    link_of = {"base": "base"}
    joints: list[JointRow] = []
    limits = dict(zip(mech.actuated_coordinates, device.joint_limits()))
    efforts = _joint_efforts(device)
    for frame in mech.frames:
        parent = link_of[frame.parent or "base"]
        for pose, joint in tree.segments(frame):
            name = frame.name if joint is None else f"{frame.name}__{len(joints)}"
            ET.SubElement(robot, "link", name=name)
            element = ET.SubElement(robot, "joint", name=f"{name}__fixed" if joint is None else joint[1],
                                    type="fixed")
            ET.SubElement(element, "parent", link=parent)
            ET.SubElement(element, "child", link=name)
            ET.SubElement(element, "origin", xyz=_fmt(pose[:3, 3]),
                          rpy=_fmt(Rotation.from_matrix(pose[:3, :3]).as_euler("xyz")))
            if joint is not None:
                _urdf_joint(mech, element, joint, (limits, efforts), joints)
            parent = name
        link_of[frame.name] = parent
    for attachment in mech.bodies:
        b = device.body(attachment.name)
        name = f"body_{attachment.name}"
        link = ET.SubElement(robot, "link", name=name)
        inertial = ET.SubElement(link, "inertial")
        ET.SubElement(inertial, "origin", xyz=_fmt([b.rx, b.ry, b.rz]), rpy="0 0 0")
        ET.SubElement(inertial, "mass", value=f"{b.m:.17g}")
        ET.SubElement(inertial, "inertia", ixx=f"{b.Ixx:.17g}", iyy=f"{b.Iyy:.17g}", izz=f"{b.Izz:.17g}",
                      ixy=f"{-b.Ixy:.17g}", ixz=f"{-b.Ixz:.17g}", iyz=f"{-b.Iyz:.17g}")
        fixed = ET.SubElement(robot, "joint", name=f"{name}__fixed", type="fixed")
        ET.SubElement(fixed, "parent", link=link_of[attachment.frame])
        ET.SubElement(fixed, "child", link=name)
    ET.indent(robot)
    return Export(_xml_text(robot, device), tuple(joints))


def _urdf_joint(mech: Mechanism, element: ET.Element, joint, bounds: tuple[dict, dict],
                joints: list[JointRow]) -> None:
    """Type, axis, limits (range and the motor's ``n tau_p`` as effort) and (for a coupling) the ``<mimic>`` of
    one driven transform."""
    kind, name, axis, k, row = joint
    limits, efforts = bounds
    span = limits.get(name) if k is not None else None
    effort = efforts.get(name, 0.0) if k is not None else 0.0
    element.set("type", ("revolute" if span is not None else "continuous") if kind == "hinge" else "prismatic")
    ET.SubElement(element, "axis", xyz=_fmt(axis))
    if kind == "slide" and span is None:
        raise UserError(f"cannot export {name} as URDF: a prismatic joint needs limits")
    if span is not None:
        ET.SubElement(element, "limit", lower=f"{span[0]:.17g}", upper=f"{span[1]:.17g}", effort=f"{effort:.17g}",
                      velocity="0")
    elif effort:
        ET.SubElement(element, "limit", effort=f"{effort:.17g}", velocity="0")
    if k is None:
        terms = [(i, c) for i, c in enumerate(row) if c]
        if len(terms) != 1:
            combination = " ".join(f"{c:+g} {mech.coordinates[i]}" for i, c in terms)
            raise UserError(f"cannot export as URDF: joint {name} turns with {combination}, a combination of "
                            "coordinates that URDF's mimic cannot state (export it as MJCF)")
        ET.SubElement(element, "mimic", joint=mech.coordinates[terms[0][0]], multiplier=f"{terms[0][1]:.17g}")
        if kind == "hinge" and span is None:
            element.set("type", "continuous")
    joints.append(JointRow(name, tuple(float(c) for c in (row if k is None else np.eye(mech.n_dof)[k]))))


def _xml_text(root: ET.Element, device: Device) -> str:
    """The XML document of ``root``; a name holding a character XML 1.0 forbids (:data:`~hapticdesign.files.NOT_TEXT`:
    control characters, lone surrogates, U+FFFE/U+FFFF), which a device built in Python may carry although no device
    file can, is refused in one line instead of making a malformed file."""
    text = ET.tostring(root, encoding="unicode") + "\n"
    found = NOT_TEXT.search(text)
    if found:
        raise UserError(f"cannot export {quote(device.name)}: a name holds the character U+{ord(found.group()):04X}, "
                        "which XML forbids")
    return text


FORMATS = {"mjcf": to_mjcf, "urdf": to_urdf}


def export_text(device: Device, fmt: str) -> str:
    """The device in format ``mjcf`` or ``urdf``."""
    if fmt not in FORMATS:
        raise UserError(f"format: unknown format {fmt!r} (use {' or '.join(FORMATS)})")
    return FORMATS[fmt](device).text
