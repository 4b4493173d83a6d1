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

from hapticdesign.analysis.linearity.bounds import Bounds, SeedBox, as_box, clip_to_bounds, within_bounds
from hapticdesign.analysis.linearity.convex import COUPLED, SCALE, body_constraints, bounds_scale, realizability_lmi, solve
from hapticdesign.analysis.linearity.quadratic import LinearityForm
from hapticdesign.analysis.linearity.linear_designs import realizable
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.model.inertia import Realizability, seed_from_standard, standard_from_seed


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
    """Strict feasibility of realizable fully linear designs, with design or certificate.

    Vanishing diagonal entries (:func:`vanishing_diagonals`) settle the question exactly; only
    without them is the margin ``max t: F(z) >= t 1`` solved for (a degenerate, and therefore
    inaccurate, interior-point problem when the answer is no).
    """
    bodies = device.body_names
    null = form.null_space()
    scale = np.tile(SCALE, len(bodies))
    null_scaled = null / scale[:, None]  # directions in scaled coordinates keep the solver well conditioned
    null_scaled /= np.linalg.norm(null_scaled, axis=0)
    basis = null_scaled * scale[:, None]
    exact = vanishing_diagonals(device, null, kind)
    if not exact:
        design = _strictly_realizable(basis, kind, len(bodies))
        if design is not None:
            return Verdict(True, kind, None, design)
    return Verdict(False, kind, _dual_certificate(basis, kind, bodies), None, exact)


def _strictly_realizable(basis: np.ndarray, kind: Realizability, n_bodies: int) -> np.ndarray | None:
    """A fully linear design with every realizability matrix >= 1e-6 * 1 (|z|_inf <= 1), if any."""
    t = cp.Variable()
    z = cp.Variable(basis.shape[1])
    pi = basis @ z
    constraints = [cp.norm(z, "inf") <= 1]
    for k in range(n_bodies):
        lmi = realizability_lmi(pi[10 * k : 10 * k + 10], kind, 0.0)
        constraints.append(0.5 * (lmi + lmi.T) >> t * np.eye(lmi.shape[0]))
    solve(cp.Problem(cp.Maximize(t), constraints))
    if t.value is None or float(t.value) <= 1e-6:
        return None
    return seed_from_standard((basis @ z.value).reshape(n_bodies, 10))


def _dual_certificate(basis: np.ndarray, kind: Realizability, bodies: tuple[str, ...]) -> Certificate:
    """PSD blocks ``Z_i`` (sum of traces 1) minimizing ``max_k |sum_i tr(Z_i F_i(N e_k))|``."""
    directions = [_lmi_values(kind, basis[:, j], len(bodies)) for j in range(basis.shape[1])]
    size = directions[0][0].shape[0]
    blocks = [cp.Variable((size, size), PSD=True) for _ in bodies]
    s = cp.Variable()
    traces = [sum(cp.trace(blocks[i] @ directions[j][i]) for i in range(len(bodies))) for j in range(len(directions))]
    dual = cp.Problem(cp.Minimize(s), [sum(cp.trace(z) for z in blocks) == 1] + [cp.abs(t) <= s for t in traces])
    solve(dual)
    z_values = {b: 0.5 * (z.value + z.value.T) for b, z in zip(bodies, blocks)}
    residual = max(abs(sum(np.trace(z_values[b] @ directions[j][i]) for i, b in enumerate(bodies))) for j in range(len(directions)))
    return Certificate(z_values, float(residual), basis)


@dataclass(frozen=True)
class MinimumLN:
    ln: float  # re-evaluated exactly from ``design`` (an attained value, so an upper bound on the minimum)
    lower_bound: float
    design: np.ndarray  # seed variables (bodies, 10)
    within_bounds: bool
    realizable: bool


# Relative margin on the mass-centre moment lower bounds of the solve: the interior-point solution
# meets its constraints only to its tolerance, the margin keeps it inside the true bounds.
MOMENT_MARGIN = 1e-4


