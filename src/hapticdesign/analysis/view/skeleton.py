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


def bars(device: Device) -> list[tuple[str, np.ndarray]]:
    """``(frame, end)``: each body with its mass centre off its frame's origin drawn as a uniform bar from that
    origin to twice the mass centre (``end`` in the frame's axes), e.g. a rod whose far end is no frame."""
    out = []
    for attachment in device.mechanism.bodies:
        body = device.body(attachment.name)
        if body.m > 0 and np.any(body.r):
            out.append((attachment.frame, 2.0 * np.asarray(body.r, dtype=float)))
    return out


PLATE_PROBE = 0.05
"""rad or m: the actuated moves that tell which frame origins move as one rigid body (:func:`plates`)."""


def plates(device: Device, q: np.ndarray) -> list[list[str]]:
    """Rigid plates to fill: per rigid body, the largest set of coplanar, non-collinear frame origins it carries
    (3 or more distinct points), as the frames of their convex hull in order. A frame origin belongs to the
    body of frame A (``base`` for the ground) when it keeps its coordinates in A's axes while each actuated
    coordinate moves by :data:`PLATE_PROBE` from ``q`` (the loops closed); e.g. a delta's base triangle of
    hip pivots and its platform with the rods' anchors. The ground is a plate only when all its distinct
    points are coplanar (three chain bases on the three axes and the origin are no plate)."""
    probes = [np.asarray(q, dtype=float)] + [q + PLATE_PROBE * np.eye(len(q))[k] for k in range(len(q))]
    try:
        sampled = [frame_poses(device, p) for p in probes]
    except UserError:  # a probe the loops cannot reach: no plates, the links still draw the device
        return []
    names = list(sampled[0])
    extent = max(float(np.abs(p[:3, 3]).max()) for p in sampled[0].values()) or 1.0
    tol = 1e-9 * extent
    found: list[list[str]] = []
    seen: set[frozenset[str]] = set()
    for carrier in names:
        local = np.array([[np.linalg.solve(s[carrier], np.append(s[name][:3, 3], 1.0))[:3] for name in names]
                          for s in sampled])
        rigid = [names[i] for i in range(len(names)) if np.ptp(local[:, i], axis=0).max() <= tol]
        ground = max(np.ptp(np.array([s[carrier] for s in sampled]), axis=0).max(), 0.0) <= tol
        outline = _plate_outline(rigid, local[0, [names.index(n) for n in rigid]], tol, whole=ground)
        if outline and frozenset(outline) not in seen:
            seen.add(frozenset(outline))
            found.append(outline)
    return found


def _plate_outline(names: list[str], points: np.ndarray, tol: float, whole: bool = False) -> list[str]:
    """The convex hull, in order, of the largest coplanar subset of distinct ``points`` (one name per point);
    with ``whole``, none unless every distinct point lies in that plane."""
    distinct: list[int] = []
    for i, p in enumerate(points):
        if all(np.linalg.norm(p - points[j]) > tol for j in distinct):
            distinct.append(i)
    best: list[int] = []
    for a in range(len(distinct)):
        for b in range(a + 1, len(distinct)):
            for c in range(b + 1, len(distinct)):
                pa, pb, pc = points[distinct[a]], points[distinct[b]], points[distinct[c]]
                normal = np.cross(pb - pa, pc - pa)
                if np.linalg.norm(normal) <= tol * max(np.linalg.norm(pb - pa), np.linalg.norm(pc - pa)):
                    continue
                normal /= np.linalg.norm(normal)
                members = [i for i in distinct if abs(float(normal @ (points[i] - pa))) <= tol]
                if len(members) > len(best):
                    best = members
    if len(best) < 3 or (whole and len(best) < len(distinct)):
        return []
    plane = points[best] - points[best].mean(axis=0)
    u, v = np.linalg.svd(plane)[2][:2]
    from scipy.spatial import ConvexHull

    hull = ConvexHull(np.column_stack([plane @ u, plane @ v]))
    return [names[best[i]] for i in hull.vertices]


def scale_length(extent: float) -> float:
    """A round length (1, 2 or 5 times a power of ten, m) near a quarter of ``extent``, for a scale bar."""
    target = max(extent, 1e-6) / 4.0
    power = 10.0 ** math.floor(math.log10(target))
    return max(step * power for step in (1.0, 2.0, 5.0) if step * power <= target)


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
    actuated = list(loops.actuated(mech.n_dof))
    extent = max([float(np.abs(p[:3, 3]).max()) for p in poses.values()] + [1e-3])
    frames = [{"name": name, "node": int(node)} for name, node in compiled.frame_node.items()]
    return {
        "name": device.name,
        "sliders": [{**s.__dict__, "coordinate": actuated[s.index]} for s in sliders(device, q)],
        "full": [float(v) for v in configuration_of(device).full(q)],
        "passive": [int(k) for k in loops.passive],
        "closures": [[c.frames[0], c.frames[1], [int(v) for v in c.components]] for c in loops.closures],
        "nodes": [[int(compiled.node_parent[n]), int(compiled.node_axis[n]), float(compiled.node_offset[n]),
                   [float(c) for c in compiled.node_coef[n]]] for n in range(len(compiled.node_parent))],
        "frames": frames,
        "links": [list(pair) for pair in links(device)],
        "bodies": [{"name": a.name, "frame": a.frame, "m": device.body(a.name).m,
                    "r": [float(v) for v in device.body(a.name).r]} for a in mech.bodies if device.body(a.name).m > 0],
        "bars": [{"frame": frame, "end": [float(v) for v in end]} for frame, end in bars(device)],
        "plates": plates(device, q),
        "end_effector": mech.end_effector,
        "extent": extent,
        "scale": scale_length(extent),
    }


def snapshot(device: Device, q: np.ndarray) -> dict:
    """The device drawn at one pose, JSON-ready, for a still 3D view that turns but does not move the joints (the
    optimization report's design card): the frame origins, the links between them, the bodies' bars, the rigid
    plates (outlines of frame names), the mass centres with their masses, the end effector and a scale length, all
    in metres in the base frame; ``q`` the actuated coordinates."""
    poses = frame_poses(device, q)
    origins = {name: [float(v) for v in pose[:3, 3]] for name, pose in poses.items()}
    ends = [[origins[frame], [float(v) for v in (poses[frame] @ np.append(end, 1.0))[:3]]] for frame, end in bars(device)]
    masses = [{"name": name, "m": float(m), "p": [float(v) for v in p]} for name, m, p in mass_centres(device, poses)]
    points = np.array([*origins.values(), *(e[1] for e in ends), *(m["p"] for m in masses)])
    extent = float(max(np.ptp(points, axis=0).max(), 1e-3))
    return {
        "q": [float(v) for v in q],
        "origins": origins,
        "links": [list(pair) for pair in links(device)],
        "bars": ends,
        "plates": plates(device, q),
        "masses": masses,
        "end_effector": device.mechanism.end_effector,
        "scale": scale_length(extent),
    }
