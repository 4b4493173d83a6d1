"""Composite ply counts of the three links (seed 001 §6.6, §7.4, eq. 6.91-6.96, Tables 7.6-7.9).

Each link has integer counts ``(n_0, n_90, n_45)`` with ``n_45`` plies at +45 and as many at -45
degrees (at most ``MAX_PLIES`` each, §6.6). The wall thickness is ``0.15 mm`` per ply and the inner
diameter follows from the cross-section ratio ``d / D``; with the tables' ``D = d + t`` (see
:func:`hapticdesign.analysis.stiffness.sections.tube_from_plies`) that is
``d = ratio t / (1 - ratio)``. Objectives: ``CF1 = ||Delta kappa_1-3||`` and
``CF2 = ||Delta kappa_4-6||`` of ``Delta kappa = (K_C1*)^-1 F`` (eq. 6.91-6.93) for 20 N along
chain 1's motion axis at the fully extended pose, and the number of plies. The tubes bend with the
laminate's axial modulus ``E_x``; ``bending="eq. 4.59"`` takes the hoop modulus as eq. 4.59 prints
it, for comparisons with the seed's Table 7.6 only.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pymoo.core.problem import Problem

from hapticdesign.errors import UserError
from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.analysis.rcube.design import FINAL_DENSITY, RCubeDesign
from hapticdesign.analysis.rcube.kinematics import inverse_kinematics
from hapticdesign.analysis.rcube.stiffness import chain_jacobians
from hapticdesign.analysis.stiffness import vjm
from hapticdesign.analysis.stiffness.link import LinkDesign
from hapticdesign.analysis.stiffness.materials import PLY_THICKNESS, Lamina, M55J, laminate
from hapticdesign.analysis.stiffness.sections import Tube
from hapticdesign.optimization.pymoo_run import NSGA_II, AlgorithmSpec, RowObjective, run

MAX_PLIES = 10
DESIGN_FORCE = 20.0
"""N, four times the device's continuous force (§6.6)."""


def link_plies(counts) -> tuple[int, int, int, int]:
    """``(n_0, n_90, n_45)`` to the ``(0, 90, -45, 45)`` counts of eq. 5.179-5.181."""
    n0, n90, n45 = (int(v) for v in counts)
    return (n0, n90, n45, n45)


def ply_tube(counts, ratio: float, ply_thickness: float = PLY_THICKNESS) -> Tube:
    """Tube of a link with ply counts ``(n_0, n_90, n_45)``: ``t = ply_thickness * (n_0 + n_90 + 2 n_45)``,
    ``D = t / (1 - ratio)``, ``d = ratio D`` (eq. 6.94-6.96 as Tables 7.7-7.8 apply them)."""
    if not 0.0 <= ratio < 1.0:
        raise UserError(f"the diameter ratio d/D must lie in [0, 1), got {ratio!r}")
    t = ply_thickness * sum(link_plies(counts)[k] for k in range(4))
    if t <= 0.0:
        raise UserError("every link needs at least one ply")
    D = t / (1.0 - ratio)
    return Tube(D, ratio * D)


def ply_design(geometry: RCubeGeometry, counts, ratio: float, lamina: Lamina = M55J,
               density: float = FINAL_DENSITY, bending: str = "E_x") -> RCubeDesign:
    """An R-CUBE design from ply counts ``(3, 3)`` (rows: links 1-3; ``n_0, n_90, n_45``)."""
    rows = np.asarray(counts).reshape(3, 3)
    links = tuple(LinkDesign(ply_tube(row, ratio), laminate(link_plies(row), lamina), density, bending) for row in rows)
    return RCubeDesign(geometry, links)


