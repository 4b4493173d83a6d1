"""Modified R-CUBE mechanism (seed 001 §5.1-5.3) as elementary-transform chains.

Three identical serial chains, one per Cartesian axis. Chain ``i`` (0, 1, 2 here; 1, 2, 3 in the
seed) starts at its base frame ``H(0,i0)`` (eq. 5.2), then (eq. 5.5-5.9)

    Rz(phi1) tx(l1) | Rz(phi2) Rx(-pi/2) Rz(phi3) tx(l2) | Rz(phi4) tx(l3) | Rz(phi5) | H(i5,p)

with the active angle ``q_i1 = phi1`` and the passive angles ``q_i2 = phi3``, ``q_i3 = phi4``,
``phi2 = -q_i1`` and ``phi5 = -(q_i2 + q_i3)`` (eq. 5.10-5.14). Two printed constants are
corrected so that the chains reproduce the seed's own closed forms (eq. 5.21-5.23) and a platform
of constant identity orientation (eq. 5.20): chain 1's base rotation is ``Rx(-pi/2) Rz(-pi/2)``
(eq. 5.2 prints ``Rx(pi/2)``), and each ``H(i5,p)`` is the constant rotation that undoes the chain's
end orientation (the printed eq. 5.15-5.17 do not give the identity with these chains).

The stiffness chain (eq. 5.77-5.81) inserts a six-coordinate virtual joint
``tx ty tz Rx Ry Rz`` (eq. 5.75) at the end of each of the three links; its coordinates are ordered
as eq. 5.86: 18 virtual, the 4 passive angles ``phi2..phi5``, then the active angle ``q_i1``.
Mass-centre frames ``com1..com3`` sit ``lg_j`` along each link (eq. 5.139-5.141, 5.182-5.184).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import lru_cache, partial
from math import isfinite, pi

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.mechanism import BodyAttachment, Frame, JointType, Mechanism
from hapticdesign.model.transforms import (
    ElementaryTransform,
    Rx,
    Ry,
    Rz,
    combination,
    joint,
    tx,
    ty,
    tz,
)

N_CHAINS = 3
N_VIRTUAL = 18
N_STIFFNESS_COORDINATES = 23
PASSIVE_SLICE = slice(18, 22)
ACTIVE_INDEX = 22

_AXIS_PERMUTATIONS = ((0, 1, 2), (1, 2, 0), (2, 0, 1))
"""Solution sets (a, b, c) of eq. 5.35-5.37 (zero-based)."""


def axis_permutation(chain: int) -> tuple[int, int, int]:
    """The (a, b, c) index triple of chain ``chain`` (seed 001 eq. 5.35-5.37, zero-based)."""
    return _AXIS_PERMUTATIONS[chain]


MAX_LENGTH = 1000.0
"""Longest link or offset (m): the kinematics square lengths (eq. 5.39), which overflows near 1e154 m."""


@dataclass(frozen=True)
class RCubeGeometry:
    """Link lengths ``l1, l2, l3`` (m), chain offset ``S`` (eq. 5.2; ``None`` means ``S = l1``,
    eq. 6.39) and passive configuration ``sigma = +-1`` (eq. 5.42)."""

    l1: float
    l2: float
    l3: float
    offset: float | None = None
    sigma: int = -1

    def __post_init__(self) -> None:
        for name in ("l1", "l2", "l3"):
            value = getattr(self, name)
            if not isfinite(value) or not 0.0 < value <= MAX_LENGTH:
                raise UserError(f"{name} must be a positive length of at most {MAX_LENGTH:g} m, got {value!r}")
        if self.offset is not None and not (isfinite(self.offset) and abs(self.offset) <= MAX_LENGTH):
            raise UserError(f"offset must be a finite length of at most {MAX_LENGTH:g} m, got {self.offset!r}")
        if self.sigma not in (-1, 1):
            raise UserError(f"sigma must be -1 or +1, got {self.sigma!r}")

    @property
    def S(self) -> float:
        """Chain offset ``S`` (``d`` in chapter 6); defaults to ``l1`` (eq. 6.39)."""
        return self.l1 if self.offset is None else float(self.offset)

    @property
    def home(self) -> np.ndarray:
        """Platform position at the home pose ``q_i1 = 0`` (eq. 5.28): ``(S, S, S)``."""
        return np.full(3, self.S)


def _base_transforms(chain: int, S: float) -> tuple[ElementaryTransform, ...]:
    """``H(0,i0)`` of eq. 5.2 (chain 1 with the corrected sign, see the module docstring)."""
    if chain == 0:
        return (tx(S), Rx(-pi / 2), Rz(-pi / 2))
    if chain == 1:
        return (ty(S),)
    if chain == 2:
        return (tz(S), Rz(pi / 2), Rx(pi / 2))
    raise UserError(f"chain index must be 0, 1 or 2, got {chain!r}")


_PLATFORM_ALIGNMENT = {
    0: (Rx(pi / 2), Rz(pi / 2), Rx(pi / 2)),
    1: (Rx(pi / 2),),
    2: (Rz(-pi / 2),),
}
"""``H(i5,p)``: rotations whose product is the inverse of ``R(0,i0) Rx(-pi/2)``."""


def _virtual_joint(first: int) -> tuple[ElementaryTransform, ...]:
    """``H_v(theta) = T1 T2 T3 R1 R2 R3`` on coordinates ``first .. first+5`` (eq. 5.75)."""
    return (
        tx(joint(first)),
        ty(joint(first + 1)),
        tz(joint(first + 2)),
        Rx(joint(first + 3)),
        Ry(joint(first + 4)),
        Rz(joint(first + 5)),
    )


def _check_fractions(centres: tuple[float, float, float]) -> tuple[float, float, float]:
    if len(centres) != 3 or not all(isfinite(c) and 0.0 <= c <= 1.0 for c in centres):
        raise UserError(f"mass-centre fractions must be three numbers in [0, 1], got {centres!r}")
    return tuple(float(c) for c in centres)


@lru_cache(maxsize=128)
def chain_mechanism(
    geometry: RCubeGeometry, chain: int, centres: tuple[float, float, float] = (0.5, 0.5, 0.5)
) -> Mechanism:
    """Kinematic chain ``chain`` with coordinates ``(q_i1, q_i2, q_i3)`` (eq. 5.5-5.18).

    Cached per arguments: the returned mechanism is shared and must not be modified.
    Frames: ``link1..link3`` (joint frames), ``com1..com3`` (mass centres at ``centres`` times
    the link length, eq. 5.182-5.184), ``tip1..tip3`` (link ends), ``platform`` (end effector).
    """
    g, (c1, c2, c3) = geometry, _check_fractions(centres)
    frames = (
        Frame("chain_base", None, _base_transforms(chain, g.S)),
        Frame("link1", "chain_base", (Rz(joint(0)),)),
        Frame("com1", "link1", (tx(c1 * g.l1),)),
        Frame("tip1", "link1", (tx(g.l1),)),
        Frame("link2", "tip1", (Rz(joint(0, -1.0)), Rx(-pi / 2), Rz(joint(1)))),
        Frame("com2", "link2", (tx(c2 * g.l2),)),
        Frame("tip2", "link2", (tx(g.l2),)),
        Frame("link3", "tip2", (Rz(joint(2)),)),
        Frame("com3", "link3", (tx(c3 * g.l3),)),
        Frame("tip3", "link3", (tx(g.l3),)),
        Frame("platform", "tip3", (Rz(combination({1: -1.0, 2: -1.0})), *_PLATFORM_ALIGNMENT[chain])),
    )
    return Mechanism(
        coordinates=(f"q{chain + 1}1", f"q{chain + 1}2", f"q{chain + 1}3"),
        joint_types=(JointType.REVOLUTE,) * 3,
        frames=frames,
        bodies=(),
        gravity=(0.0, 0.0, -9.81),
        end_effector="platform",
        metadata={"device": "rcube", "chain": chain},
    )


CHAIN_KINEMATIC = ("l1", "l2", "l3", "S")
"""Kinematic parameters of a chain's equations of motion (:data:`CHAIN_BUILDERS`)."""

