"""The device builder shared by the readers: device files (:mod:`.device_file`) and URDF (:mod:`.urdf`).

A reader turns its format into a :class:`ChainBuilder`, a frozen (hashable, value-compared)
callable that maps the kinematic parameter values to a
:class:`~hapticdesign.model.mechanism.Mechanism`, exactly as the presets' builders do: DH rows in
seed 000's convention (eq. 2.26, :func:`dh_frames`) followed by frames of elementary transforms
whose values are affine in the coordinates (the couplings of closed loops, seed 000
eq. 2.38-2.43). :func:`assemble_device` then gives the Device with its inertial parameters under
the seed's names (Table 2.3). The readers import this module and never each other.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.actuators import Actuator, Limits, damping_matrix
from hapticdesign.model.device import Device
from hapticdesign.model.dh import DHRow, dh_frames
from hapticdesign.model.elastic import Elasticity
from hapticdesign.model.inertia import SEED_FIELDS, BodyInertia, seed_parameter_name
from hapticdesign.model.loops import ClosedLoops
from hapticdesign.model.mechanism import BodyAttachment, Frame, JointType, Mechanism
from hapticdesign.model.transforms import (
    Axis,
    ElementaryTransform,
    JointValue,
    combination,
)

IDENTIFIER_PATTERN = r"^[A-Za-z_][A-Za-z0-9_]*$"
IDENTIFIER = re.compile(IDENTIFIER_PATTERN)
BODY_NAME_PATTERN = r"^[A-Za-z0-9_]+$"
BODY_NAME = re.compile(BODY_NAME_PATTERN)
"""Coordinate and parameter names are identifiers; body names are letters, digits and ``_`` (they
become the suffix of parameter names such as ``m2a``): no user string that reaches generated code
(``eom --format python``, ``ln --symbolic``) can carry code or markup."""


@dataclass(frozen=True)
class LinearExpr:
    """``constant + sum(coefficient * value(name))``; names are parameters or coordinates."""

    constant: float = 0.0
    terms: tuple[tuple[str, float], ...] = ()

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(name for name, _ in self.terms)


@dataclass(frozen=True)
class TransformSpec:
    """One elementary transform of a frame: ``axis`` and its affine value."""

    axis: Axis
    value: LinearExpr


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
    loops: ClosedLoops = ClosedLoops()

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
    elasticity: Elasticity | None = None,
    reference: str = "",
) -> Device:
    """A Device whose ``params`` hold every kinematic and inertial name (``m2``, ``r2x``, ``Ixy2``...).

    ``damping`` is the joints' own; the diagonal of the actuators' viscous damping ``b a a^T`` is added to
    it per coordinate (the off-diagonal part is :attr:`Device.damping_matrix`'s).
    ``elasticity`` (elastic links, joint springs) is checked against the geometry here; ``reference`` names the
    published device a device file derives from.
    """
    params = dict(kinematic)
    for body, inertia in inertias.items():
        for f in SEED_FIELDS:
            key = seed_parameter_name(f, body)
            if key in params:
                raise UserError(f"parameter name {key!r} is ambiguous (rename a body or a parameter)")
            params[key] = float(getattr(inertia, f))
    if actuators:
        damping = tuple(a + float(b) for a, b in zip(damping, np.diag(damping_matrix(actuators, len(damping)))))
    device = Device(name, description, tuple(kinematic), builder, params, damping, tuple(actuators),
                    tuple(limits) if any(span is not None for span in limits) else (), elasticity, reference)
    mechanism = device.mechanism  # build once: geometry errors surface at load time, not at first use
    if elasticity is not None:  # import the solvers only for elastic devices
        from hapticdesign.analysis.stiffness.device import check_elasticity

        check_elasticity(mechanism, elasticity)
    return device
