"""Can a device be made fully linear? A decision with a checkable certificate (seed 000 §3.3, App. D).

The fully linear designs are ``pi = N z`` (N: basis of the null space of the LN form). Each
body's realizability matrix ``F_i(pi)`` (:func:`.convex.realizability_lmi` with no margin) is
linear and homogeneous in ``pi``, so a strictly realizable fully linear design exists exactly when
the LMI ``F(z) = blockdiag_i F_i(N z) > 0`` is strictly feasible. The bounds of eq. 3.40-3.42 do not
change the answer: they are a cone scaled by 10^-15 ... 10^15, and positive lower bounds only add
constraints. By the theorem of alternatives for linear matrix inequalities, ``F(z) > 0`` has no
solution iff there are ``Z_i >= 0`` with ``sum tr Z_i = 1`` and ``sum_i tr(Z_i F_i(N e_k)) = 0`` for
every basis direction k. We solve for the ``Z_i`` minimizing ``s = max_k |sum_i tr(Z_i F_i(N e_k))|``.
Whatever the solver's accuracy, the certificate gives a bound anyone can check: for every fully
linear design, ``min_i lambda_min(F_i(pi)) <= s * |z|_1``.
"""

from __future__ import annotations

from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from hapticdesign.analysis.linearity.bounds import BodyBounds, within_bounds
from hapticdesign.analysis.linearity.convert import seed_from_standard
from hapticdesign.analysis.linearity.convex import SCALE, body_constraints, realizability_lmi, solve
from hapticdesign.analysis.linearity.form import LinearityForm
from hapticdesign.model.device import Device
from hapticdesign.model.inertia import Realizability


@dataclass(frozen=True)
class Certificate:
    """Dual certificate of infeasibility: PSD blocks per body and the worst residual ``s``."""

    blocks: dict[str, np.ndarray]
    residual: float
    null_basis: np.ndarray

    def support(self, rel: float = 1e-6) -> list[str]:
        """Bodies whose block carries weight (the bodies that cannot all be realizable)."""
        total = sum(np.trace(z) for z in self.blocks.values())
        return [b for b, z in self.blocks.items() if np.trace(z) > rel * total]

    def min_eigenvalue(self) -> float:
        return min(float(np.linalg.eigvalsh(z).min()) for z in self.blocks.values())


@dataclass(frozen=True)
class Verdict:
    linear_possible: bool
    kind: Realizability
    certificate: Certificate | None
    design: np.ndarray | None  # seed variables (bodies, 10) when possible
    exact: tuple[tuple[str, int], ...] = ()  # (body, k): diagonal entry k of F_body is 0 on every linear design


def vanishing_diagonals(device: Device, null: np.ndarray, kind: Realizability, tol: float = 1e-12) -> tuple[tuple[str, int], ...]:
    """Diagonal entries of a body's realizability matrix that vanish on every fully linear design.

    Each is an exact certificate with ``Z = e_k e_k^T`` on that body: a positive definite matrix
    has positive diagonal entries, so no fully linear design is strictly realizable.
    """
    bodies = device.body_names
    found = []
    for k, body in enumerate(bodies):
        unit = [_lmi_values(kind, np.eye(null.shape[0])[j], len(bodies))[k] for j in range(10 * k, 10 * k + 10)]
        for d in range(unit[0].shape[0]):
            row = np.zeros(null.shape[0])
            row[10 * k : 10 * k + 10] = [u[d, d] for u in unit]
            if np.abs(row @ null).max() <= tol * np.abs(row).max():
                found.append((body, d))
    return tuple(found)


def _lmi_values(kind: Realizability, direction: np.ndarray, n_bodies: int) -> list[np.ndarray]:
    """Numeric realizability matrices F_i for one standard-parameter direction."""
    out = []
    for k in range(n_bodies):
        p = cp.Constant(direction[10 * k : 10 * k + 10])
        out.append(np.asarray(realizability_lmi(p, kind, 0.0).value))
    return out


