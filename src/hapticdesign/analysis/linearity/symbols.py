"""SymPy symbols for the seed's design variables and the standard parameters they map to.

Seed variables (seed 000 Table 2.3 / Table 3.1 names: ``m2, r2x, Ixx2, Ixy2, ...``) map to the
standard parameters ``(m, h = m r, J)`` of :mod:`hapticdesign.model.inertia` by the
parallel-axis theorem; the products of inertia enter the tensor with a minus sign.
"""

from __future__ import annotations

import sympy as sp

from hapticdesign.model.inertia import SEED_FIELDS, STANDARD_FIELDS, seed_parameter_name


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
    out: list[sp.Expr] = []
    symbols = seed_symbols(bodies)
    for b in range(len(bodies)):
        m, rx, ry, rz, ixx, iyy, izz, ixy, ixz, iyz = symbols[10 * b : 10 * b + 10]
        out += [
            m, m * rx, m * ry, m * rz,
            ixx + m * (ry**2 + rz**2), iyy + m * (rx**2 + rz**2), izz + m * (rx**2 + ry**2),
            -ixy - m * rx * ry, -ixz - m * rx * rz, -iyz - m * ry * rz,
        ]
    return out
