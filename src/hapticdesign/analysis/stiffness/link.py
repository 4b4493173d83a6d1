"""Stiffness matrix of one link lumped on its six-coordinate virtual joint (seed 001 eq. 4.58-4.59).

The virtual joint sits at the link's end, its local x along the link (eq. 5.77-5.79); coordinates
``(psi_1, psi_2, psi_3, phi_1, phi_2, phi_3)`` are the translations and rotations of eq. 5.76.
The matrix is the end stiffness of a cantilever: axial ``E_x A / L``, bending
``12 E I / L^3`` with the ``-+6 E I / L^2`` couplings and ``4 E I / L``, torsion ``G J / L``.

A tube bends with its laminate's axial modulus ``E = E_x`` (the fibres along the link carry the
bending stresses) and twists with ``G_xy``. Eq. 4.59 prints the hoop modulus ``E_y = E_z`` in the
bending terms, a slip that the seed's own final-design ``K_C`` (eq. 7.7) carries: ``bending="eq. 4.59"``
keeps that reading for reproducing the seed only.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import isfinite

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.analysis.stiffness.materials import LinkModuli
from hapticdesign.analysis.stiffness.sections import Tube, tube_area, tube_polar_moment, tube_second_moment


BENDING_RULES = ("E_x", "eq. 4.59")
"""Bending modulus of a link: the axial ``E_x`` (physical, default) or ``E_y`` as eq. 4.59 prints it."""


def bending_modulus(moduli: LinkModuli, bending: str = "E_x") -> float:
    """The modulus of the bending terms: ``E_x`` (beam theory) or ``E_y`` (eq. 4.59 as printed)."""
    if bending not in BENDING_RULES:
        raise UserError(f"unknown bending rule {bending!r}; choose one of {', '.join(BENDING_RULES)}")
    return moduli.E_x if bending == "E_x" else moduli.E_y


def beam_stiffness(axial: float, bending: float, torsion: float, length: float) -> np.ndarray:
    """6 x 6 end stiffness of a straight cantilever with an axisymmetric section (eq. 4.58-4.59).

    ``axial = E A`` (N), ``bending = E I`` and ``torsion = G J`` (N m^2): ``E A / L`` along the link,
    ``12 E I / L^3`` with the ``-+6 E I / L^2`` couplings and ``4 E I / L`` in bending, ``G J / L``
    in torsion. Coordinates ``(psi_1, psi_2, psi_3, phi_1, phi_2, phi_3)`` of eq. 5.76, x along the
    link; with ``I_y = I_z`` the matrix does not change when the section turns about x. The arguments may be
    arrays of many links (then ``(..., 6, 6)``).
    """
    length = np.asarray(length, dtype=float)
    if not np.all(np.isfinite(length) & (length > 0.0)):
        raise UserError(f"link length must be positive, got {np.ravel(length).tolist()}")
    L = length
    axial, bending, torsion = (np.asarray(v, dtype=float) for v in (axial, bending, torsion))
    K = np.zeros(np.broadcast_shapes(L.shape, axial.shape, bending.shape, torsion.shape) + (6, 6))
    K[..., 0, 0] = axial / L
    K[..., 1, 1] = K[..., 2, 2] = 12.0 * bending / L**3
    K[..., 1, 5] = K[..., 5, 1] = -6.0 * bending / L**2
    K[..., 2, 4] = K[..., 4, 2] = 6.0 * bending / L**2
    K[..., 3, 3] = torsion / L
    K[..., 4, 4] = K[..., 5, 5] = 4.0 * bending / L
    return K


def rigidities(moduli: LinkModuli, section: Tube, bending: str = "E_x") -> tuple[float, float, float]:
    """``(E_x A, E_b I, G_xy J)`` of a tube; ``E_b`` from :func:`bending_modulus` (eq. 4.59, 5.162-5.165)."""
    return tube_rigidities(moduli, section.D, section.d, bending)


def tube_rigidities(moduli: LinkModuli, D, d, bending: str = "E_x") -> tuple:
    """:func:`rigidities` of tubes of diameters ``D``, ``d`` (floats or arrays of many designs' sections)."""
    return (moduli.E_x * tube_area(D, d), bending_modulus(moduli, bending) * tube_second_moment(D, d),
            moduli.G_xy * tube_polar_moment(D, d))


def link_stiffness(moduli: LinkModuli, section: Tube, length: float, bending: str = "E_x") -> np.ndarray:
    """6 x 6 virtual-joint stiffness of a straight link (eq. 4.59; eq. 4.58 when isotropic).

    The bending terms use :func:`bending_modulus` (``E_x`` unless ``bending="eq. 4.59"``).
    """
    return beam_stiffness(*rigidities(moduli, section, bending), length)


@dataclass(frozen=True)
class LinkDesign:
    """Cross-section, material, density (kg/m^3) and bending rule of one link (its length comes
    from the geometry); ``bending="eq. 4.59"`` only for reproducing the seed."""

    section: Tube
    moduli: LinkModuli
    density: float = 1790.0
    bending: str = "E_x"

    def __post_init__(self) -> None:
        if not isfinite(self.density) or self.density <= 0.0:
            raise UserError(f"density must be positive, got {self.density!r}")
        bending_modulus(self.moduli, self.bending)

    def stiffness(self, length: float) -> np.ndarray:
        return link_stiffness(self.moduli, self.section, length, self.bending)

    def compliance(self, length: float) -> np.ndarray:
        return np.linalg.inv(self.stiffness(length))
