"""Link materials: isotropic, unidirectional lamina and laminate averages (seed 001 §4.2.4, §5.2.4).

A material gives the moduli the link stiffness matrix uses (eq. 4.59): ``E_x`` (axial, and the
bending modulus of a tube), ``E_y = E_z`` (hoop; eq. 4.59 prints it in the bending terms, see
:func:`hapticdesign.analysis.stiffness.link.bending_modulus`) and ``G_xy`` (torsion).
"""

from __future__ import annotations

from dataclasses import dataclass
from math import cos, isfinite, radians, sin

from hapticdesign.errors import UserError


def _positive(name: str, value: float) -> float:
    if not isfinite(value) or value <= 0.0:
        raise UserError(f"{name} must be positive, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class LinkModuli:
    """Moduli (Pa) entering eq. 4.59: axial ``E_x``, hoop ``E_y`` (= ``E_z``), shear ``G_xy``; and the density
    (kg/m^3) where known, which a body that follows a link needs (docs/device-files.md)."""

    E_x: float
    E_y: float
    G_xy: float
    density: float | None = None


def isotropic(E: float, G: float | None = None, nu: float = 0.3, density: float | None = None) -> LinkModuli:
    """An isotropic material (eq. 4.58): ``G = E / (2 (1 + nu))`` unless given; Poisson's ratio of a
    stable isotropic solid lies in (-1, 0.5) (positive bulk and shear moduli); ``density`` in kg/m^3."""
    E = _positive("E", E)
    if G is None and not -1.0 < nu < 0.5:
        raise UserError(f"Poisson's ratio nu must lie in (-1, 0.5) for an isotropic material, got {nu:g}")
    G = E / (2.0 * (1.0 + nu)) if G is None else _positive("G", G)
    return LinkModuli(E, E, G, None if density is None else _positive("density", density))


STRUCTURAL_STEEL = isotropic(200e9, nu=0.3, density=7850.0)
"""Structural steel as in the seed's verification cases (§5.2.1, §5.2.5): E = 200 GPa, nu = 0.3; density
7850 kg/m^3 (EN 1991-1-1 Table A.4: 77.0-78.5 kN/m^3)."""

ALUMINIUM_6061 = isotropic(68.9e9, G=26.0e9, density=2700.0)
"""Aluminium 6061-T6: E = 68.9 GPa, G = 26 GPa, density 2700 kg/m^3 (ASM Aerospace Specification Metals data
sheet: 2.70 g/cc)."""

LAMINATE_DENSITY = 1790.0
"""kg/m^3 of a laminate link without a stated density: the M55J/epoxy of seed 001, whose final design's 77.7 g of
links (Table 7.9) with the tubes of Table 7.8 imply 1.79 g/cm^3."""

MATERIALS = {"steel": STRUCTURAL_STEEL, "aluminium_6061": ALUMINIUM_6061}
"""Named materials a device file's links may use (docs/device-files.md)."""


@dataclass(frozen=True)
class Lamina:
    """Unidirectional lamina: ``E1`` along the fibres, ``E2`` across, ``G12``, ``nu12`` (Pa)."""

    E1: float
    E2: float
    G12: float
    nu12: float

    def __post_init__(self) -> None:
        for name in ("E1", "E2", "G12"):
            _positive(name, getattr(self, name))
        if not isfinite(self.nu12) or not 0.0 <= self.nu12 < 1.0:
            raise UserError(f"nu12 must be a finite Poisson ratio, got {self.nu12!r}")


M55J = Lamina(E1=300e9, E2=12e9, G12=5e9, nu12=0.3)
"""Toray M55J / epoxy lamina as used by the seed (§5.2.4, Appendix A)."""

PLY_THICKNESS = 0.15e-3
"""Thickness of one ply (m), seed §6.6."""

PLY_ANGLES = (0.0, 90.0, -45.0, 45.0)
"""Orientations of the ply counts ``(a, b, c, d)`` of eq. 5.179-5.181 (degrees)."""


def micromechanics(E_f: float, E_m: float, G_f: float, G_m: float, nu_f: float, nu_m: float, V_f: float) -> Lamina:
    """Rule of mixtures (eq. 4.60-4.66): a lamina from fibre and matrix properties.

    ``E1 = E_f V_f + E_m V_m``; ``E2 = E_f E_m / (V_m E_f + V_f E_m)``;
    ``G12 = G_m / (V_m + V_f G_m / G_f)``; ``nu12 = nu_f V_f + nu_m V_m`` (the standard rule of
    mixtures for the major Poisson ratio, which eq. 4.62 defines as ``-eps2 / eps1``).
    """
    if not isfinite(V_f) or not 0.0 < V_f < 1.0:
        raise UserError(f"fibre volume fraction must be in (0, 1), got {V_f!r}")
    E_f, E_m, G_f, G_m = (_positive(n, v) for n, v in (("E_f", E_f), ("E_m", E_m), ("G_f", G_f), ("G_m", G_m)))
    V_m = 1.0 - V_f
    return Lamina(
        E1=E_f * V_f + E_m * V_m,
        E2=E_f * E_m / (V_m * E_f + V_f * E_m),
        G12=G_m / (V_m + V_f * G_m / G_f),
        nu12=nu_f * V_f + nu_m * V_m,
    )


def off_axis(lamina: Lamina, xi_deg: float) -> LinkModuli:
    """Moduli of a lamina rotated by ``xi`` (eq. 4.67-4.69; eq. 5.167-5.178 at 0, 90, +-45 deg)."""
    c, s = cos(radians(xi_deg)), sin(radians(xi_deg))
    E1, E2, G12, nu = lamina.E1, lamina.E2, lamina.G12, lamina.nu12
    mixed = (1.0 / G12 - 2.0 * nu / E1) * s * s * c * c
    inv_Ex = c**4 / E1 + mixed + s**4 / E2
    inv_Ey = s**4 / E1 + mixed + c**4 / E2
    inv_G = 2.0 * (2.0 / E1 + 2.0 / E2 + 4.0 * nu / E1 - 1.0 / G12) * s * s * c * c + (s**4 + c**4) / G12
    return LinkModuli(1.0 / inv_Ex, 1.0 / inv_Ey, 1.0 / inv_G)


def check_plies(plies: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
    """Validate ply counts ``(a, b, c, d)`` at 0, 90, -45 and 45 degrees."""
    if len(plies) != 4:
        raise UserError(f"expected four ply counts (0, 90, -45, 45 degrees), got {plies!r}")
    counts = []
    for n in plies:
        if float(n) != int(n) or int(n) < 0:
            raise UserError(f"ply counts must be non-negative integers, got {plies!r}")
        counts.append(int(n))
    if sum(counts) == 0:
        raise UserError("a laminate needs at least one ply")
    return tuple(counts)


def printed_45_shear(lamina: Lamina) -> float:
    """``G_xy`` of a +-45 degree ply exactly as eq. 5.175/5.178 print it (Pa).

    ``1/G = 2 (2/(4 E1) + 2/(4 E2) + 4 nu12/(4 E1) - 1/(4 G12)) + 1/(4 G12)``: eq. 4.69 with
    ``sin^2 cos^2 = 1/4`` put inside the bracket and ``sin^4 + cos^4 = 1/2`` written as ``1/4``
    (25.9 GPa for M55J instead of eq. 4.69's 11.3 GPa). The seed's final-design ``K_C`` (eq. 7.7)
    reproduces only with this value (see docs/rcube.md).
    """
    E1, E2, G12, nu = lamina.E1, lamina.E2, lamina.G12, lamina.nu12
    return 1.0 / (2.0 * (2.0 / (4 * E1) + 2.0 / (4 * E2) + 4.0 * nu / (4 * E1) - 1.0 / (4 * G12)) + 1.0 / (4 * G12))


SHEAR_RULES = ("eq. 4.69", "eq. 5.175")
"""How a +-45 degree ply's ``G_xy`` is computed: eq. 4.69 (default) or as eq. 5.175 prints it."""


def laminate(plies: tuple[int, int, int, int], lamina: Lamina = M55J, shear: str = "eq. 4.69") -> LinkModuli:
    """Ply-count weighted average of the oriented moduli (eq. 5.179-5.181).

    ``shear="eq. 5.175"`` takes the +-45 degree plies' ``G_xy`` as printed (:func:`printed_45_shear`).
    """
    if shear not in SHEAR_RULES:
        raise UserError(f"unknown shear rule {shear!r}; choose one of {', '.join(SHEAR_RULES)}")
    counts = check_plies(plies)
    total = float(sum(counts))
    parts = [off_axis(lamina, angle) for angle in PLY_ANGLES]
    if shear == "eq. 5.175":
        G45 = printed_45_shear(lamina)
        parts = [LinkModuli(p.E_x, p.E_y, G45) if abs(a) == 45.0 else p for p, a in zip(parts, PLY_ANGLES)]
    return LinkModuli(
        E_x=sum(n * p.E_x for n, p in zip(counts, parts)) / total,
        E_y=sum(n * p.E_y for n, p in zip(counts, parts)) / total,
        G_xy=sum(n * p.G_xy for n, p in zip(counts, parts)) / total,
    )
