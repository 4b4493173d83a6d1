"""Devices of one's own: load a device file (YAML, TOML or JSON; URDF via :mod:`.urdf`) into a Device.

The file format is described in docs/device-files.md and validated by :mod:`.schema`. The
geometry becomes a :class:`ChainBuilder`, a frozen (hashable, value-compared) callable that maps
the kinematic parameter values to a :class:`~hapticdesign.model.mechanism.Mechanism`, exactly as
the presets' builders do: DH rows in seed 000's convention (eq. 2.26, :func:`dh_frames`) followed
by frames of elementary transforms whose values are affine in the coordinates (the couplings of
closed loops, seed 000 eq. 2.38-2.43). Inertial parameters keep the seed's names (Table 2.3).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from pydantic import ValidationError

from hapticdesign.devices.schema import DeviceFileSpec, LinearExpr, TransformSpec
from hapticdesign.model.actuators import Actuator, Limits, per_joint
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.model.dh import DHRow, dh_frames
from hapticdesign.model.inertia import SEED_FIELDS, BodyInertia, seed_parameter_name
from hapticdesign.model.loops import ClosedLoops, LoopClosure
from hapticdesign.model.mechanism import BodyAttachment, Frame, JointType, Mechanism
from hapticdesign.model.params_io import read_mapping
from hapticdesign.model.transforms import ElementaryTransform, JointValue, combination


@dataclass(frozen=True)
class DHRowTemplate:
    """A DH row whose entries are affine expressions of parameters and coordinates."""

    name: str
    a: LinearExpr
    alpha: LinearExpr
    s: LinearExpr
    theta: LinearExpr


@dataclass(frozen=True)
class FrameTemplate:
    """A frame on ``parent`` (``None``: the base) made of elementary transforms with affine values."""

    name: str
    parent: str | None
    transforms: tuple[TransformSpec, ...]


@dataclass(frozen=True)
class ChainBuilder:
    """Builds the mechanism of a device file for given kinematic parameter values.

    Frozen and compared by value, so that two loads of the same file share
    :class:`~hapticdesign.model.device.Device`'s per-builder caches.
    """

    coordinates: tuple[str, ...]
    joint_types: tuple[JointType, ...]
    dh: tuple[DHRowTemplate, ...]
    frames: tuple[FrameTemplate, ...]
    bodies: tuple[tuple[str, str], ...]
    end_effector: str | None = None
    loops: ClosedLoops | None = None

    def value(self, expr: LinearExpr, params: Mapping[str, float]) -> JointValue:
        """The joint value ``offset + sum_k c_k q_k`` of an expression at parameter values ``params``."""
        offset, coefficients = expr.constant, {}
        for name, c in expr.terms:
            if name in self.coordinates:
                k = self.coordinates.index(name)
                coefficients[k] = coefficients.get(k, 0.0) + c
            else:
                offset += c * float(params[name])
        return combination(coefficients, offset)

    def __call__(self, params: Mapping[str, float]) -> Mechanism:
        rows = [
            DHRow(
                self.value(r.a, params).offset,
                self.value(r.alpha, params).offset,
                self.value(r.s, params),
                self.value(r.theta, params),
            )
            for r in self.dh
        ]
        frames = dh_frames(rows, [r.name for r in self.dh]) if rows else []
        for f in self.frames:
            transforms = tuple(ElementaryTransform(t.axis, self.value(t.value, params)) for t in f.transforms)
            frames.append(Frame(f.name, f.parent, transforms))
        return Mechanism(
            coordinates=self.coordinates,
            joint_types=self.joint_types,
            frames=tuple(frames),
            bodies=tuple(BodyAttachment(name, frame) for name, frame in self.bodies),
            gravity=(0.0, 0.0, -float(params["g"])),
            end_effector=self.end_effector,
            loops=self.loops,
        )


def assemble_device(
    name: str,
    description: str,
    kinematic: Mapping[str, float],
    builder: ChainBuilder,
    inertias: Mapping[str, BodyInertia],
    damping: tuple[float, ...],
    actuators: tuple[Actuator, ...] = (),
    limits: tuple[Limits, ...] = (),
) -> Device:
    """A Device whose ``params`` hold every kinematic and inertial name (``m2``, ``r2x``, ``Ixy2``...).

    ``damping`` is the joints' own; the actuators' viscous damping is added to it per coordinate.
    """
    params = dict(kinematic)
    for body, inertia in inertias.items():
        for f in SEED_FIELDS:
            key = seed_parameter_name(f, body)
            if key in params:
                raise UserError(f"parameter name {key!r} is ambiguous (rename a body or a parameter)")
            params[key] = float(getattr(inertia, f))
    if actuators:
        damping = tuple(a + b for a, b in zip(damping, per_joint(actuators, len(damping), "damping")))
    device = Device(name, description, tuple(kinematic), builder, params, damping, tuple(actuators),
                    tuple(limits) if any(span is not None for span in limits) else ())
    device.mechanism  # build once: geometry errors surface at load time, not at first use
    return device


def device_from_spec(spec: DeviceFileSpec) -> Device:
    """The Device described by a validated device file."""
    builder = ChainBuilder(
        coordinates=tuple(j.name for j in spec.joints),
        joint_types=tuple(JointType(j.type) for j in spec.joints),
        dh=tuple(
            DHRowTemplate(name, row.a, row.alpha, row.s, row.theta) for row, name in zip(spec.dh, spec.dh_names())
        ),
        frames=tuple(
            FrameTemplate(f.name, None if f.parent == "base" else f.parent, tuple(f.transforms)) for f in spec.frames
        ),
        bodies=tuple((b.name, b.frame) for b in spec.bodies),
        end_effector=spec.end_effector,
        loops=_closed_loops(spec),
    )
    return assemble_device(
        spec.name,
        spec.description,
        {**spec.parameters, "g": spec.g},
        builder,
        {b.name: b.inertia() for b in spec.bodies},
        tuple(j.damping for j in spec.joints if j.actuated),
        _actuators(spec),
        tuple(None if j.limits is None else (float(j.limits[0]), float(j.limits[1])) for j in spec.joints
              if j.actuated),
    )


def _closed_loops(spec: DeviceFileSpec) -> ClosedLoops | None:
    """Passive joints, closures, assembly guess and home of a file with ``loops`` (None for a tree)."""
    if not spec.loops:
        return None
    names = [j.name for j in spec.joints]
    return ClosedLoops(
        passive=tuple(k for k, j in enumerate(spec.joints) if not j.actuated),
        closures=tuple(LoopClosure(tuple(loop.frames), tuple(loop.close)) for loop in spec.loops),
        assembly=tuple(float(spec.assembly[j.name]) for j in spec.joints if not j.actuated),
        home=tuple(float(spec.home.get(name, 0.0)) for name, j in zip(names, spec.joints) if j.actuated),
    )


def _actuators(spec: DeviceFileSpec) -> tuple[Actuator, ...]:
    """The file's actuators with 0-based indices among the actuated joints (in the order of ``joints``)."""
    index = {j.name: k for k, j in enumerate(j for j in spec.joints if j.actuated)}
    return tuple(
        Actuator(index[a.joint], a.rotor_inertia, a.gear_ratio, a.coulomb, a.damping) for a in spec.actuators
    )


def _location(loc: tuple) -> str:
    out = ""
    for part in loc:
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


def device_from_mapping(data: object, source: str = "device file") -> Device:
    """Validate a parsed device file and build its Device; problems raise a one-line UserError."""
    if not isinstance(data, dict):
        raise UserError(f"{source}: expected a mapping with keys such as name, joints, dh, frames, bodies")
    try:
        spec = DeviceFileSpec.model_validate(data)
    except ValidationError as exc:
        raise UserError(f"{source}: {describe_validation_error(exc)}") from None
    try:
        return device_from_spec(spec)
    except UserError as exc:
        raise UserError(f"{source}: {exc}") from None


def load_device_file(path: Path) -> Device:
    """Load a device file: ``.yaml``/``.yml``/``.toml``/``.json`` (docs/device-files.md) or ``.urdf``."""
    path = Path(path)
    if path.suffix.lower() == ".urdf":
        from hapticdesign.devices.urdf import load_urdf

        return load_urdf(path)
    return device_from_mapping(read_mapping(path), str(path))
