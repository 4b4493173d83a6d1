"""Objectives of the kinematic synthesis (seed 001 §6.4, eq. 6.82-6.84).

``O1 = tan q_max`` (eq. 6.82), ``O2 = det M_C`` with two active links fully folded and the third
at home (eq. 6.83), ``O3 = 1 / det K_CA`` at the fully extended pose (eq. 6.84). ``M_C`` and
``K_C`` are those of :mod:`hapticdesign.analysis.rcube` for links of the post-evaluation tube
(D = 20 mm, d = 10 mm, rho = 2000 kg/m^3, §7.1), so that only the link lengths and the active
range change between designs (§6.2: "material properties and cross-section dimensions are assumed
to be constant"). The seed does not state the tube's material; it is the explicit setting
:attr:`EvaluationLinks.material`: M55J quasi-isotropic by default, structural steel
(E = 200 GPa, nu = 0.3) being the one with which Table 7.3's ``S_f`` column reproduces.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.analysis.rcube.design import RCubeDesign, uniform_design
from hapticdesign.analysis.rcube.dynamics import cartesian_mass_matrix
from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness
from hapticdesign.analysis.stiffness.materials import STRUCTURAL_STEEL, LinkModuli, laminate
from hapticdesign.errors import UserError
from hapticdesign.optimization.rcube.constraints import CubeWorkspace, link1_length

OBJECTIVE_NAMES = ("O1", "O2", "O3")

EVALUATION_MATERIALS: dict[str, LinkModuli] = {
    "M55J quasi-isotropic": laminate((1, 1, 1, 1)),
    "structural steel": STRUCTURAL_STEEL,
}
"""Materials of the post-evaluation tube by name: M55J plies at 0, 90, -45, 45 degrees (eq. 5.179-5.181),
or structural steel (E = 200 GPa, nu = 0.3)."""

SEED_EVALUATION_MATERIAL = "structural steel"
"""The material with which Table 7.3's ``S_f`` reproduces (all 40 rows, see docs/optimization.md)."""


@dataclass(frozen=True)
class EvaluationLinks:
    """The tube every link gets while the lengths are optimized (§7.1): ``D``, ``d`` (m), ``density``
    (kg/m^3) and ``material`` (a key of :data:`EVALUATION_MATERIALS`)."""

    D: float = 0.020
    d: float = 0.010
    density: float = 2000.0
    passive_eliminated: bool = True
    """``K_C`` with passive joints eliminated (eq. 5.121-5.123); False: ``K_C*`` (eq. 6.60-6.61)."""
    material: str = "M55J quasi-isotropic"

    def __post_init__(self) -> None:
        if self.material not in EVALUATION_MATERIALS:
            raise UserError(f"unknown evaluation material {self.material!r}; choose one of {', '.join(EVALUATION_MATERIALS)}")

    @property
    def moduli(self) -> LinkModuli:
        return EVALUATION_MATERIALS[self.material]

    def settings(self) -> dict[str, float | bool | str]:
        """The evaluation tube as reported beside Table 7.3 (SI units)."""
        return {"material": self.material, "D": self.D, "d": self.d, "density": self.density,
                "passive_eliminated": self.passive_eliminated}

    def design(self, geometry: RCubeGeometry) -> RCubeDesign:
        return uniform_design(geometry, self.D, self.d, self.moduli, density=self.density)


def geometry_of(x, workspace: CubeWorkspace = CubeWorkspace()) -> RCubeGeometry:
    """The geometry of a design vector ``(q_max, l2, l3)``: ``l1`` from Constraint 1, ``S = l1`` (eq. 6.39)."""
    q, l2, l3 = (float(v) for v in x)
    return RCubeGeometry(float(link1_length(q, workspace)), l2, l3)


def folded_pose(geometry: RCubeGeometry, half: float) -> np.ndarray:
    """Two active links fully folded (``q_i1 = -q_max``), the first at home: the pose of ``O2`` (§6.4)."""
    return geometry.home + np.array([0.0, -half, -half])


def extended_pose(geometry: RCubeGeometry, half: float) -> np.ndarray:
    """All active links at ``q_max``: the fully extended pose of ``O3`` and eq. 6.91."""
    return geometry.home + half


def o1(q_max) -> np.ndarray:
    """``O1 = tan q_max`` (eq. 6.82): the inverse of the manipulability ``cot q_max`` (eq. 6.26)."""
    return np.tan(np.asarray(q_max, dtype=float))


def o2(design: RCubeDesign, half: float) -> float:
    """``O2 = det M_C`` (eq. 6.83, 5.227) at :func:`folded_pose`."""
    return float(np.linalg.det(cartesian_mass_matrix(design, folded_pose(design.geometry, half))))


def o3(design: RCubeDesign, half: float, passive_eliminated: bool = True) -> float:
    """``O3 = 1 / det K_CA`` (eq. 6.84, 6.74) at :func:`extended_pose`."""
    K = cartesian_stiffness(design, extended_pose(design.geometry, half), passive=passive_eliminated)
    return float(1.0 / np.linalg.det(K[:3, :3]))


def objectives(x, workspace: CubeWorkspace = CubeWorkspace(), links: EvaluationLinks = EvaluationLinks()) -> np.ndarray:
    """``(O1, O2, O3)`` of one feasible design vector."""
    design = links.design(geometry_of(x, workspace))
    return np.array([float(o1(x[0])), o2(design, workspace.half), o3(design, workspace.half, links.passive_eliminated)])