CHAIN_BODIES = (("1", "link1"), ("2", "link2"), ("3", "link3"), ("p", "platform"))
"""Bodies of a chain's equations of motion and their frames: the three tubes on the joint frames
``link1..link3`` (x along the link, mass centre at ``(lg_j, 0, 0)``, eq. 5.182-5.184) and the chain's
share of the platform at the platform frame's origin."""


def _chain_dynamics_mechanism(chain: int, params: Mapping[str, float]) -> Mechanism:
    mech = chain_mechanism(RCubeGeometry(params["l1"], params["l2"], params["l3"], params["S"]), chain)
    return replace(
        mech,
        bodies=tuple(BodyAttachment(name, frame) for name, frame in CHAIN_BODIES),
        gravity=(0.0, 0.0, 0.0),
        metadata=dict(mech.metadata),
    )


CHAIN_BUILDERS = tuple(partial(_chain_dynamics_mechanism, chain) for chain in range(N_CHAINS))
"""Mechanism builders of the chains' equations of motion (seed 001 eq. 5.199-5.209), one per chain:
:func:`chain_mechanism` of the parameters :data:`CHAIN_KINEMATIC` with the bodies :data:`CHAIN_BODIES`
and no gravity (the seed leaves it out, §5.3). One object per chain, so that models cached per
builder and geometry are shared."""


