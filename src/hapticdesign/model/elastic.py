"""What deforms in a device: elastic links and joint springs, for the virtual joint method (seed 001 §5.2).

A link is a straight beam from the origin of frame ``start`` to the origin of frame ``end``, fixed
to both (no joint between them). The virtual joint method lumps its compliance into a six-coordinate
virtual joint at ``end`` (eq. 5.75-5.81); the link is described by its rigidities, axial ``E A``,
bending ``E I`` and torsional ``G J`` of an axisymmetric section (eq. 4.58-4.59, 5.162-5.165).
A joint spring is the finite stiffness of an actuated joint (drive and transmission; N m/rad or N/m);
actuated joints without one are rigid, passive joints are free.

This module holds only *what the device is*; the stiffness engine is
:mod:`hapticdesign.analysis.stiffness.device`.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import isfinite

from hapticdesign.errors import UserError


def _positive(what: str, value: float) -> float:
    value = float(value)
    if not isfinite(value) or value <= 0.0:
        raise UserError(f"{what} must be positive and finite, got {value!r}")
    return value


@dataclass(frozen=True)
class ElasticLink:
    """A link from ``start`` to ``end`` with rigidities ``axial = E A`` (N), ``bending = E I`` and
    ``torsion = G J`` (N m^2)."""

    name: str
    start: str
    end: str
    axial: float
    bending: float
    torsion: float

    def __post_init__(self) -> None:
        for what in ("axial", "bending", "torsion"):
            _positive(f"link {self.name}: {what} rigidity", getattr(self, what))


@dataclass(frozen=True)
class Elasticity:
    """Elastic links and joint springs ``(actuated coordinate name, stiffness)`` of a device."""

    links: tuple[ElasticLink, ...] = ()
    joints: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        ends = [link.end for link in self.links]
        for i, link in enumerate(self.links):
            if any(other.name == link.name for other in self.links[:i]):
                raise UserError(f"link name {link.name!r} is used twice")
            if ends.count(link.end) > 1:
                raise UserError(f"links {', '.join(l.name for l in self.links if l.end == link.end)} end at the "
                                f"same frame {link.end!r} (give each link its own end frame)")
        for name, stiffness in self.joints:
            _positive(f"joint {name} stiffness", stiffness)
