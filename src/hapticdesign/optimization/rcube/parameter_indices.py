"""Indices that are closed forms of a device's parameters (no pose is reached): the R-CUBE's synthesis indices of
seed 001 §6.1.3 and §6.4, so that its kinematic synthesis runs as a study file (docs/optimization.md,
docs/indices.md).

These indices are specific to the modified R-CUBE: they read the device file's ``l1``, ``l2``, ``l3`` and ``S``
(``S = l1``, eq. 6.39, is required) and evaluate the synthesis's own closed forms
(:mod:`~hapticdesign.optimization.rcube.constraints`, :mod:`~hapticdesign.optimization.rcube.objectives`; ``M_C`` and ``K_C`` of
the device's ``l1, l2, l3`` with the evaluation tube) at ``q_max = asin(h / l1)`` (Constraint 1, eq. 6.24, read backward: the active joint travel that covers the cube of half
edge ``h``). They are not computed from the device file's frames and loops: the passive-joint conditions of
Constraints 3-7 at points of a virtual cube that the handle need not reach, and the hand-side condition of
Constraint 8, have no counterpart among the pose indices. Options: ``side`` (the workspace cube's edge, m, 0.120) and
``virtual_side`` (the virtual cube's edge, m, 0.130); the objectives' links are the synthesis's evaluation tube
(:class:`~hapticdesign.optimization.rcube.objectives.EvaluationLinks`).

They are registered in the one registry of design indices (:mod:`hapticdesign.analysis.metrics.indices`) as any
package's own indices are: this module is named by the ``hapticdesign.indices`` entry point of pyproject.toml, and
the registry imports it the first time a study asks for an index it does not hold.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from hapticdesign.analysis.metrics.indices import ParameterStates, index
from hapticdesign.errors import UserError
from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.optimization.rcube.constraints import ERGONOMIC_POINTS, PASSIVE_POINTS, CubeWorkspace, constraint_values
from hapticdesign.optimization.rcube.objectives import EvaluationLinks, o1, o2, o3

POINTS = (*PASSIVE_POINTS, *ERGONOMIC_POINTS)
"""The critical points of Constraints 3-8, in the column order of :func:`constraint_values`."""
SIDE, VIRTUAL_SIDE = 0.120, 0.130
"""The workspace cube's and the virtual cube's edges (m), the options' defaults."""
PARAMETERS = ("parameters",)


def _workspace(side: object, virtual_side: object) -> CubeWorkspace:
    for name, value in (("side", side), ("virtual_side", virtual_side)):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise UserError(f"R-CUBE index option {name} is a length in m, got {value!r}")
    return CubeWorkspace(float(side), float(virtual_side))


def design_vectors(params, workspace: CubeWorkspace) -> np.ndarray:
    """``(q_max, l2, l3)`` per design (n, 3) from the parameters, ``q_max = asin(h / l1)`` (eq. 6.24 read backward);
    a design with ``S != l1`` is refused (the closed forms hold for ``S = l1``, eq. 6.39)."""
    missing = [n for n in ("l1", "l2", "l3", "S") if n not in params]
    if missing:
        raise UserError(f"the R-CUBE indices need device parameters l1, l2, l3 and S; {missing[0]} is missing")
    l1 = np.asarray(params["l1"], dtype=float)
    if not np.allclose(params["S"], l1, rtol=1e-12, atol=0.0, equal_nan=True):
        raise UserError("the R-CUBE indices hold for S = l1 (eq. 6.39): set S from l1 in the study's parameters")
    with np.errstate(invalid="ignore"):
        q = np.arcsin(workspace.half / l1)
    return np.column_stack([q, np.asarray(params["l2"], dtype=float), np.asarray(params["l3"], dtype=float)])


@index(unit="1", formula="cos^2 q_i3 - 1 at C2, C3, C5, B3, B5; sin(q_i2 + q_i3) at C1, B1 (feasible: <= 0)",
       source="seed 001 eq. 6.45-6.49, 6.52", needs=PARAMETERS)
def rcube_constraint(design: ParameterStates, side: float = SIDE, virtual_side: float = VIRTUAL_SIDE,
                     point: str = "C2") -> np.ndarray:
    if point not in POINTS:
        raise UserError(f"index rcube_constraint: point is one of {', '.join(POINTS)}, got {point!r}")
    workspace = _workspace(side, virtual_side)
    key = ("constraints", workspace)
    if key not in design.cache:
        design.cache[key] = constraint_values(design_vectors(design.params, workspace), workspace)
    return design.cache[key][:, POINTS.index(point)]


@index(unit="1", formula="tan q_max, q_max = asin(h / l1)", source="seed 001 eq. 6.82, 6.24", needs=PARAMETERS)
def rcube_o1(design: ParameterStates, side: float = SIDE, virtual_side: float = VIRTUAL_SIDE) -> np.ndarray:
    return o1(design_vectors(design.params, _workspace(side, virtual_side))[:, 0])


def _per_design(design: ParameterStates, side, virtual_side, objective: Callable) -> np.ndarray:
    workspace = _workspace(side, virtual_side)
    links = EvaluationLinks()
    out = []
    for l1, (_, l2, l3) in zip(np.asarray(design.params["l1"], dtype=float), design_vectors(design.params, workspace)):
        key = ("design", float(l1), float(l2), float(l3))
        if key not in design.cache:
            design.cache[key] = links.design(RCubeGeometry(float(l1), float(l2), float(l3)))
        out.append(objective(design.cache[key], workspace.half, links))
    return np.array(out)


@index(unit="kg^3", formula="det M_C with two active links folded (q_i1 = -q_max), the third at home",
       source="seed 001 eq. 6.83, 5.227", needs=PARAMETERS)
def rcube_o2(design: ParameterStates, side: float = SIDE, virtual_side: float = VIRTUAL_SIDE) -> np.ndarray:
    return _per_design(design, side, virtual_side, lambda built, half, links: o2(built, half))


@index(unit="m^3/N^3", formula="1 / det K_CA at the fully extended pose (q_i1 = q_max)", source="seed 001 eq. 6.84, 6.74",
       needs=PARAMETERS)
def rcube_o3(design: ParameterStates, side: float = SIDE, virtual_side: float = VIRTUAL_SIDE) -> np.ndarray:
    return _per_design(design, side, virtual_side, lambda built, half, links: o3(built, half, links.passive_eliminated))
