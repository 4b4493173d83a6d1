"""Actuators and joint limits: what a motor adds to a joint, and the range a joint may move in.

A motor of rotor inertia ``J_r`` drives joint ``i`` through a transmission of ratio ``n`` (rotor
angle per joint unit: rad/rad for a revolute joint, rad/m for a prismatic one). Its kinetic energy
``J_r (n qd_i)^2 / 2`` adds the *reflected inertia* ``n^2 J_r`` to the diagonal entry ``H_ii`` of
the mass matrix of seed 000 eq. 2.50. The gyroscopic coupling between a rotor and a moving carrier
link is neglected, as usual for geared or capstan drives (Spong, Hutchinson & Vidyasagar,
*Robot Modeling and Control*, 2006, §7.4); the reflected inertia is therefore a constant matrix,
``H(q) = H_pi(q) + diag(n^2 J_r)``, and the dynamics stay linear in the standard inertial
parameters ``pi`` (a constant has no variance over a region, so the Linearity Number of eq. 3.1-3.4
is unchanged by it). Coulomb friction and viscous damping are given on the joint side (N m and
N m s/rad, or N and N s/m), i.e. as the joint feels them through the transmission.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

Limits = tuple[float, float] | None
"""A joint's range ``(low, high)`` in rad or m, or ``None`` when it moves freely."""


@dataclass(frozen=True)
class Actuator:
    """A motor on coordinate ``joint`` (0-based): rotor inertia [kg m^2], ratio, joint-side friction."""

    joint: int
    rotor_inertia: float = 0.0
    gear_ratio: float = 1.0
    coulomb: float = 0.0
    damping: float = 0.0

    @property
    def reflected_inertia(self) -> float:
        """``n^2 J_r``: kg m^2 on a revolute joint, kg on a prismatic one."""
        return self.gear_ratio**2 * self.rotor_inertia


def per_joint(actuators: tuple[Actuator, ...], n_dof: int, field: str) -> tuple[float, ...]:
    """One value per coordinate: the actuators' ``field`` (``reflected_inertia``, ``coulomb``, ``damping``)."""
    out = [0.0] * n_dof
    for actuator in actuators:
        out[actuator.joint] += float(getattr(actuator, field))
    return tuple(out)


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
