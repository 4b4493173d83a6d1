"""Denavit-Hartenberg builder in seed 000's convention (eq. 2.4-2.7, 2.11-2.26).

Link ``i`` is placed by ``(a_i, alpha_i, s_i, theta_i)``: ``C(i-1,i) = R3(theta_i) R1(alpha_i)``
(eq. 2.12-2.17) and ``P_i = P_{i-1} + s_i C(0,i-1) u3 + a_i C(0,i) u1`` (eq. 2.26), i.e. the
elementary transforms ``tz(s) Rz(theta) tx(a) Rx(alpha)``. The body of link ``i`` is expressed
in a frame with the orientation ``C(0,i)`` and the origin ``P_{i-1}`` (Table 2.3: the mass
centre vector is measured from the origin of frame ``i-1``); for a prismatic link the origin
moves with the link, ``P_{i-1} + s_i C(0,i-1) u3``.
"""

from __future__ import annotations

from dataclasses import dataclass

from hapticdesign.model.mechanism import Frame, JointType
from hapticdesign.model.transforms import JointValue, Rx, Rz, const, joint, tx, tz


@dataclass(frozen=True)
class DHRow:
    """One row of a DH table; the joint variable is ``theta`` (revolute) or ``s`` (prismatic)."""

    a: float
    alpha: float
    s: float | JointValue
    theta: float | JointValue

    @property
    def joint_type(self) -> JointType:
        return JointType.PRISMATIC if isinstance(self.s, JointValue) and not self.s.is_constant else JointType.REVOLUTE


def revolute(a: float, alpha: float, s: float, index: int, offset: float = 0.0) -> DHRow:
    return DHRow(a, alpha, s, joint(index, 1.0, offset))


def prismatic(a: float, alpha: float, theta: float, index: int, offset: float = 0.0) -> DHRow:
    return DHRow(a, alpha, joint(index, 1.0, offset), theta)


def _value(v: float | JointValue) -> JointValue:
    return v if isinstance(v, JointValue) else const(v)


def dh_frames(rows: list[DHRow], names: list[str], parent: str | None = None) -> list[Frame]:
    """Frames ``link<i>`` (DH frame i) and ``body<i>`` (the seed's body frame) for every row."""
    frames: list[Frame] = []
    for row, name in zip(rows, names):
        theta, s = _value(row.theta), _value(row.s)
        moving_s = row.joint_type is JointType.PRISMATIC
        body_path = ((tz(s),) if moving_s else ()) + (Rz(theta), Rx(row.alpha))
        frames.append(Frame(f"body{name}", parent, body_path))
        link_path = (Rx(-row.alpha),) + (() if moving_s else (tz(s),)) + (tx(row.a), Rx(row.alpha))
        frames.append(Frame(f"link{name}", f"body{name}", link_path))
        parent = f"link{name}"
    return frames
