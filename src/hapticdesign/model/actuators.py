"""Actuators and joint limits: what a motor adds to the joints, and the range a joint may move in.

A motor of rotor inertia ``J_r`` turns, through a transmission of ratio ``n`` (rotor angle per
joint unit: rad/rad for a revolute joint, rad/m for a prismatic one), one coordinate or an affine
combination ``a^T q + a_0`` of them: a capstan that drives the Phantom's distal link from the base
turns its absolute angle, the sum ``theta2 + theta3`` of seed 000's relative DH angles (Table 2.2).
Its kinetic energy ``J_r (n a^T qd)^2 / 2`` adds the *reflected inertia* ``n^2 J_r a a^T`` to the
mass matrix of seed 000 eq. 2.50 (``n^2 J_r`` on the diagonal entry ``H_ii`` when ``a`` is the unit
vector of coordinate ``i``); its viscous damping ``b`` adds ``b a a^T`` and its Coulomb friction
``f`` the torque ``f sign(a^T qd) a``, both acting on the combination's rate ``a^T qd``. The gyroscopic coupling between a rotor and a moving carrier
link is neglected, as usual for geared or capstan drives (Spong, Hutchinson & Vidyasagar,
*Robot Modeling and Control*, 2006, §7.4); the reflected inertia is therefore a constant matrix,
``H(q) = H_pi(q) + sum n^2 J_r a a^T``, and the dynamics stay linear in the standard inertial
parameters ``pi`` (a constant has no variance over a region, so the Linearity Number of eq. 3.1-3.4
is unchanged by it). Coulomb friction and viscous damping are given on the joint side (N m and
N m s/rad, or N and N s/m), i.e. as the joint feels them through the transmission.

A compliant transmission (``transmission_stiffness`` ``k``, N m/rad or N/m at the joint side: a capstan's cables,
a belt, a gearbox's torsion) puts a spring between the motor and the link: the motor's coordinate ``phi`` (its
angle divided by ``n``, in joint units) carries the rotor's ``n^2 J_r`` and the motor's damping ``b``, friction and
encoder, and the link side the rest of H, the spring ``k (a^T q - phi)^2 / 2`` between them. Over the coordinates
the motors turn this is :class:`Transmission` (``M_r = sum n^2 J_r a a^T``, ``B_m = sum b a a^T``,
``K_t = sum k a a^T``); as ``k`` grows the two sides move as one and the rigid model above returns (the sampled
loop's plant, :func:`hapticdesign.analysis.sampled_loop.handle_loops`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from hapticdesign.errors import UserError

Limits = tuple[float, float] | None
"""A joint's range ``(low, high)`` in rad or m, or ``None`` when it moves freely."""


@dataclass(frozen=True)
class Actuator:
    """A motor on coordinate ``joint`` (0-based), or on the combination ``coupling`` of coordinates:
    rotor inertia [kg m^2], ratio, friction and damping on the side of the coordinates it turns.

    ``coupling`` holds ``(coordinate, coefficient)`` pairs of ``a`` (empty: ``a`` is the unit vector
    of ``joint``); ``offset`` is ``a_0`` and ``limits`` the range of ``a^T q + a_0`` (the motor's
    travel, in joint units), or ``None``. ``torque_continuous`` and ``torque_peak`` are the motor's
    rated torques (N m at the motor shaft, before the transmission), ``encoder_cpr`` its encoder's
    counts per motor revolution as the data sheet gives them (lines; ``quadrature`` edges per line,
    4 for x4 decoding); ``None`` when not known. ``transmission_stiffness`` the stiffness between the motor and
    what it turns, at the joint side (N m/rad or N/m; ``None``: rigid).
    """

    joint: int
    rotor_inertia: float = 0.0
    gear_ratio: float = 1.0
    coulomb: float = 0.0
    damping: float = 0.0
    coupling: tuple[tuple[int, float], ...] = ()
    offset: float = 0.0
    limits: Limits = None
    torque_continuous: float | None = None
    torque_peak: float | None = None
    encoder_cpr: int | None = None
    quadrature: int = 4
    transmission_stiffness: float | None = None

    @property
    def counts_per_radian(self) -> float | None:
        """Encoder counts per radian (or metre) of ``a^T q``: ``cpr * quadrature * n / (2 pi)``."""
        if self.encoder_cpr is None:
            return None
        return self.encoder_cpr * self.quadrature * self.gear_ratio / (2.0 * math.pi)

    @property
    def reflected_inertia(self) -> float:
        """``n^2 J_r``: kg m^2 on a revolute joint, kg on a prismatic one (times ``a a^T`` in H)."""
        return self.gear_ratio**2 * self.rotor_inertia

    @property
    def coupled(self) -> bool:
        """Whether the motor turns anything but one coordinate with coefficient 1."""
        return bool(self.coupling) and self.coupling != ((self.joint, 1.0),)

    def row(self, n_dof: int) -> np.ndarray:
        """``a`` (n_dof,): the rate the motor turns is ``a^T qd``."""
        a = np.zeros(n_dof)
        for k, coefficient in self.coupling or ((self.joint, 1.0),):
            a[k] += coefficient
        return a


