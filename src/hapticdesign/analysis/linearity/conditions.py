"""Analytic linearization (seed 000 §3.2.1, eq. 3.12-3.27) as linear algebra.

LN is ``pi^T Q pi`` with Q positive semi-definite, so LN = 0 exactly when ``Q pi = 0``: every
non-constant basis coefficient of H and G and every coefficient of C vanishes. These are linear
equations in the standard inertial parameters; their reduced row-echelon form names the
dependent parameters, the rest are free (Table 3.2), and on the solution set H equals its
constant basis coefficient (eq. 3.27). Substituting the standard parameters' expressions in the
seed's variables and solving for the seed's dependent variables reproduces eq. 3.12-3.26.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import sympy as sp

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.linearity.quadratic import LinearityForm
from hapticdesign.analysis.linearity.symbols import seed_symbols, standard_expressions, standard_names
from hapticdesign.model.device import Device

# Pivot preference among standard parameters: first moments, then products, then moments, then masses.
_FIELD_RANK = {"h": 0, "J": 1, "m": 3}


@dataclass(frozen=True)
class LinearConditions:
    """LN = 0 as ``rows @ pi = 0`` in reduced row-echelon form, with pivots and free parameters."""

    names: tuple[str, ...]
    rows: np.ndarray
    pivots: tuple[int, ...]
    constant_h: np.ndarray  # (N, N, P): H = constant_h @ pi on the solution set (eq. 3.27)

    @property
    def free(self) -> tuple[int, ...]:
        return tuple(i for i in range(len(self.names)) if i not in self.pivots)

    def residual(self, pi: np.ndarray) -> np.ndarray:
        return np.asarray(pi) @ self.rows.T

    def project(self, pi: np.ndarray) -> np.ndarray:
        """Orthogonal projection of parameters onto the solution set (exactly linear designs)."""
        q, _ = np.linalg.qr(self.rows.T)
        pi = np.asarray(pi, dtype=float)
        return pi - (pi @ q) @ q.T

    def solve(self, free_values: np.ndarray) -> np.ndarray:
        """Complete parameters from the free ones (non-pivot entries of ``free_values`` are kept)."""
        pi = np.array(free_values, dtype=float)
        pi[list(self.pivots)] = 0.0
        pi[list(self.pivots)] = -(self.rows @ pi)
        return pi

    def equations(self, digits: int = 6) -> list[str]:
        """Readable equations ``pivot = sum c_j free_j``."""
        out = []
        for row, p in zip(self.rows, self.pivots):
            terms = [
                f"{-c:+.{digits}g} {self.names[j]}" for j, c in enumerate(row) if j != p and abs(c) > 1e-12
            ]
            out.append(f"{self.names[p]} = " + (" ".join(terms).lstrip("+") if terms else "0"))
        return out


def _pivot_order(names: list[str], preferred: tuple[str, ...]) -> list[int]:
    first = [names.index(p) for p in preferred]
    rest = sorted((i for i in range(len(names)) if i not in first), key=lambda i: (_FIELD_RANK[names[i][0]], -i))
    return first + rest


def _rref(matrix: np.ndarray, order: list[int], tol: float) -> tuple[np.ndarray, list[int]]:
    a = matrix.copy()
    rows, pivots = 0, []
    for col in order:
        if rows == a.shape[0]:
            break
        k = rows + int(np.argmax(np.abs(a[rows:, col])))
        if abs(a[k, col]) <= tol:
            continue
        a[[rows, k]] = a[[k, rows]]
        a[rows] /= a[rows, col]
        others = np.arange(a.shape[0]) != rows
        a[others] -= np.outer(a[others, col], a[rows])
        pivots.append(col)
        rows += 1
    a = a[:rows]
    a[np.abs(a) < 1e-13] = 0.0
    return a, pivots


def linear_conditions(device: Device, form: LinearityForm, rel_tol: float = 1e-10) -> LinearConditions:
    """Linear equations for LN = 0 in reduced row-echelon form.

    On any region with interior the basis functions are linearly independent, so LN = 0 exactly
    when every non-constant basis coefficient of a weighted H or G entry and every coefficient of
    a weighted C entry vanishes: these coefficient rows (orthonormalized by an SVD) span the
    conditions.
    """
    model = dynamics_of(device)
    w_h, w_c, w_g = form.weights.per_entry()
    a = model.coefficients
    blocks = [
        a[1:, model.slice_h][:, w_h > 0],
        a[:, model.slice_c][:, w_c > 0],
        a[1:, model.slice_g][:, w_g > 0],
    ]
    stacked = np.concatenate([b.reshape(-1, model.n_params) for b in blocks])
    # same right singular vectors as the tall stack, at a third of the cost: QR first, then SVD of R
    _, sing, vt = np.linalg.svd(np.linalg.qr(stacked, mode="r"))
    row_space = vt[sing > rel_tol * max(sing.max(), 1e-300)]
    names = standard_names(device.body_names)
    rows, pivots = _rref(row_space, _pivot_order(names, device.preset_data.pivots), 1e-9)
    n = model.n_dof
    h0 = model.coefficients[0, model.slice_h]  # constant basis function is index 0
    iu, ju = np.triu_indices(n)
    constant = np.zeros((n, n, model.n_params))
    constant[iu, ju] = h0
    constant[ju, iu] = h0
    return LinearConditions(tuple(names), rows, tuple(pivots), constant)


@dataclass(frozen=True)
class SeedConditions:
    """The conditions solved for the seed's dependent variables (eq. 3.12-3.26)."""

    solution: dict[sp.Symbol, sp.Expr]
    free: tuple[sp.Symbol, ...]