@lru_cache(maxsize=128)
def stiffness_chain_mechanism(
    geometry: RCubeGeometry, chain: int, centres: tuple[float, float, float] = (0.5, 0.5, 0.5)
) -> Mechanism:
    """Chain ``chain`` with virtual joints (eq. 5.77-5.81): 23 coordinates ordered as eq. 5.86.

    Frames: ``com1..com3`` (mass centres, eq. 5.139-5.141; ``com1`` precedes the first virtual
    joint as in the seed) and ``platform``.
    """
    g, (c1, c2, c3) = geometry, _check_fractions(centres)
    p2, p3, p4, p5, a = 18, 19, 20, 21, ACTIVE_INDEX
    frames = (
        Frame("chain_base", None, _base_transforms(chain, g.S)),
        Frame("link1", "chain_base", (Rz(joint(a)),)),
        Frame("com1", "link1", (tx(c1 * g.l1),)),
        Frame("k1", "link1", (tx(g.l1), *_virtual_joint(0))),
        Frame("link2", "k1", (Rz(joint(p2)), Rx(-pi / 2), Rz(joint(p3)))),
        Frame("com2", "link2", (tx(c2 * g.l2),)),
        Frame("k2", "link2", (tx(g.l2), *_virtual_joint(6))),
        Frame("link3", "k2", (Rz(joint(p4)),)),
        Frame("com3", "link3", (tx(c3 * g.l3),)),
        Frame("k3", "link3", (tx(g.l3), *_virtual_joint(12))),
        Frame("platform", "k3", (Rz(joint(p5)), *_PLATFORM_ALIGNMENT[chain])),
    )
    virtual_types = ((JointType.PRISMATIC,) * 3 + (JointType.REVOLUTE,) * 3) * 3
    names = tuple(f"theta{chain + 1}{j + 1}_{k + 1}" for j in range(3) for k in range(6))
    names += tuple(f"phi{chain + 1}{k}" for k in (2, 3, 4, 5)) + (f"phi{chain + 1}1",)
    return Mechanism(
        coordinates=names,
        joint_types=virtual_types + (JointType.REVOLUTE,) * 5,
        frames=frames,
        bodies=(),
        gravity=(0.0, 0.0, -9.81),
        end_effector="platform",
        metadata={"device": "rcube", "chain": chain, "virtual": True},
    )


def stiffness_coordinates(q_chain: np.ndarray, theta: np.ndarray | None = None) -> np.ndarray:
    """The 23 coordinates of eq. 5.86 from chain angles ``(..., 3)`` and virtual ``(..., 18)``.

    Passive angles follow eq. 5.13-5.14: ``phi2 = -q1``, ``phi3 = q2``, ``phi4 = q3``,
    ``phi5 = -(q2 + q3)``.
    """
    q = np.asarray(q_chain, dtype=float)
    out = np.zeros(q.shape[:-1] + (N_STIFFNESS_COORDINATES,))
    if theta is not None:
        out[..., :N_VIRTUAL] = theta
    out[..., 18] = -q[..., 0]
    out[..., 19] = q[..., 1]
    out[..., 20] = q[..., 2]
    out[..., 21] = -(q[..., 1] + q[..., 2])
    out[..., ACTIVE_INDEX] = q[..., 0]
    return out