def transmission(actuators: tuple[Actuator, ...], n_dof: int) -> np.ndarray:
    """``A`` (actuators x n_dof): row k is actuator k's ``a`` (a unit row for a motor on one joint)."""
    return np.array([a.row(n_dof) for a in actuators]).reshape(len(actuators), n_dof)


def reflected_inertia_matrix(actuators: tuple[Actuator, ...], n_dof: int) -> np.ndarray:
    """``sum_k n_k^2 J_r,k a_k a_k^T`` (n_dof x n_dof), the constant the motors add to H (eq. 2.50);
    ``diag(n^2 J_r)`` when every motor turns one joint."""
    a = transmission(actuators, n_dof)
    return a.T @ (np.array([x.reflected_inertia for x in actuators]).reshape(-1, 1) * a)


def damping_matrix(actuators: tuple[Actuator, ...], n_dof: int) -> np.ndarray:
    """``sum_k b_k a_k a_k^T`` (n_dof x n_dof): the motors' viscous damping on the coordinates."""
    a = transmission(actuators, n_dof)
    return a.T @ (np.array([x.damping for x in actuators]).reshape(-1, 1) * a)


class Transmission(NamedTuple):
    """The motors' side of compliant transmissions over the coordinates they turn (module docstring), each
    (..., n, n): the rotors' reflected inertia ``M_r``, the motors' damping ``B_m`` and the transmissions' stiffness
    ``K_t``. The plant of the sampled loop then has the motor coordinates ``phi`` beside ``q``:
    ``M_r phi'' + B_m phi' + K_t (phi - q) = tau`` and ``(H - M_r) q'' + (B - B_m) q' + K_t (q - phi) = f_ext``."""

    inertia: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray

    def taken(self, index) -> "Transmission":
        """The transmissions of the poses ``index`` (leading axis), or all of them where the arrays are one
        design's (n, n)."""
        return Transmission(*(x if x.ndim == 2 else x[index] for x in self))


def transmission_of(actuators: tuple[Actuator, ...], n_dof: int) -> Transmission | None:
    """The :class:`Transmission` of the motors, or None when none states a ``transmission_stiffness``; a one-line
    error when some do and others do not (a rigid motor beside compliant ones would need a model of its own), or
    when the stiffness is not a positive finite number."""
    stated = [a.transmission_stiffness is not None for a in actuators]
    if not any(stated):
        return None
    if not all(stated):
        missing = ", ".join(str(a.joint + 1) for a in actuators if a.transmission_stiffness is None)
        raise UserError(f"every actuator states its transmission_stiffness once one does (missing on the motors of "
                        f"coordinates {missing})")
    k = np.array([a.transmission_stiffness for a in actuators], dtype=float)
    if not np.all(np.isfinite(k) & (k > 0)):
        raise UserError(f"a transmission_stiffness is a positive finite number (N m/rad or N/m), got "
                        f"{float(k[~(np.isfinite(k) & (k > 0))][0])!r}")
    a = transmission(actuators, n_dof)
    return Transmission(reflected_inertia_matrix(actuators, n_dof), damping_matrix(actuators, n_dof),
                        a.T @ (k[:, None] * a))


def motor_limit_warnings(q, actuators: tuple[Actuator, ...], names: tuple[str, ...]) -> list[str]:
    """One message per motor whose combination ``a^T q + a_0`` is outside its travel."""
    q = np.ravel(np.asarray(q, dtype=float))
    out = []
    for actuator in actuators:
        if actuator.limits is None:
            continue
        value = float(actuator.row(len(q)) @ q) + actuator.offset
        low, high = actuator.limits
        if not low <= value <= high:
            out.append(f"the motor on {combination_text(actuator, names)} is at {value:g}, outside its travel "
                       f"[{low:g}, {high:g}]")
    return out


def combination_text(actuator: Actuator, names: tuple[str, ...]) -> str:
    """``theta2 + theta3`` for a coupled motor, the coordinate's name otherwise."""
    terms = actuator.coupling or ((actuator.joint, 1.0),)
    parts = []
    for k, coefficient in terms:
        sign = "-" if coefficient < 0 else "+"
        size = "" if abs(coefficient) == 1.0 else f"{abs(coefficient):g} "
        parts.append(f"{sign} {size}{names[k]}")
    text = " ".join(parts)
    text = text[2:] if text.startswith("+ ") else "-" + text[2:]
    return text + (f" {'+' if actuator.offset >= 0 else '-'} {abs(actuator.offset):g}" if actuator.offset else "")


def limit_warnings(q, limits: tuple[Limits, ...], names: tuple[str, ...]) -> list[str]:
    """One message per coordinate of ``q`` outside its limits (none for coordinates without limits)."""
    out = []
    for k, (value, span) in enumerate(zip(q, limits)):
        if span is not None and not span[0] <= float(value) <= span[1]:
            out.append(f"{names[k]} = {float(value):g} is outside its limits [{span[0]:g}, {span[1]:g}]")
    return out


def full_turn(limits: Limits) -> tuple[float, float]:
    """A joint's range for sampling: its limits, or the full turn ``[-pi, pi]`` when it has none."""
    return (-math.pi, math.pi) if limits is None else (float(limits[0]), float(limits[1]))