class PlyEvaluator:
    """Deflections under the design force for many ply designs of one geometry.

    The virtual-joint Jacobian of chain 1 at the fully extended pose does not depend on the
    sections, so it is computed once; each design only rebuilds ``K_theta^-1`` (eq. 5.105).
    """

    def __init__(self, geometry: RCubeGeometry, ratio: float, half: float = 0.060, force: float = DESIGN_FORCE,
                 lamina: Lamina = M55J, bending: str = "E_x"):
        self.geometry, self.ratio, self.lamina, self.bending = geometry, ratio, lamina, bending
        position = geometry.home + half
        q = inverse_kinematics(geometry, position)
        reference = ply_design(geometry, np.ones((3, 3), dtype=int), ratio, lamina, bending=bending)
        self.J_theta = chain_jacobians(reference, 0, q[0]).theta
        self.wrench = np.array([force, 0.0, 0.0, 0.0, 0.0, 0.0])

    def deflection(self, counts) -> np.ndarray:
        """``Delta kappa_1* = (K_C1*)^-1 F = J_theta K_theta^-1 J_theta^T F`` (eq. 6.91), 6-vector (m, rad)."""
        design = ply_design(self.geometry, counts, self.ratio, self.lamina, bending=self.bending)
        C = vjm.joint_compliance([link.stiffness(L) for link, L in zip(design.links, design.lengths)])
        return vjm.compliance(self.J_theta, C) @ self.wrench

    def objectives(self, counts) -> np.ndarray:
        """``(CF1 [m], CF2 [rad], number of plies)`` (eq. 6.92-6.93)."""
        k = self.deflection(counts)
        rows = np.asarray(counts).reshape(3, 3)
        return np.array([np.linalg.norm(k[:3]), np.linalg.norm(k[3:]), float(rows[:, :2].sum() + 2 * rows[:, 2].sum())])


class PlyProblem(Problem):
    """Ply counts of the three links, rows of 9 integers; a link without plies gets infinite
    objectives, the others are evaluated row by row (a loop, or the Dask ``client``'s workers)."""

    def __init__(self, evaluator: PlyEvaluator, max_plies: int, client=None):
        super().__init__(n_var=9, n_obj=3, xl=np.zeros(9), xu=np.full(9, max_plies), vtype=int)
        self.objective = RowObjective(evaluator.objectives, 9, 3, client)

    def _evaluate(self, X, out, *args, **kwargs):
        X = np.round(X).astype(int)
        ok = np.all(X.reshape(-1, 3, 3).sum(axis=2) > 0, axis=1)
        F = np.full((len(X), 3), np.inf)
        F[ok] = self.objective(X[ok])
        out["F"] = F


@dataclass(frozen=True)
class PlyResult:
    """Front of ply designs ``counts (n, 3, 3)``, objectives ``(n, 3)`` sorted by CF1, and the evaluator."""

    counts: np.ndarray
    F: np.ndarray
    evaluator: PlyEvaluator
    evaluations: int


def optimize_plies(geometry: RCubeGeometry, ratio: float, population: int = 100, generations: int = 100,
                   seed: int = 1, max_plies: int = MAX_PLIES, force: float = DESIGN_FORCE,
                   progress: Callable[[int], None] | None = None, client=None) -> PlyResult:
    """NSGA-II with integer variables (pymoo: integer sampling, rounded SBX and polynomial mutation);
    ``client``: a ``dask.distributed.Client`` whose workers evaluate the designs."""
    spec = AlgorithmSpec(NSGA_II, population, generations, integer=True)
    if max_plies < 1:
        raise UserError(f"the ply limit must be at least 1, got {max_plies}")
    evaluator = PlyEvaluator(geometry, ratio, force=force)
    problem = PlyProblem(evaluator, max_plies, client)
    result = run(problem, spec, seed, progress)
    keep = result.front()
    order = keep[np.argsort(result.F[keep, 0])]
    return PlyResult(result.X[order].reshape(-1, 3, 3), result.F[order], evaluator, problem.objective.evaluations)


def choose(F: np.ndarray, max_deflection: float) -> int:
    """The design with the fewest plies whose translational deflection ``CF1`` stays below
    ``max_deflection`` (m); ties go to the smaller deflection."""
    ok = np.flatnonzero(F[:, 0] <= max_deflection)
    if len(ok) == 0:
        raise UserError(f"no ply design deflects less than {max_deflection * 1e3:g} mm under the design force")
    return int(ok[np.lexsort((F[ok, 0], F[ok, 2]))[0]])