def _rational(value: float) -> sp.Expr:
    """A float coefficient as a short fraction when one matches to 1e-12 (lengths are decimals)."""
    fraction = Fraction(value).limit_denominator(10**8)
    if abs(float(fraction) - value) <= 1e-12 * max(abs(value), 1e-300):
        return sp.Rational(fraction.numerator, fraction.denominator)
    return sp.Float(value)


def _rational_rows(rows: np.ndarray) -> sp.Matrix:
    return sp.Matrix([[_rational(float(c)) for c in row] for row in rows])


def seed_conditions(device: Device, conditions: LinearConditions, dependents: tuple[str, ...] | None = None) -> SeedConditions:
    """Rewrite the conditions in the seed's design variables and solve them for the dependents."""
    bodies = device.body_names
    symbols = seed_symbols(bodies)
    by_name = {s.name: s for s in symbols}
    dependents = dependents or device.preset_data.dependents or _mapped_pivots(conditions, bodies)
    unknowns = [by_name[d] for d in dependents]
    std = sp.Matrix(standard_expressions(bodies))
    rows = _rational_rows(conditions.rows)
    equations = [sp.expand(e) for e in rows * std]
    solution = _solve_one_at_a_time(equations, unknowns)
    free = tuple(s for s in symbols if s not in unknowns)
    return SeedConditions(solution, free)


def _solve_one_at_a_time(equations: list[sp.Expr], unknowns: list[sp.Symbol]) -> dict[sp.Symbol, sp.Expr]:
    """Solve equations that are each linear in one remaining unknown, substituting as we go."""
    solution: dict[sp.Symbol, sp.Expr] = {}
    pending = list(equations)
    while pending:
        progress = False
        for eq in list(pending):
            current = sp.expand(eq.subs(solution))
            left = [u for u in unknowns if u in current.free_symbols and u not in solution]
            if not left:
                pending.remove(eq)
                progress = True
                continue
            if len(left) == 1 and sp.degree(current, left[0]) == 1:
                coeff = current.coeff(left[0], 1)
                solution[left[0]] = sp.simplify(-(current - coeff * left[0]) / coeff)
                pending.remove(eq)
                progress = True
        if not progress:
            raise ValueError("the linearization conditions are not solvable one variable at a time for these dependents")
    return solution


def _mapped_pivots(conditions: LinearConditions, bodies: tuple[str, ...]) -> tuple[str, ...]:
    """Seed variable named like each pivot (h2x -> r2x, J2xy -> Ixy2, m2 -> m2)."""
    out = []
    for p in conditions.pivots:
        name = conditions.names[p]
        body = next(b for b in sorted(bodies, key=len, reverse=True) if name[1:].startswith(b))
        rest = name[1 + len(body) :]
        out.append({"m": f"m{body}", "h": f"r{body}{rest}", "J": f"I{rest}{body}"}[name[0]])
    return tuple(out)
