"""Cartesian stiffness of any device by the virtual joint method (seed 001 §5.2, eq. 5.75-5.123).

The device's elastic links and joint springs (:mod:`hapticdesign.model.elastic`) become the VJM's
virtual joints:

- each link gets a six-coordinate virtual joint ``tx ty tz Rx Ry Rz`` appended to its end frame
  (eq. 5.75-5.81), in that frame's axes; its compliance is the inverse of the cantilever stiffness
  (eq. 4.58-4.59, :func:`~hapticdesign.analysis.stiffness.link.beam_stiffness`) turned from the
  link's axes (x from the start frame's origin to the end frame's) into the end frame's;
- an actuated joint with a spring is a one-coordinate virtual joint (its own column, compliance
  ``1 / k``); actuated joints without one are locked, passive joints stay free (eq. 5.118).

With the end-effector Jacobian ``J`` over the virtual coordinates ``theta`` and the passive ones
``p`` (eq. 5.93-5.97) and, for a device with closed loops, the loop-closure Jacobian ``Phi``
(:mod:`hapticdesign.analysis.loops.solver`), equilibrium under a wrench ``F`` at the end effector
with loop reactions ``lambda`` reads (eq. 5.117-5.122 with the closures as extra rows)

    [[G C_theta G^T, P], [P^T, 0]] [[F; lambda], dp] = [[dx; 0], 0],
    G = [J_theta; Phi_theta],   P = [J_p; Phi_p],

so ``K_C`` is the leading 6 x 6 block of the inverse bordered matrix
(:func:`~hapticdesign.analysis.stiffness.vjm.chain_stiffness`). For a serial chain (no loops, no
passive joints) it is ``(J_theta K_theta^-1 J_theta^T)^-1`` (eq. 4.55, 5.119); for a parallel device
whose chains meet at the end effector it equals the sum of the chains' stiffnesses (eq. 5.123).
Twists and wrenches are ``(v, w)`` and ``(F, M)`` in the base frame at the end-effector frame's origin.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.linalg import block_diag

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.kinematics import jacobian
from hapticdesign.analysis.stiffness import vjm
from hapticdesign.analysis.stiffness.link import beam_stiffness
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.model.elastic import Elasticity, ElasticLink
from hapticdesign.model.loops import LoopClosure
from hapticdesign.model.mechanism import JointType, Mechanism
from hapticdesign.model.transforms import Rx, Ry, Rz, joint, tx, ty, tz

LENGTH_TOLERANCE = 1e-12


def check_elasticity(mech: Mechanism, elasticity: Elasticity) -> None:
    """Each link's end frame is fixed to its start frame (no coordinate between them) at a distance;
    each joint spring is on an actuated joint. Raises a one-line UserError."""
    compiled = mech.compiled
    for link in elasticity.links:
        for frame in (link.start, link.end):
            if frame not in compiled.frame_node:
                raise UserError(f"link {link.name}: unknown frame {frame!r}")
        start, end = compiled.path_to(link.start), compiled.path_to(link.end)
        between = end[len(start):]
        if end[: len(start)] != start or np.any(compiled.node_coef[between] != 0.0):
            raise UserError(f"link {link.name}: frame {link.end!r} must follow {link.start!r} with no joint "
                            "between them (a link is one rigid piece of the tree)")
        if _length(mech, link, np.zeros(mech.n_dof)) <= LENGTH_TOLERANCE:
            raise UserError(f"link {link.name}: frames {link.start!r} and {link.end!r} coincide (zero length)")
    actuated = set(mech.actuated_coordinates)
    for name, _ in elasticity.joints:
        if name not in actuated:
            kind = "a passive joint is free" if name in mech.coordinates else "unknown joint"
            raise UserError(f"joint stiffness {name}: {kind} (actuated joints: {', '.join(mech.actuated_coordinates)})")


def _length(mech: Mechanism, link: ElasticLink, q: np.ndarray) -> float:
    c = mech.compiled
    return float(np.linalg.norm(c.frame_pose(q, link.end)[:3, 3] - c.frame_pose(q, link.start)[:3, 3]))


def virtual_mechanism(mech: Mechanism, elasticity: Elasticity) -> Mechanism:
    """The mechanism with a virtual joint ``tx ty tz Rx Ry Rz`` appended to each link's end frame
    (eq. 5.75-5.81); the virtual coordinates follow the device's, six per link in link order."""
    first = {link.end: mech.n_dof + 6 * k for k, link in enumerate(elasticity.links)}
    frames = tuple(
        replace(f, transforms=f.transforms + _virtual_joint(first[f.name])) if f.name in first else f
        for f in mech.frames
    )
    names = tuple(f"{link.name}_{axis}" for link in elasticity.links for axis in ("tx", "ty", "tz", "rx", "ry", "rz"))
    types = ((JointType.PRISMATIC,) * 3 + (JointType.REVOLUTE,) * 3) * len(elasticity.links)
    return Mechanism(mech.coordinates + names, mech.joint_types + types, frames, (), mech.gravity, mech.end_effector)


def _virtual_joint(first: int) -> tuple:
    return (tx(joint(first)), ty(joint(first + 1)), tz(joint(first + 2)),
            Rx(joint(first + 3)), Ry(joint(first + 4)), Rz(joint(first + 5)))


def _link_compliance(mech: Mechanism, link: ElasticLink, q: np.ndarray) -> np.ndarray:
    """Compliance of the link's virtual joint in its end frame's axes (eq. 4.59 turned from the link's axes)."""
    c = mech.compiled
    end = c.frame_pose(q, link.end)
    axis = end[:3, :3].T @ (end[:3, 3] - c.frame_pose(q, link.start)[:3, 3])
    return end_compliance(axis, link.axial, link.bending, link.torsion)


