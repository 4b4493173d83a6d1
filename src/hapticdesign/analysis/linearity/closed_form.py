"""Closed-form Linearity Number in the seed's design variables (seed 000 Appendix B.1, B.2).

The seed derives LN symbolically from the equations of motion (Appendix B.1 for 3 DOF; its
6-DOF build, B.2, is the expensive one). Here LN is already the quadratic form
``pi^T Q pi`` in the standard parameters (:mod:`.form`), so the closed form is that form with the
seed -> standard map substituted (:func:`.symbols.standard_expressions`: ``h = m r``,
``J = I_c + m (r.r 1 - r r^T)``, products of inertia entering ``I_c`` with a minus sign, Table
2.3): a polynomial of degree at most 6 in the masses, mass centres and inertias, built with
SymPy's sparse polynomial ring from the ~10^2-10^3 non-zero entries of Q in well under a second,
for 3 and 6 DOF alike.

Lengths stay numeric (those of the device). Gravity can be kept as the symbol ``g``: the G part
is exactly ``g^2`` times the form computed with the device's g, as in the seed's
``0.5 g^2 (l2^2 m2a^2 + ...)`` of Appendix B.1. Entries of Q below ``1e-12`` of the largest
entry of their part are floating-point noise (true entries are above 1e-9 of it, noise below
1e-15) and are dropped; coefficients are rounded to 14 significant digits, so dyadic values
such as Appendix B.1's ``0.75 Ixx2^2`` come out exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import sympy as sp
from sympy.polys.domains import RR
from sympy.polys.rings import ring

from hapticdesign.analysis.linearity.quadratic import PARTS, LinearityForm
from hapticdesign.analysis.linearity.symbols import seed_symbols, standard_expressions
from hapticdesign.errors import InputError, UserError
from hapticdesign.escape import docstring_text, python_identifier
from hapticdesign.model.device import Device
from hapticdesign.model.inertia import SEED_FIELDS

NOISE = 1e-12
DIGITS = 14
FORMATS = ("text", "latex", "python")


Terms = dict[tuple[int, ...], float]  # exponents of ``gens`` -> coefficient


@dataclass(frozen=True)
class ClosedForm:
    """LN and its H, C, G parts as sparse polynomials in the seed's variables (and ``g``).

    The terms are kept sparse (exponent tuple -> coefficient) so that exports stay fast with the
    6-DOF Phantom's 81 generators; :meth:`polynomial` gives the SymPy ``Poly`` on request.
    """

    device: str
    gens: tuple[sp.Symbol, ...]  # the device's inertial parameters in device order, then ``g`` if symbolic
    parts: dict[str, Terms]
    latex_names: dict[sp.Symbol, str]

    @cached_property
    def total(self) -> Terms:
        out: dict[tuple[int, ...], float] = {}
        size: dict[tuple[int, ...], float] = {}
        for terms in self.parts.values():
            for monom, coeff in terms.items():
                out[monom] = out.get(monom, 0.0) + coeff
                size[monom] = size.get(monom, 0.0) + abs(coeff)
        return _cleaned(out, size)

    def terms(self, part: str = "all") -> Terms:
        if part == "all":
            return self.total
        if part not in self.parts:
            raise InputError(f"part: choose all, H, C or G, got {part!r}", "part")
        return self.parts[part]

    def polynomial(self, part: str = "all") -> sp.Poly:
        """The SymPy polynomial (real coefficients) in all generators."""
        return sp.Poly.from_dict(dict(self.terms(part)) or {(0,) * len(self.gens): 0.0}, *self.gens, domain=RR)

    def expression(self, part: str = "all") -> sp.Expr:
        return sp.Add(*(sp.Float(c, DIGITS) * self._monomial(m) for m, c in self._sorted(part)))

    def variables(self, part: str = "all") -> list[sp.Symbol]:
        """Generators that occur in the polynomial, in generator order."""
        used = np.zeros(len(self.gens), dtype=bool)
        for monom in self.terms(part):
            used |= np.array(monom) > 0
        return [g for g, u in zip(self.gens, used) if u]

    def evaluate(self, values: dict[str, float], part: str = "all") -> float:
        """The polynomial at one design given by name (``g`` too when it is symbolic)."""
        missing = [s.name for s in self.variables(part) if s.name not in values]
        if missing:
            raise UserError(f"missing values for {', '.join(missing)}")
        x = np.array([values.get(g.name, 0.0) for g in self.gens], dtype=float)
        return float(sum(c * np.prod(x ** np.array(m)) for m, c in self.terms(part).items()))

    def text(self, part: str = "all") -> str:
        return f"LN{_suffix(part)} = {self.expression(part)}"

    def latex(self, part: str = "all") -> str:
        """``\\mathrm{LN} = ...`` with the seed's names as subscripted symbols (``I_{xx2a}``)."""
        out = []
        for monom, coeff in self._sorted(part):
            factors = " ".join(
                self.latex_names[g] + (f"^{{{k}}}" if k > 1 else "") for g, k in zip(self.gens, monom) if k
            )
            out.append(f"{'-' if coeff < 0 else '+'} {_latex_number(abs(coeff))} {factors}".rstrip())
        body = " ".join(out) or "+ 0"
        body = body[2:] if body.startswith("+ ") else "-" + body[2:]
        return rf"\mathrm{{LN}}{_suffix(part)} = {body}"

    def python(self, part: str = "all") -> str:
        """Source of a function ``linearity_number(**design)`` (extra keywords are ignored)."""
        terms = []
        for monom, coeff in self._sorted(part):
            factors = "".join(f" * {g.name}" + (f"**{k}" if k > 1 else "") for g, k in zip(self.gens, monom) if k)
            terms.append(f"{coeff!r}{factors}")
        body = "\n        + ".join(terms) if terms else "0.0"
        names = [python_identifier(s.name) for s in self.variables(part)]
        signature = ", ".join(["*", *names, "**_unused"] if names else ["**_unused"])  # "*, **x" is not Python
        return (
            f'"""{_title(part)} of {docstring_text(self.device)} in the seed\'s design variables '
            '(seed 000 eq. 3.1-3.4, Appendix B)."""\n\n\n'
            f"def linearity_number({signature}) -> float:\n"
            f"    return (\n        {body}\n    )\n"
        )

    def export(self, fmt: str, part: str = "all") -> str:
        if fmt not in FORMATS:
            raise InputError(f"format: choose {', '.join(FORMATS)}, got {fmt!r}", "format")
        return getattr(self, fmt)(part)

    def _sorted(self, part: str) -> list[tuple[tuple[int, ...], float]]:
        return sorted(self.terms(part).items(), reverse=True)

    def _monomial(self, monom: tuple[int, ...]) -> sp.Expr:
        return sp.Mul(*(g**k for g, k in zip(self.gens, monom) if k))