def _relaxed(box: SeedBox) -> SeedBox:
    """A box whose conservative constraints (:mod:`.convex`) contain every design of ``box``: the upper
    moment bounds raised by ``m_hi (r_b^2 + r_c^2)`` and the product bounds widened by ``m_hi |r_a r_b|``
    (the largest parallel-axis terms), where those coordinates are not fixed."""
    r = np.maximum(np.abs(box.low[1:4]), np.abs(box.high[1:4]))
    low, high = box.low.copy(), box.high.copy()
    for k, (a, b) in enumerate(COUPLED):
        if box.fixed[1 + a] and box.fixed[1 + b]:
            continue  # bounded exactly
        if k < 3:
            high[4 + k] += box.high[0] * (r[a] ** 2 + r[b] ** 2)
        else:
            low[4 + k] -= box.high[0] * r[a] * r[b]
            high[4 + k] += box.high[0] * r[a] * r[b]
    return SeedBox(low, high)


def _with_margin(box: SeedBox) -> SeedBox:
    """The box with :data:`MOMENT_MARGIN` on the moments' lower bounds (not beyond their upper bounds)."""
    low = box.low.copy()
    low[4:7] = np.where(box.fixed[4:7], low[4:7], np.minimum(low[4:7] * (1 + MOMENT_MARGIN), box.high[4:7]))
    return SeedBox(low, box.high)


def minimum_ln(
    device: Device,
    form: LinearityForm,
    bounds: dict[str, Bounds],
    kind: Realizability = Realizability.RIGID_BODY,
    affine: tuple[np.ndarray, np.ndarray] | None = None,
) -> MinimumLN:
    """Smallest LN over realizable designs within the bounds (a convex program in ``pi``).

    ``min |L pi|`` (``LN = |L pi|^2``, a second-order cone objective that stays well scaled where
    LN itself spans twelve orders of magnitude) in variables scaled per body from its bounds
    (:func:`.convex.bounds_scale`). Bodies without bounds keep the device's parameters. The
    conservative upper bounds on mass-centre moments (:mod:`.convex`) and a small margin on their
    lower bounds give a design inside the bounds; it is clipped to the bounds in the seed's
    variables (a no-op up to the solver's tolerance), checked for realizability and its LN
    re-evaluated exactly: an attained upper bound on the minimum. Replacing the conservative bounds
    by their valid relaxation (:func:`_relaxed`, no margin) gives a lower bound on the true minimum.
    ``affine = (A, b)`` adds ``A pi <= b`` on the standard parameters of all bodies to both problems.
    """
    bodies = device.body_names
    factor = form.factor()
    scale = bounds_scale(bounds, bodies)
    fixed = device.standard_parameters()
    results = []
    for relaxed in (False, True):
        x = cp.Variable(len(scale))
        pi = cp.multiply(scale, x)
        constraints = []
        for k, body in enumerate(bodies):
            p = pi[10 * k : 10 * k + 10]
            if body not in bounds:
                constraints.append(x[10 * k : 10 * k + 10] == fixed[10 * k : 10 * k + 10] / scale[10 * k : 10 * k + 10])
                continue
            box = as_box(bounds[body])
            constraints += body_constraints(p, _relaxed(box) if relaxed else _with_margin(box), kind, 0.0)
        if affine is not None:
            constraints.append(affine[0] @ pi <= affine[1])
        problem = cp.Problem(cp.Minimize(cp.norm(factor @ pi)), constraints)
        solve(problem)
        if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
            raise UserError(f"no realizable design within the bounds (solver: {problem.status})")
        results.append((problem.value**2, x.value * scale))
    (_, best), (lower, _) = results
    design = clip_to_bounds(seed_from_standard(best.reshape(len(bodies), 10)), bodies, bounds)
    standard = standard_from_seed(design)
    return MinimumLN(
        float(form.ln(standard.ravel())),
        float(lower),
        design,
        within_bounds(design, bodies, bounds),
        realizable(design, standard, kind),
    )


def scaled_minimum(device: Device, mins: MinimumLN) -> float:
    """LN of the practical optimum scaled down until its smallest mass or moment is 1e-15 (eq. 3.40-3.42)."""
    bodies = [k for k, b in enumerate(device.body_names)]
    smallest = min(min(mins.design[k, 0], mins.design[k, 4:7].min()) for k in bodies if mins.design[k, 0] > 0)
    return mins.ln * (1e-15 / smallest) ** 2
