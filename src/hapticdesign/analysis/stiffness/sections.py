"""Hollow circular tube cross-sections (seed 001 eq. 5.162-5.166, 5.229-5.230, 6.94-6.96)."""

from __future__ import annotations

from dataclasses import dataclass
from math import isfinite, pi

from hapticdesign.errors import UserError
from hapticdesign.analysis.stiffness.materials import PLY_THICKNESS, check_plies


def tube_area(D, d):
    """Cross-section area ``A`` of tubes of outer and inner diameters ``D``, ``d`` (eq. 5.165; floats or arrays)."""
    return pi * ((D / 2) ** 2 - (d / 2) ** 2)


def tube_second_moment(D, d):
    """``I_y = I_z`` of tubes (eq. 5.162-5.163; floats or arrays)."""
    return pi / 4 * ((D / 2) ** 4 - (d / 2) ** 4)


def tube_polar_moment(D, d):
    """``J`` of tubes (eq. 5.164; floats or arrays)."""
    return pi / 2 * ((D / 2) ** 4 - (d / 2) ** 4)


@dataclass(frozen=True)
class Tube:
    """Outer diameter ``D`` and inner diameter ``d`` (m), ``0 <= d < D``."""

    D: float
    d: float

    def __post_init__(self) -> None:
        if not isfinite(self.D) or self.D <= 0.0:
            raise UserError(f"outer diameter D must be positive, got {self.D!r}")
        if not isfinite(self.d) or self.d < 0.0:
            raise UserError(f"inner diameter d must be non-negative, got {self.d!r}")
        if self.d >= self.D:
            raise UserError(f"inner diameter d = {self.d} must be below the outer diameter D = {self.D}")

    @property
    def area(self) -> float:
        """Cross-section area ``A`` (eq. 5.165)."""
        return tube_area(self.D, self.d)

    @property
    def second_moment(self) -> float:
        """``I_y = I_z`` (eq. 5.162-5.163)."""
        return tube_second_moment(self.D, self.d)

    @property
    def polar_moment(self) -> float:
        """``J`` (eq. 5.164)."""
        return tube_polar_moment(self.D, self.d)

    def mass(self, length: float, density: float) -> float:
        """Tube mass ``rho pi l (R^2 - r^2)`` (eq. 5.230)."""
        return density * self.area * length


def tube_from_plies(d: float, plies: tuple[int, int, int, int], ply_thickness: float = PLY_THICKNESS) -> Tube:
    """A laminated tube on a mandrel of diameter ``d``: wall thickness ``t = ply_thickness * sum(plies)``.

    Eq. 6.94-6.96 print ``D = d + 2 t``; the diameters of Tables 7.7-7.8 satisfy ``D = d + t``
    (e.g. link 1: 25 plies, ``D - d = 3.75 mm``), so the tables' reading is used here.
    """
    counts = check_plies(plies)
    if not isfinite(ply_thickness) or ply_thickness <= 0.0:
        raise UserError(f"ply thickness must be positive, got {ply_thickness!r}")
    return Tube(D=d + ply_thickness * sum(counts), d=d)