def closed_form(device: Device, form: LinearityForm, symbolic_gravity: bool = False) -> ClosedForm:
    """Substitute the seed -> standard map into ``pi^T Q pi`` (per part) and expand."""
    bodies = device.body_names
    symbols = seed_symbols(bodies)
    gens = list(symbols)
    g_value = None
    if symbolic_gravity:
        g_value = float(device.params.get("g", 0.0))
        if g_value == 0.0:
            raise UserError(f"device {device.name} has no non-zero gravity parameter g to keep symbolic")
        gens.append(sp.Symbol("g", positive=True))
    poly_ring, *ring_gens = ring(gens, RR)
    standard = [poly_ring.from_expr(e) for e in standard_expressions(bodies)]
    magnitude = [poly_ring.from_dict({m: abs(float(c)) for m, c in e.items()}) for e in standard]
    parts = {}
    for name, q in zip(PARTS, form.Q):
        if name == "G" and g_value is not None:
            q = q / g_value**2
        poly, size = _quadratic(q, standard, poly_ring), _quadratic(np.abs(q), magnitude, poly_ring)
        if name == "G" and g_value is not None:
            poly, size = poly * ring_gens[-1] ** 2, size * ring_gens[-1] ** 2
        parts[name] = _cleaned({m: float(c) for m, c in poly.items()}, {m: float(c) for m, c in size.items()})
    return ClosedForm(device.name, tuple(gens), parts, _latex_names(bodies, symbols, gens))


def _quadratic(q: np.ndarray, standard: list, poly_ring) -> object:
    """``sum_ij q_ij s_i s_j`` over the entries above the noise level (upper triangle doubled)."""
    threshold = NOISE * max(np.abs(q).max(), 1e-300)
    out = poly_ring(0)
    for i in range(q.shape[0]):
        row = poly_ring(0)
        for j in np.nonzero(np.abs(q[i, i:]) > threshold)[0] + i:
            row += standard[j] * float(q[i, j] if j == i else 2.0 * q[i, j])
        if row:
            out += standard[i] * row
    return out


def _cleaned(terms: Terms, size: Terms) -> Terms:
    """Drop cancellation noise (below ``NOISE`` of the sum of the term's contributions' magnitudes)
    and round the coefficients to ``DIGITS`` significant digits."""
    out = {m: float(f"{c:.{DIGITS}g}") for m, c in terms.items() if abs(c) > NOISE * size[m]}
    return {m: c for m, c in out.items() if c != 0.0}


def _latex_names(bodies: tuple[str, ...], symbols: list[sp.Symbol], gens: list[sp.Symbol]) -> dict[sp.Symbol, str]:
    """``m2a -> m_{2a}``, ``r2ax -> r_{2ax}``, ``Ixy3 -> I_{xy3}``, ``g -> g``."""
    out = {}
    for k, body in enumerate(bodies):
        for field, symbol in zip(SEED_FIELDS, symbols[10 * k : 10 * k + 10]):
            if field == "m":
                out[symbol] = f"m_{{{body}}}"
            elif field.startswith("r"):
                out[symbol] = f"r_{{{body}{field[1]}}}"
            else:
                out[symbol] = f"I_{{{field[1:]}{body}}}"
    for extra in gens[len(symbols) :]:
        out[extra] = extra.name
    return out


def _latex_number(value: float) -> str:
    mantissa, _, exponent = f"{value:.{DIGITS}g}".partition("e")
    return rf"{mantissa} \times 10^{{{int(exponent)}}}" if exponent else mantissa


def _title(part: str) -> str:
    return "Linearity Number" if part == "all" else f"{part} part of the Linearity Number"


def _suffix(part: str) -> str:
    return "" if part == "all" else f"_{part}"
