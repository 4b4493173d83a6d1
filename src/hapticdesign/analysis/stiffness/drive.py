"""The compliance between the motors and the handle in joint space: the transmissions' and the links' in series.

The sampled loop's compliant plant (:func:`hapticdesign.analysis.sampled_loop.handle_loops`) puts one spring ``K``
(n x n, symmetric) between the motors' coordinates ``phi`` (the rotors' ``n^2 J_r`` and the motors' damping) and the
links' ``q`` (the links' inertia, the joints' damping, the hand and gravity): the drive of
:class:`~hapticdesign.model.actuators.Transmission`, whose ``stiffness`` is that ``K``. Two compliances make it:

- **the transmissions'** ``K_t^-1`` (``transmission_stiffness`` of the actuators, ``K_t = sum k a a^T``);
- **the links'**, where the device file gives elastic links (or joint springs): the VJM (seed 001 §5.2, eq.
  5.117-5.123) gives the handle's Cartesian stiffness ``K_C`` with the actuated joints locked
  (:func:`~hapticdesign.analysis.stiffness.device.cartesian_stiffness_at`). A wall and a hand push on the handle
  with a force ``F`` and no moment, so the links deflect the handle by ``C_F F``, ``C_F`` the translational block
  of ``K_C^-1`` (the rotations free to follow). The rigid-link model feels
  ``tau = J_v^T F`` at the joints and moves the handle by ``J_v dq``. The joint-space compliance ``C_q`` that moves
  the handle as the links do, ``J_v C_q J_v^T = P C_F P`` (``P = J_v J_v^+`` the projector on the directions the
  handle moves), for every force in those directions, is

      C_q = J_v^+ C_F J_v^+T            (J_v^-1 C_F J_v^-T for a square J_v),

  exact when ``J_v`` has full column rank (at most three actuated joints, at a regular pose: each joint's motion
  seen at the handle, :func:`joint_compliance`); the deflection out of those directions (a planar device bending out
  of its plane) is not seen by the wall and is left out. A single cantilever of length ``L`` on a revolute joint,
  its tip the handle, gives ``C_q = (L^3 / (3 E I)) / L^2``: the tip's stiffness ``3 E I / L^3`` times ``L^2``.

In series, ``K = (K_t^-1 + C_q)^-1`` (:func:`compliant_drive`); without a transmission ``K = C_q^-1``. Assumed: the
links' inertia is lumped beyond the whole compliance, on the handle's side, and the rotors before it (one spring per
joint, the drive's lowest mode; the links' own distributed modes are left out, the VJM being static); the joints'
damping acts on the links' side. Motors with no rotor inertia (and no damping of their own) make a massless motor
side: the spring passes the held torque unchanged and the encoders read ``q + K^-1 u`` (the sampled loop's reduction).
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.stiffness.device import cartesian_stiffness_at
from hapticdesign.errors import UserError
from hapticdesign.model.actuators import Transmission, damping_matrix
from hapticdesign.model.device import Device

RANK_TOL = 1e-9
"""``J_v`` has full column rank when its smallest singular value is above this share of its largest."""


def elastic(device: Device) -> bool:
    """Whether the device file gives elastic links or joint springs (the links' compliance enters the drive); a
    one-line error when it gives joint springs beside transmissions (the drives' compliance stated twice)."""
    elasticity = device.elasticity
    if elasticity is None or not (elasticity.links or elasticity.joints):
        return False
    if elasticity.joints and device.transmission is not None:
        raise UserError(f"device {device.name} gives both joint_stiffness and transmission_stiffness: each states the "
                        "drives' compliance (give the drives' compliance once)")
    return True


def compliances(device: Device) -> str:
    """What a wall's drive includes, for an output: ``rigid``, ``transmissions``, ``links`` or ``transmissions and
    links`` (the links' meaning the VJM's, with any joint springs)."""
    parts = [name for name, present in (("transmissions", device.transmission is not None),
                                        ("links", elastic(device))) if present]
    return " and ".join(parts) or "rigid"


def joint_compliance(jacobian: np.ndarray, cartesian_stiffness: np.ndarray) -> np.ndarray:
    """``C_q = J_v^+ [K_C^-1]_(1:3, 1:3) J_v^+T`` (P, n, n) from ``J_v`` (P, 3, n) and the VJM's ``K_C`` (P, 6, 6)
    (module docstring); a one-line error when ``J_v`` has not full column rank (more actuated joints than the
    handle's translations, or a singular pose) or ``K_C`` is singular."""
    jacobian = np.asarray(jacobian, dtype=float)
    s = np.linalg.svd(jacobian, compute_uv=False)
    n = jacobian.shape[-1]
    if n > 3 or not np.all(s[..., -1] > RANK_TOL * s[..., 0]):
        raise UserError("the links' compliance maps to the joints only where the handle's translation moves with each "
                        f"actuated joint (at most 3, at a regular pose); here {n} joint(s), J_v of rank "
                        f"{int(np.min(np.sum(s > RANK_TOL * s[..., :1], axis=-1)))}")
    try:
        force = np.linalg.inv(np.asarray(cartesian_stiffness, dtype=float))[..., :3, :3]
    except np.linalg.LinAlgError:
        raise UserError("the handle's VJM stiffness is singular at this pose: the links' compliance is not "
                        "defined there") from None
    pinv = np.linalg.pinv(jacobian)
    c = pinv @ force @ np.swapaxes(pinv, -1, -2)
    return 0.5 * (c + np.swapaxes(c, -1, -2))


def compliant_drive(transmission: Transmission | None, links: np.ndarray | None, rotor: np.ndarray,
                    motor_damping: np.ndarray) -> Transmission | None:
    """The drive between the motors and the handle: ``transmission`` (each (n, n) or (P, n, n); None: rigid) and
    the links' joint-space compliance ``links`` (P, n, n; None: rigid links) in series, ``K = (K_t^-1 + C_q)^-1``,
    the rotors ``rotor`` and the motors' damping ``motor_damping`` on the motors' side; ``transmission`` itself
    without elastic links, None when both are rigid."""
    if links is None:
        return transmission
    links = np.asarray(links, dtype=float)
    shape = links.shape
    if transmission is None:
        inertia, damping, compliance = rotor, motor_damping, links
    else:
        inertia, damping = transmission.inertia, transmission.damping
        try:
            compliance = np.linalg.inv(transmission.stiffness) + links
        except np.linalg.LinAlgError:
            raise UserError("the transmissions' stiffness is singular (a coordinate no motor turns): the links' "
                            "compliance cannot be put in series with it") from None
    stiffness = np.linalg.inv(compliance)
    return Transmission(np.broadcast_to(np.asarray(inertia, dtype=float), shape).copy(),
                        np.broadcast_to(np.asarray(damping, dtype=float), shape).copy(),
                        0.5 * (stiffness + np.swapaxes(stiffness, -1, -2)))


def device_drive(device: Device, full: np.ndarray, jacobian: np.ndarray, frame: str | None = None,
                 stiffness: np.ndarray | None = None) -> Transmission | None:
    """:func:`compliant_drive` of ``device`` at closed full poses ``full`` (P, N) whose handle Jacobians ``J_v``
    (P, 3, n) are ``jacobian``: its transmissions and, when it gives elastic links (:func:`elastic`), their
    compliance from the VJM's ``K_C`` (``stiffness`` (P, 6, 6) when known, else computed at ``frame``)."""
    links = None
    if elastic(device):
        if stiffness is None:
            stiffness = np.array([cartesian_stiffness_at(device, q, frame) for q in np.atleast_2d(full)])
        links = joint_compliance(jacobian, stiffness)
    return compliant_drive(device.transmission, links, device.reflected_inertia,
                           damping_matrix(device.actuators, device.n_dof))
