"""SymPy symbols for the seed's design variables and the standard parameters they map to.

Seed variables (seed 000 Table 2.3 / Table 3.1 names: ``m2, r2x, Ixx2, Ixy2, ...``) map to the
standard parameters ``(m, h = m r, J)`` by :func:`hapticdesign.model.inertia.standard_terms`.
"""

from __future__ import annotations

import sympy as sp

from hapticdesign.model.inertia import SEED_FIELDS, STANDARD_FIELDS, seed_parameter_name, standard_terms


def standard_name(field: str, body: str) -> str:
    """Name of a standard parameter: ``m2``, ``h2x``, ``J2xy``."""
    if field == "m":
        return f"m{body}"
    return f"{field[0]}{body}{field[1:]}"


def standard_names(bodies: tuple[str, ...]) -> list[str]:
    return [standard_name(f, b) for b in bodies for f in STANDARD_FIELDS]


def seed_symbols(bodies: tuple[str, ...]) -> list[sp.Symbol]:
    return [sp.Symbol(seed_parameter_name(f, b), real=True) for b in bodies for f in SEED_FIELDS]


def standard_expressions(bodies: tuple[str, ...]) -> list[sp.Expr]:
    """Standard parameters as polynomials in the seed variables (same order as the regressor)."""
    symbols = seed_symbols(bodies)
    return [term for b in range(len(bodies)) for term in standard_terms(*symbols[10 * b : 10 * b + 10])]
