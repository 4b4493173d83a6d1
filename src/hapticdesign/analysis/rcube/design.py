"""An R-CUBE design: geometry plus the tube, material and density of each link (seed 001 Table 7.8).

All three chains share the same three link designs (the seed's symmetric design, eq. 6.69).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from math import isfinite

from hapticdesign.errors import UserError
from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.analysis.stiffness.joints import RIGID, JointStiffness
from hapticdesign.analysis.stiffness.link import LinkDesign
from hapticdesign.analysis.stiffness.materials import LinkModuli, laminate, isotropic
from hapticdesign.analysis.stiffness.sections import Tube

FINAL_DENSITY = 1790.0
"""Laminate density (kg/m^3), a stated input: the value implied by Table 7.9's 77.7 g of links for
Table 7.8's tubes (the seed states no density)."""

JOINT_NAMES = ("phi_i1 (active)", "phi_i2", "phi_i3", "phi_i4", "phi_i5")
"""The five joints of a chain in the order of :attr:`RCubeDesign.joints` (eq. 5.5-5.14): the active
joint at the base, the passive pair at link 1's end, the passive joints at links 2 and 3's ends."""

RIGID_JOINTS = (RIGID,) * 5


@dataclass(frozen=True)
class RCubeDesign:
    """Geometry, three link designs, mass-centre fractions along the links, platform mass (kg), and
    the stiffness of the five joints of each chain (:data:`JOINT_NAMES`; rigid by default, as in the seed)."""

    geometry: RCubeGeometry
    links: tuple[LinkDesign, LinkDesign, LinkDesign]
    centres: tuple[float, float, float] = (0.5, 0.5, 0.5)
    platform_mass: float = 0.0
    gravity: tuple[float, float, float] = field(default=(0.0, 0.0, -9.81))
    joints: tuple[JointStiffness, ...] = RIGID_JOINTS

    def __post_init__(self) -> None:
        if len(self.links) != 3:
            raise UserError("an R-CUBE design needs exactly three link designs")
        if len(self.joints) != len(JOINT_NAMES) or not all(isinstance(j, JointStiffness) for j in self.joints):
            raise UserError(f"an R-CUBE design needs {len(JOINT_NAMES)} joint stiffnesses per chain")
        if not isfinite(self.platform_mass) or self.platform_mass < 0.0:
            raise UserError(f"platform mass must be non-negative, got {self.platform_mass!r}")

    @property
    def lengths(self) -> tuple[float, float, float]:
        g = self.geometry
        return (g.l1, g.l2, g.l3)

    def link_masses(self) -> tuple[float, float, float]:
        """Mass of each link of one chain (eq. 5.230)."""
        return tuple(link.section.mass(length, link.density) for link, length in zip(self.links, self.lengths))

    def total_link_mass(self) -> float:
        """Mass of the nine links (Table 7.9: 77.7 g for the final design)."""
        return 3.0 * sum(self.link_masses())

    @property
    def rigid_joints(self) -> bool:
        return all(j.rigid for j in self.joints)

    def with_geometry(self, geometry: RCubeGeometry) -> "RCubeDesign":
        return replace(self, geometry=geometry)

    def with_joints(self, joints: JointStiffness | tuple[JointStiffness, ...]) -> "RCubeDesign":
        """The same design with every joint (one :class:`JointStiffness`) or each joint given."""
        return replace(self, joints=(joints,) * len(JOINT_NAMES) if isinstance(joints, JointStiffness) else tuple(joints))


def final_design() -> RCubeDesign:
    """The seed's final design (Table 7.8): M55J tubes with the printed diameters and ply counts."""
    rows = [  # D, d (m), plies at 0, 90, -45, 45 degrees (Table 7.8 lists 0, 90, 45, -45; c = d here)
        (15e-3, 11.25e-3, (4, 7, 7, 7)),
        (12e-3, 9e-3, (2, 6, 6, 6)),
        (7.2e-3, 5.4e-3, (2, 6, 2, 2)),
    ]
    links = tuple(LinkDesign(Tube(D, d), laminate(plies), FINAL_DENSITY) for D, d, plies in rows)
    return RCubeDesign(RCubeGeometry(0.1117, 0.0741, 0.1218), links)


def seed_final_design() -> RCubeDesign:
    """Table 7.8's design as the seed's own computation of eq. 7.7 evidently built its links.

    Three departures from :func:`final_design`, all needed together to reproduce the printed
    ``K_C`` of eq. 7.7 (209110 N/m, 727 N m/rad, coupling 6495 N; within 0.7 %, see
    docs/rcube.md): the +-45 degree plies take the shear modulus as eq. 5.175 prints it, the
    tubes bend with the hoop modulus ``E_y`` as eq. 4.59 prints it (a tube bends with ``E_x``), and
    the section properties of eq. 5.162-5.165 are evaluated with Table 7.8's diameters in place of
    the radii, i.e. tubes of twice the printed diameters. The density is scaled by 1/4 so that the
    links keep the mass of :func:`final_design`. For reproduction only; :func:`final_design` is the
    physical one.
    """
    rows = [  # printed D, d (m) and plies at 0, 90, -45, 45 degrees (Table 7.8)
        (15e-3, 11.25e-3, (4, 7, 7, 7)),
        (12e-3, 9e-3, (2, 6, 6, 6)),
        (7.2e-3, 5.4e-3, (2, 6, 2, 2)),
    ]
    links = tuple(
        LinkDesign(Tube(2.0 * D, 2.0 * d), laminate(plies, shear="eq. 5.175"), FINAL_DENSITY / 4.0, bending="eq. 4.59")
        for D, d, plies in rows
    )
    return RCubeDesign(RCubeGeometry(0.1117, 0.0741, 0.1218), links)


def uniform_design(
    geometry: RCubeGeometry, D: float, d: float, moduli: LinkModuli | None = None, density: float = 2000.0
) -> RCubeDesign:
    """All links the same tube and material (Table 7.3's post-evaluation: D = 20 mm, d = 10 mm,
    rho = 2000 kg/m^3; the material is not stated, M55J quasi-isotropic ``(1, 1, 1, 1)`` by default)."""
    link = LinkDesign(Tube(D, d), moduli or laminate((1, 1, 1, 1)), density)
    return RCubeDesign(geometry, (link, link, link))


def steel_design(geometry: RCubeGeometry, D: float, d: float) -> RCubeDesign:
    """Structural-steel tubes (the seed's verification cases, §5.2.1 and §5.2.5)."""
    link = LinkDesign(Tube(D, d), isotropic(200e9, nu=0.3), 7850.0)
    return RCubeDesign(geometry, (link, link, link))
