"""Concrete fully linear, physically realizable designs (seed 000 §3.2.1, eq. 3.28-3.33).

The designs with LN = 0 form a linear subspace of the standard parameters; realizability and
the practical bounds are convex there (:mod:`.convex`). Each design is a random convex
combination of three extreme points reached with seeded random linear objectives, projected
exactly onto the subspace and checked in the seed's variables: bounds, realizability and
LN < 1e-12.
"""

from __future__ import annotations

from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from hapticdesign.analysis.linearity.bounds import BodyBounds, within_bounds
from hapticdesign.analysis.linearity.conditions import LinearConditions
from hapticdesign.analysis.linearity.convex import SCALE, body_constraints, solve
from hapticdesign.analysis.linearity.quadratic import LinearityForm
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.model.inertia import Realizability, pseudo_inertia, seed_from_standard

EXTREME_POINTS = 3
LN_TOLERANCE = 1e-12


@dataclass
class LinearDesignProblem:
    """The convex set {LN = 0, realizable, within bounds} in scaled standard parameters."""

    device: Device
    bounds: dict[str, BodyBounds]
    kind: Realizability
    x: cp.Variable
    objective: cp.Parameter
    problem: cp.Problem

    @property
    def scale(self) -> np.ndarray:
        return np.tile(SCALE, len(self.device.body_names))


def linear_design_problem(
    device: Device,
    conditions: LinearConditions,
    bounds: dict[str, BodyBounds],
    kind: Realizability = Realizability.RIGID_BODY,
    delta: float = 1e-7,
) -> LinearDesignProblem:
    bodies = device.body_names
    scale = np.tile(SCALE, len(bodies))
    x = cp.Variable(len(scale))
    pi = cp.multiply(scale, x)
    fixed = device.standard_parameters()
    constraints = [(conditions.rows * scale) @ x == 0]
    for k, body in enumerate(bodies):
        p = pi[10 * k : 10 * k + 10]
        if body in bounds:
            constraints += body_constraints(p, bounds[body], kind, delta)
        else:
            constraints.append(x[10 * k : 10 * k + 10] == fixed[10 * k : 10 * k + 10] / SCALE)
    objective = cp.Parameter(len(scale))
    problem = cp.Problem(cp.Minimize(objective @ x), constraints)
    return LinearDesignProblem(device, bounds, kind, x, objective, problem)


def realizable(seed: np.ndarray, standard: np.ndarray, kind: Realizability) -> bool:
    """Every body with mass is realizable (pseudo-inertia or mass-centre inertia positive definite)."""
    for s, p in zip(seed, standard):
        if s[0] <= 0:
            return False
        if kind is Realizability.RIGID_BODY:
            if np.linalg.eigvalsh(pseudo_inertia(p)).min() <= 0:
                return False
        else:
            ic = np.array([[s[4], -s[7], -s[8]], [-s[7], s[5], -s[9]], [-s[8], -s[9], s[6]]])
            if np.linalg.eigvalsh(ic).min() <= 0:
                return False
    return True


def find_linear_designs(
    device: Device,
    form: LinearityForm,
    conditions: LinearConditions,
    bounds: dict[str, BodyBounds],
    count: int,
    seed: int,
    kind: Realizability = Realizability.RIGID_BODY,
) -> np.ndarray:
    """``count`` fully linear realizable designs in the seed's variables, (count, bodies * 10)."""
    if count < 1:
        raise UserError("the number of fully linear designs must be at least 1")
    rng = np.random.default_rng(seed)
    prob = linear_design_problem(device, conditions, bounds, kind)
    bodies = device.body_names
    designs: list[np.ndarray] = []
    attempts = 0
    while len(designs) < count:
        attempts += 1
        if attempts > 5 * count + 10:
            raise UserError("could not find enough realizable linear designs within the bounds")
        points = []
        for _ in range(EXTREME_POINTS):
            prob.objective.value = rng.normal(size=prob.x.size)
            solve(prob.problem)
            if prob.problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
                raise UserError(f"no realizable fully linear design within the bounds (solver: {prob.problem.status})")
            points.append(prob.x.value * prob.scale)
        pi = conditions.project(rng.dirichlet(np.ones(EXTREME_POINTS)) @ np.array(points))
        for k, body in enumerate(bodies):
            if body not in bounds:
                pi[10 * k : 10 * k + 10] = device.standard_parameters()[10 * k : 10 * k + 10]
        standard = pi.reshape(len(bodies), 10)
        seed_values = seed_from_standard(standard)
        if not (realizable(seed_values, standard, kind) and within_bounds(seed_values, bodies, bounds)):
            continue
        if form.ln(pi) >= LN_TOLERANCE:
            continue
        designs.append(seed_values.ravel())
    return np.array(designs)