def decide_linearizable(device: Device, form: LinearityForm, kind: Realizability = Realizability.RIGID_BODY) -> Verdict:
    """Strict feasibility of realizable fully linear designs, with design or certificate."""
    bodies = device.body_names
    null = form.null_space()
    scale = np.tile(SCALE, len(bodies))
    null_scaled = null / scale[:, None]  # directions in scaled coordinates keep the solver well conditioned
    null_scaled /= np.linalg.norm(null_scaled, axis=0)
    basis = null_scaled * scale[:, None]
    directions = [_lmi_values(kind, basis[:, j], len(bodies)) for j in range(basis.shape[1])]
    size = directions[0][0].shape[0]
    blocks = [cp.Variable((size, size), PSD=True) for _ in bodies]
    s = cp.Variable()
    traces = [sum(cp.trace(blocks[i] @ directions[j][i]) for i in range(len(bodies))) for j in range(len(directions))]
    dual = cp.Problem(cp.Minimize(s), [sum(cp.trace(z) for z in blocks) == 1] + [cp.abs(t) <= s for t in traces])
    solve(dual)
    z_values = {b: 0.5 * (z.value + z.value.T) for b, z in zip(bodies, blocks)}
    residual = max(abs(sum(np.trace(z_values[b] @ directions[j][i]) for i, b in enumerate(bodies))) for j in range(len(directions)))
    certificate = Certificate(z_values, float(residual), basis)
    t = cp.Variable()
    z = cp.Variable(basis.shape[1])
    pi = basis @ z
    constraints = [cp.norm(z, "inf") <= 1]
    for k in range(len(bodies)):
        lmi = realizability_lmi(pi[10 * k : 10 * k + 10], kind, 0.0)
        constraints.append(0.5 * (lmi + lmi.T) >> t * np.eye(size))
    primal = cp.Problem(cp.Maximize(t), constraints)
    solve(primal)
    margin = float(t.value) if t.value is not None else 0.0
    if margin > 1e-6:
        design = seed_from_standard((basis @ z.value).reshape(len(bodies), 10))
        return Verdict(True, kind, None, design)
    return Verdict(False, kind, certificate, None, vanishing_diagonals(device, form.null_space(), kind))


@dataclass(frozen=True)
class MinimumLN:
    ln: float
    lower_bound: float
    design: np.ndarray  # seed variables (bodies, 10)
    within_bounds: bool


def minimum_ln(
    device: Device,
    form: LinearityForm,
    bounds: dict[str, BodyBounds],
    kind: Realizability = Realizability.RIGID_BODY,
) -> MinimumLN:
    """Smallest LN over realizable designs within the bounds (a convex program in ``pi``).

    The conservative upper bounds on mass-centre moments (:mod:`.convex`) give a feasible
    design and so an upper bound; replacing them by their valid relaxation
    ``J_xx <= hi + 2 r_max^2 m`` gives a lower bound on the true minimum.
    """
    bodies = device.body_names
    factor = form.factor()
    scale = np.tile(SCALE, len(bodies))
    fixed = device.standard_parameters()
    results = []
    for relaxed in (False, True):
        x = cp.Variable(len(scale))
        pi = cp.multiply(scale, x)
        constraints = []
        for k, body in enumerate(bodies):
            p = pi[10 * k : 10 * k + 10]
            if body not in bounds:
                constraints.append(x[10 * k : 10 * k + 10] == fixed[10 * k : 10 * k + 10] / SCALE)
                continue
            b = bounds[body]
            if relaxed:
                r2 = max(abs(b.centre[0]), abs(b.centre[1])) ** 2
                b = BodyBounds(b.mass, b.centre, (b.moments[0], b.moments[1] + 2 * r2 * b.mass[1]), b.products + r2 * b.mass[1])
            constraints += body_constraints(p, b, kind, 0.0)
        weight = cp.Parameter(nonneg=True, value=1.0)
        problem = cp.Problem(cp.Minimize(weight * cp.sum_squares(factor @ pi)), constraints)
        solve(problem)
        weight.value = 1.0 / max(problem.value, 1e-30)  # re-solve with the optimum near 1 for accuracy
        solve(problem)
        results.append((problem.value / weight.value, x.value * scale))
    (_, best), (lower, _) = results
    standard = best.reshape(len(bodies), 10)
    design = seed_from_standard(standard)
    return MinimumLN(float(form.ln(best)), max(float(lower), 0.0), design, within_bounds(design, bodies, bounds))
