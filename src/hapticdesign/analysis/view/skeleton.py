"""A device's skeleton: the data that draws it, at any pose.

Every frame of the mechanism (seed 000 §2.1: frames placed by elementary transforms, DH frames
included) is a point, the origin of its pose ``T(q)``; a *link* is the segment from a frame's parent
origin to its own origin; a body's mass centre is ``T(q) [r; 1]`` with ``r`` in the frame's axes
(Table 2.3). The page (:mod:`.page`) redoes the forward kinematics in the browser from the node
table exported here (one elementary transform per node, value ``offset + coef . q``), so every pose
a slider reaches is exact, not interpolated.

Devices with closed loops (:mod:`hapticdesign.model.loops`) have a slider per *actuated* joint; the
passive joints follow from the closures ``phi(q_a, q_p) = 0`` (origin differences and the skew part
of ``R_A R_B^T``), solved here by :mod:`hapticdesign.analysis.loops` and in the page by Newton's
method continued from the previous pose, so the page stays on the assembly branch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.errors import InputError, UserError
from hapticdesign.model.device import Device
from hapticdesign.model.mechanism import JointType
from hapticdesign.model.walk import node_poses

PRISMATIC_SPAN = 0.1
"""Slider half range [m] of a prismatic joint without limits."""


@dataclass(frozen=True)
class Slider:
    """One coordinate's slider: index, name, unit and range; ``value`` is the initial pose."""

    index: int
    name: str
    unit: str
    low: float
    high: float
    value: float


def home_pose(device: Device) -> np.ndarray:
    """Actuated coordinates of the home pose: a loop device's ``home``, else zeros; moved to the middle of a
    joint's limits where the value lies outside them."""
    q = configuration_of(device).home.copy()
    for k, span in enumerate(device.joint_limits()):
        if span is not None and not span[0] <= q[k] <= span[1]:
            q[k] = 0.5 * (span[0] + span[1])
    return q


def sliders(device: Device, q: np.ndarray) -> list[Slider]:
    """A slider per coordinate over its limits (full turn, or +-0.1 m, without), widened to hold ``q``."""
    out = []
    mech = device.mechanism
    kinds = [mech.joint_types[mech.coordinates.index(name)] for name in actuated_names(device)]
    for k, (name, kind, span) in enumerate(zip(actuated_names(device), kinds, device.joint_limits())):
        prismatic = kind is JointType.PRISMATIC
        low, high = span if span is not None else ((-PRISMATIC_SPAN, PRISMATIC_SPAN) if prismatic else (-math.pi, math.pi))
        value = float(q[k])
        out.append(Slider(k, name, "m" if prismatic else "rad", min(low, value), max(high, value), value))
    return out


def actuated_names(device: Device) -> tuple[str, ...]:
    """Names of the actuated coordinates (all coordinates of a tree)."""
    return configuration_of(device).names


def frame_poses(device: Device, q: np.ndarray) -> dict[str, np.ndarray]:
    """World pose (4x4) of every frame, ``base`` included, at actuated coordinates ``q``."""
    tree = device.mechanism.compiled.tree
    rot, pos = tree.workspace()
    q = np.ascontiguousarray(configuration_of(device).full(q), dtype=float)
    node_poses(q, *tree.arrays, len(tree.parent) - 1, rot, pos)
    poses = {}
    for name, node in tree.frame_node.items():
        poses[name] = np.eye(4)
        if node >= 0:
            poses[name][:3, :3], poses[name][:3, 3] = rot[node], pos[node]
    return poses


def links(device: Device) -> list[tuple[str, str]]:
    """Segments ``(parent frame, frame)`` between frame origins; ``base`` is the root."""
    return [(frame.parent or "base", frame.name) for frame in device.mechanism.frames]


def mass_centres(device: Device, poses: dict[str, np.ndarray]) -> list[tuple[str, float, np.ndarray]]:
    """``(body, mass, position)`` of every body with mass at the poses of :func:`frame_poses`."""
    out = []
    for attachment in device.mechanism.bodies:
        body = device.body(attachment.name)
        if body.m > 0:
            out.append((attachment.name, body.m, (poses[attachment.frame] @ np.append(body.r, 1.0))[:3]))
    return out


def parse_pose(text: str | None, device: Device) -> np.ndarray:
    """``--q`` as a pose (the home pose of :func:`home_pose` when not given)."""
    if text is None:
        return home_pose(device)
    try:
        values = [float(v) for v in text.replace(" ", "").split(",") if v != ""]
    except ValueError:
        raise InputError(f"q: expected comma-separated numbers, got {text[:80]!r}", "q") from None
    if len(values) != device.n_dof:
        raise InputError(f"q: expected {device.n_dof} values, got {len(values)}", "q")
    if not all(math.isfinite(v) for v in values):
        raise InputError("q: values must be finite", "q")
    return np.array(values)


def export(device: Device, q: np.ndarray) -> dict:
    """Everything the page needs, JSON-ready: sliders, node table, frames, links, bodies."""
    mech = device.mechanism
    compiled = mech.compiled
    poses = frame_poses(device, q)
    loops = mech.loops
    actuated = list(range(mech.n_dof)) if loops is None else list(loops.actuated(mech.n_dof))
    extent = max([float(np.abs(p[:3, 3]).max()) for p in poses.values()] + [1e-3])
    frames = [{"name": name, "node": int(node)} for name, node in compiled.frame_node.items()]
    return {
        "name": device.name,
        "sliders": [{**s.__dict__, "coordinate": actuated[s.index]} for s in sliders(device, q)],
        "full": [float(v) for v in configuration_of(device).full(q)],
        "passive": [] if loops is None else [int(k) for k in loops.passive],
        "closures": [] if loops is None else [[c.frames[0], c.frames[1], [int(v) for v in c.components]]
                                               for c in loops.closures],
        "nodes": [[int(compiled.node_parent[n]), int(compiled.node_axis[n]), float(compiled.node_offset[n]),
                   [float(c) for c in compiled.node_coef[n]]] for n in range(len(compiled.node_parent))],
        "frames": frames,
        "links": [list(pair) for pair in links(device)],
        "bodies": [{"name": a.name, "frame": a.frame, "m": device.body(a.name).m,
                    "r": [float(v) for v in device.body(a.name).r]} for a in mech.bodies if device.body(a.name).m > 0],
        "end_effector": mech.end_effector,
        "extent": extent,
    }