def end_compliance(axis, axial, bending, torsion) -> np.ndarray:
    """Compliance (..., 6, 6) of links' virtual joints in their end frames' axes, from each link's vector ``axis``
    (..., 3) from its start frame's origin to its end frame's, in the end frame's axes, and its rigidities: the
    cantilever's (eq. 4.58-4.59, :func:`~hapticdesign.analysis.stiffness.link.beam_stiffness`) turned from the
    link's axes (x along the link) into the end frame's."""
    axis = np.asarray(axis, dtype=float)
    length = np.linalg.norm(axis, axis=-1)
    x = axis / length[..., None]
    helper = np.eye(3)[np.argmin(np.abs(x), axis=-1)]
    y = np.cross(x, helper)
    y /= np.linalg.norm(y, axis=-1)[..., None]
    T = np.zeros(axis.shape[:-1] + (6, 6))
    T[..., :3, :3] = T[..., 3:, 3:] = np.stack([x, y, np.cross(x, y)], axis=-1)  # link axes in the end frame's axes
    return T @ np.linalg.inv(beam_stiffness(axial, bending, torsion, length)) @ np.swapaxes(T, -1, -2)


def cartesian_stiffness(device: Device, q_a, frame: str | None = None) -> np.ndarray:
    """``K_C`` (6 x 6) of ``frame`` (default: the end effector) at actuated coordinates ``q_a``
    (see the module docstring)."""
    elasticity = device.elasticity
    if elasticity is None or not (elasticity.links or elasticity.joints):
        raise UserError(f"device {device.name} has no elastic links or joint springs (give links: with a "
                        "section and a material)")
    mech = device.mechanism
    frame = frame or mech.end_effector
    if frame is None:
        raise UserError(f"device {device.name} names no end-effector frame")
    check_elasticity(mech, elasticity)
    q_a = np.asarray(q_a, dtype=float)
    if q_a.shape != (mech.n_actuated,) or not np.all(np.isfinite(q_a)):
        raise UserError(f"expected {mech.n_actuated} finite actuated joint coordinates, got {q_a.tolist()}")
    return cartesian_stiffness_at(device, configuration_of(device).full(q_a), frame)


def cartesian_stiffness_at(device: Device, q: np.ndarray, frame: str | None = None) -> np.ndarray:
    """``K_C`` (6 x 6) of ``frame`` (default: the end effector) at the closed full pose ``q`` (N,) of a device with
    elastic links or joint springs (:func:`cartesian_stiffness` at actuated coordinates)."""
    elasticity, mech = device.elasticity, device.mechanism
    if elasticity is None or not (elasticity.links or elasticity.joints):
        raise UserError(f"device {device.name} has no elastic links or joint springs (give links: with a "
                        "section and a material)")
    frame = frame or mech.end_effector
    virtual = virtual_mechanism(mech, elasticity)
    q_virtual = np.concatenate([q, np.zeros(virtual.n_dof - mech.n_dof)])
    rows = np.vstack([jacobian(virtual, q_virtual, frame), *closure_rows(virtual, q_virtual, mech.loops.closures)])
    springs = dict(elasticity.joints)
    index = {name: k for k, name in enumerate(mech.coordinates)}
    theta = list(range(mech.n_dof, virtual.n_dof)) + [index[name] for name in springs]
    blocks = [_link_compliance(mech, link, q) for link in elasticity.links] + [
        np.array([[1.0 / k]]) for k in springs.values()]
    C_theta = block_diag(*blocks)
    try:
        K = vjm.chain_stiffness(rows[:, theta], C_theta, rows[:, list(mech.loops.passive)])
    except UserError:
        raise UserError(f"the end effector {frame!r} is rigid in some direction at this pose: the elastic links "
                        "and joint springs do not reach it, or the pose is singular") from None
    return K[:6, :6]


def closure_rows(mech: Mechanism, q: np.ndarray, closures: tuple[LoopClosure, ...]) -> list[np.ndarray]:
    """The constraint Jacobian ``Phi = select(J_A - J_B)`` of ``closures`` at the full pose ``q`` of ``mech`` (one
    array of rows per closure; none for a tree), with ``J`` the geometric Jacobian of a frame's origin (the
    definition of :mod:`hapticdesign.analysis.loops.closure_kernel`), here over the virtual coordinates too."""
    return [(jacobian(mech, q, c.frames[0]) - jacobian(mech, q, c.frames[1]))[list(c.components)] for c in closures]


def deflection(stiffness: np.ndarray, wrench) -> np.ndarray:
    """Deflection ``(dx, dphi)`` (6,) of the end effector with stiffness ``K_C`` under ``wrench`` ``(F, M)``
    or ``F`` (moments zero): ``K_C^-1 F`` (eq. 5.117-5.123, unloaded mode)."""
    w = np.asarray(wrench, dtype=float)
    if w.shape == (3,):
        w = np.concatenate([w, np.zeros(3)])
    if w.shape != (6,) or not np.all(np.isfinite(w)):
        raise UserError(f"a wrench is 3 forces or 6 forces and moments, finite, got {np.ravel(wrench).tolist()}")
    try:
        return np.linalg.solve(stiffness, w)
    except np.linalg.LinAlgError:
        raise UserError("K_C is singular at this pose: the end effector moves freely in some direction") from None
