"""Exact symbolic equations of motion (seed 000 §2.4 and Appendix A), exportable.

The same algorithm as the compiled kernel (:mod:`.kernel`) runs on exact polynomials: every
joint angle ``q_k`` enters through ``c_k = cos q_k`` and ``s_k = sin q_k``, lengths and
inertial parameters may stay symbolic, and products are reduced modulo ``s_k^2 + c_k^2 = 1``
(a Groebner basis, so every result has one canonical form). Kinematic parameters enter the
mechanism affinely (lengths in translations), which is recovered by probing the device's
builder; constant angles must be multiples of pi/2 for exact rational arithmetic (other
angles fall back to floating-point coefficients).

The parameters are the seed's (Table 2.3: ``m_i``, ``r_i`` from the origin of frame ``i-1``,
inertia about the mass centre with products of inertia entering with a minus sign).
"""

from __future__ import annotations

from collections.abc import Callable

from dataclasses import dataclass, replace
from fractions import Fraction
from math import pi

import numpy as np
import sympy as sp
from sympy.polys.domains import QQ, RR
from sympy.polys.rings import ring

from hapticdesign.analysis.dynamics.model import has_trigonometric_basis, pair_index
from hapticdesign.errors import InputError, UserError
from hapticdesign.escape import docstring_text, python_identifier
from hapticdesign.model.device import Device
from hapticdesign.model.mechanism import CompiledMechanism
from hapticdesign.model.inertia import SEED_FIELDS, seed_parameter_name, standard_terms
from hapticdesign.model.transforms import Axis


@dataclass
class SymbolicEquations:
    """``tau = H qdd + C qd^2 + G`` as SymPy matrices in ``theta``, with the symbols used."""

    device: str
    H: sp.Matrix
    C: sp.Matrix
    G: sp.Matrix
    theta: list[sp.Symbol]
    thetad: list[sp.Symbol]
    thetadd: list[sp.Symbol]
    parameters: list[sp.Symbol]

    @property
    def tau(self) -> sp.Matrix:
        n = len(self.theta)
        qd2 = sp.Matrix([self.thetad[j] * self.thetad[k] for j, k in pair_index(n)])
        return self.H * sp.Matrix(self.thetadd) + self.C * qd2 + self.G


def _symbolic_names(device: Device, spec: str) -> list[str]:
    names = device.parameter_names()
    spec = spec.strip()
    if spec == "all":
        return names
    if spec == "none":
        return []
    if spec == "inertial":
        return device.inertial_names()
    chosen = [s.strip() for s in spec.split(",") if s.strip()]
    unknown = [s for s in chosen if s not in names]
    if unknown:
        raise InputError(f"symbolic: unknown parameter name {unknown[0]!r} for device {device.name}", "symbolic")
    return chosen


def _exact(value: float):
    """A float as an exact decimal rational (0.215 -> 43/200)."""
    return Fraction(repr(float(value))) if np.isfinite(value) else None


@dataclass(frozen=True)
class _AffineKinematics:
    """The compiled frame tree at the device's values, with node offsets and gravity as affine
    functions of the symbolic kinematic parameters ``names`` (exact rational slopes)."""

    compiled: CompiledMechanism
    base: dict[str, float]
    names: list[str]
    offsets: np.ndarray
    slopes: list[list[Fraction]]
    gravity: np.ndarray
    gravity_slopes: list[list[Fraction]]


def _affine_offsets(device: Device, kin_symbolic: list[str]) -> _AffineKinematics:
    """Node offsets and gravity as affine functions of the symbolic kinematic parameters."""
    base = dict(device.kinematic_values())
    mech = device.builder(base)
    c0 = mech.compiled
    offsets0 = c0.node_offset.copy()
    gravity0 = np.array(mech.gravity, dtype=float)
    slopes, gslopes = [], []
    rng = np.random.default_rng(12345)
    for name in kin_symbolic:
        step = float(rng.uniform(0.37, 0.71))
        probe = dict(base)
        probe[name] = base[name] + step
        c1 = device.builder(probe).compiled
        if c1.node_offset.shape != offsets0.shape or not np.array_equal(c1.node_axis, c0.node_axis):
            raise UserError(f"parameter {name} changes the structure of the mechanism; keep it numeric")
        slopes.append((c1.node_offset - offsets0) / step)
        gslopes.append((np.array(device.builder(probe).gravity) - gravity0) / step)
    check = dict(base)
    for name in kin_symbolic:
        check[name] = base[name] + float(rng.uniform(-0.3, 0.3))
    cc = device.builder(check).compiled
    predicted = offsets0 + sum(
        (check[n] - base[n]) * s for n, s in zip(kin_symbolic, slopes)
    ) if kin_symbolic else offsets0
    if not np.allclose(cc.node_offset, predicted, rtol=1e-9, atol=1e-12):
        raise UserError("the symbolic kinematic parameters do not enter the mechanism affinely; keep them numeric")
    round_slope = lambda s: [Fraction(x).limit_denominator(1000) for x in s]  # noqa: E731
    return _AffineKinematics(
        c0, base, list(kin_symbolic), offsets0, [round_slope(s) for s in slopes], gravity0, [round_slope(s) for s in gslopes]
    )


@dataclass(frozen=True)
class _Ring:
    """The polynomial ring of one derivation and its reduction modulo ``s_k^2 + c_k^2 = 1``.

    Generators: ``s_k, c_k`` for every joint, ``q_k`` for the prismatic ones, then the symbolic
    parameters. Coefficients are exact rationals (``QQ``) when every constant angle is a
    multiple of pi/2, floating-point (``RR``) otherwise.
    """

    ring: object
    domain: object
    names: list[str]
    gens: dict[str, object]
    s: list
    c: list
    prismatic: list[bool]
    reducers: list

    @classmethod
    def build(cls, aff: _AffineKinematics, inertial: list[str]) -> _Ring:
        comp = aff.compiled
        n = comp.n_dof
        prismatic = [bool(p) for p in comp.prismatic]
        names = [f"s{k + 1}" for k in range(n)] + [f"c{k + 1}" for k in range(n)]
        names += [f"q{k + 1}" for k in range(n) if prismatic[k]] + aff.names + inertial
        domain = QQ if _right_angles_only(aff) else RR
        R, *gens = ring(",".join(names), domain)
        g = dict(zip(names, gens))
        s = [g[f"s{k + 1}"] for k in range(n)]
        c = [g[f"c{k + 1}"] for k in range(n)]
        return cls(R, domain, names, g, s, c, prismatic, [s[k] ** 2 + c[k] ** 2 - 1 for k in range(n)])

    @property
    def exact(self) -> bool:
        return self.domain is QQ

    def num(self, x: float):
        """A constant of the ring (a float taken as its exact decimal rational over ``QQ``)."""
        return self.ring(self.domain.convert(_exact(x) if self.exact else x))

    def const(self, x: Fraction):
        return self.ring(self.domain.convert(x))

    def reduce(self, p):
        """The canonical form of ``p`` modulo ``s_k^2 + c_k^2 - 1``."""
        return p.rem(self.reducers)

    def d_dq(self, p, k: int):
        """``dp/dq_k``: ``ds_k/dq_k = c_k``, ``dc_k/dq_k = -s_k`` for a revolute joint."""
        if self.prismatic[k]:
            return p.diff(self.gens[f"q{k + 1}"])
        return self.reduce(p.diff(self.s[k]) * self.c[k] - p.diff(self.c[k]) * self.s[k])


def _right_angles_only(aff: _AffineKinematics) -> bool:
    """Whether every rotation's constant angle is a multiple of pi/2 (exact rational arithmetic)."""
    return all(
        abs(o / (pi / 2) - round(o / (pi / 2))) < 1e-12
        for o, a in zip(aff.offsets, aff.compiled.node_axis)
        if a < 3
    )


def _affine_poly(R: _Ring, aff: _AffineKinematics, value: float, slopes: list[Fraction]):
    """``value + sum_k slope_k (p_k - p_k0)`` over the symbolic kinematic parameters ``p_k``."""
    out = R.num(value - sum(aff.base[name] * float(sl) for name, sl in zip(aff.names, slopes)))
    for name, sl in zip(aff.names, slopes):
        if sl != 0:
            out += R.const(sl) * R.gens[name]
    return out


def _rotation_cos_sin(R: _Ring, comp: CompiledMechanism, node: int) -> tuple:
    """Cosine and sine of a rotation node's angle ``offset + sum_k coef_k q_k`` as polynomials
    in ``s_k, c_k`` (angle-sum formulas; the couplings must be integers)."""
    offset = comp.node_offset[node]
    if R.exact:
        quarter = int(round(offset / (pi / 2))) % 4
        cs = (R.num([1, 0, -1, 0][quarter]), R.num([0, 1, 0, -1][quarter]))
    else:
        cs = (R.num(np.cos(offset)), R.num(np.sin(offset)))
    coef = comp.node_coef[node]
    for k in range(comp.n_dof):
        if coef[k] == 0:
            continue
        if R.prismatic[k] or coef[k] != round(coef[k]):
            raise UserError("symbolic derivation needs integer couplings between revolute joints")
        m = int(round(coef[k]))
        ck, sk = R.ring(1), R.ring(0)
        for _ in range(abs(m)):
            ck, sk = ck * R.c[k] - sk * R.s[k], sk * R.c[k] + ck * R.s[k]
        if m < 0:
            sk = -sk
        cs = (cs[0] * ck - cs[1] * sk, cs[1] * ck + cs[0] * sk)
    return cs


def _node_poses(R: _Ring, aff: _AffineKinematics) -> tuple[list, list]:
    """Exact world rotation and position of every node of the compiled frame tree.

    The same walk over ``node_parent``, ``node_axis``, ``node_coef``, ``node_offset`` as the
    numeric kernel: a rotation node turns its parent's frame (orientations, seed 000
    eq. 2.20-2.23), a translation node moves the origin along its parent's axis (link
    origins, eq. 2.24-2.26).
    """
    comp = aff.compiled
    n_nodes = comp.node_parent.shape[0]
    rot: list = [None] * n_nodes
    pos: list = [None] * n_nodes
    eye = [[R.ring(1) if i == j else R.ring(0) for j in range(3)] for i in range(3)]
    for node in range(n_nodes):
        parent = comp.node_parent[node]
        rp = eye if parent < 0 else rot[parent]
        pp = [R.ring(0)] * 3 if parent < 0 else pos[parent]
        axis = Axis(int(comp.node_axis[node]))
        a = axis.unit
        if axis.is_rotation:
            cv, sv = _rotation_cos_sin(R, comp, node)
            b, d = (a + 1) % 3, (a + 2) % 3
            new = [row[:] for row in rp]
            for i in range(3):
                new[i][b] = R.reduce(rp[i][b] * cv + rp[i][d] * sv)
                new[i][d] = R.reduce(-rp[i][b] * sv + rp[i][d] * cv)
            rot[node], pos[node] = new, pp
        else:
            value = _affine_poly(R, aff, aff.offsets[node], [sl[node] for sl in aff.slopes])
            for k in range(comp.n_dof):
                if comp.node_coef[node, k] != 0:
                    value += R.num(comp.node_coef[node, k]) * R.gens[f"q{k + 1}"]
            rot[node] = rp
            pos[node] = [R.reduce(pp[i] + rp[i][a] * value) for i in range(3)]
    return rot, pos


def _body_jacobian(R: _Ring, comp: CompiledMechanism, rot: list, pos: list, b: int) -> tuple[list, list]:
    """World rotation of body ``b`` and its body-frame Jacobian ``[Jv; Jw]`` (6 x N).

    Each variable node on ``body_path[b]`` contributes its unit twist moved to the body frame,
    times its joint coefficients: the angular velocity of eq. 2.20-2.23 and the velocity of the
    frame origin obtained by differentiating eq. 2.24-2.26.
    """
    n = comp.n_dof
    nb = comp.body_node[b]
    rb = [[R.ring(1) if i == j else R.ring(0) for j in range(3)] for i in range(3)] if nb < 0 else rot[nb]
    pb = [R.ring(0)] * 3 if nb < 0 else pos[nb]
    jac = [[R.ring(0)] * n for _ in range(6)]
    for e in comp.body_path[b]:
        if e < 0:
            break
        axis = Axis(int(comp.node_axis[e]))
        a = axis.unit
        u = [R.reduce(sum((rb[r][i] * rot[e][r][a] for r in range(3)), R.ring(0))) for i in range(3)]
        if axis.is_rotation:
            d = [pos[e][r] - pb[r] for r in range(3)]
            rr = [R.reduce(sum((rb[r][i] * d[r] for r in range(3)), R.ring(0))) for i in range(3)]
            v = [rr[1] * u[2] - rr[2] * u[1], rr[2] * u[0] - rr[0] * u[2], rr[0] * u[1] - rr[1] * u[0]]
            w = u
        else:
            v, w = u, [R.ring(0)] * 3
        for k in range(n):
            ck = comp.node_coef[e, k]
            if ck != 0:
                ckp = R.num(ck)
                for i in range(3):
                    jac[i][k] += ckp * v[i]
                    jac[3 + i][k] += ckp * w[i]
    return rb, [[R.reduce(x) for x in row] for row in jac]


def _body_parameters(R: _Ring, device: Device, body: str) -> tuple:
    """Mass, first moment ``h`` and inertia tensor about the frame origin of one body, each a
    ring generator when symbolic, else the device's value (:func:`standard_terms`)."""

    def param(name: str):
        return R.gens[name] if name in R.gens else R.num(device.params.get(name, 0.0))

    m, hx, hy, hz, jxx, jyy, jzz, jxy, jxz, jyz = standard_terms(
        *(param(seed_parameter_name(f, body)) for f in SEED_FIELDS)
    )
    return m, [hx, hy, hz], [[jxx, jxy, jxz], [jxy, jyy, jyz], [jxz, jyz, jzz]]


def _add_body(R: _Ring, body: tuple, rb: list, jac: list, gravity: list, H: list, G: list) -> None:
    """Add one body's share to the upper triangle of ``H`` and to ``G``.

    Kinetic energy eq. 2.44 in the body frame gives
    ``H_ij += m Jv_i.Jv_j + h.(Jv_j x Jw_i + Jv_i x Jw_j) + Jw_i^T J Jw_j``; the potential of
    eq. 2.46 gives ``G_i -= (R_b^T g).(m Jv_i + Jw_i x h)`` (Lagrange, eq. 2.49).
    """
    m, h, jo = body
    n = len(G)
    jv, jw = jac[:3], jac[3:]
    gb = [R.reduce(sum((rb[r][i] * gravity[r] for r in range(3)), R.ring(0))) for i in range(3)]
    for i in range(n):
        wi = [jw[0][i], jw[1][i], jw[2][i]]
        vi = [jv[0][i], jv[1][i], jv[2][i]]
        wxh = [wi[1] * h[2] - wi[2] * h[1], wi[2] * h[0] - wi[0] * h[2], wi[0] * h[1] - wi[1] * h[0]]
        G[i] -= sum((gb[r] * (m * vi[r] + wxh[r]) for r in range(3)), R.ring(0))
        for j in range(i, n):
            wj = [jw[0][j], jw[1][j], jw[2][j]]
            vj = [jv[0][j], jv[1][j], jv[2][j]]
            term = m * sum((vi[r] * vj[r] for r in range(3)), R.ring(0))
            # h . (Jv_j x Jw_i) + h . (Jv_i x Jw_j): the first-moment coupling A + A^T
            x1 = [vj[1] * wi[2] - vj[2] * wi[1], vj[2] * wi[0] - vj[0] * wi[2], vj[0] * wi[1] - vj[1] * wi[0]]
            x2 = [vi[1] * wj[2] - vi[2] * wj[1], vi[2] * wj[0] - vi[0] * wj[2], vi[0] * wj[1] - vi[1] * wj[0]]
            term += sum((h[r] * (x1[r] + x2[r]) for r in range(3)), R.ring(0))
            term += sum((wi[r] * jo[r][t] * wj[t] for r in range(3) for t in range(3)), R.ring(0))
            H[i][j] += term


def _mass_and_gravity(R: _Ring, device: Device, aff: _AffineKinematics) -> tuple[list, list]:
    """``H`` and ``G`` of eq. 2.50 (seed 000 eq. 2.44-2.49), summed over the bodies, with the
    actuators' reflected rotor inertia ``sum n^2 J_r a a^T`` added to ``H`` (``n^2 J_r`` on the diagonal for
    a motor on one joint)."""
    comp = aff.compiled
    n = comp.n_dof
    rot, pos = _node_poses(R, aff)
    gravity = [_affine_poly(R, aff, aff.gravity[i], [gs[i] for gs in aff.gravity_slopes]) for i in range(3)]
    H = [[R.ring(0)] * n for _ in range(n)]
    G = [R.ring(0)] * n
    for b, body in enumerate(device.body_names):
        rb, jac = _body_jacobian(R, comp, rot, pos, b)
        _add_body(R, _body_parameters(R, device, body), rb, jac, gravity, H, G)
    H = [[R.reduce(H[min(i, j)][max(i, j)]) for j in range(n)] for i in range(n)]
    G = [R.reduce(x) for x in G]
    for (i, j), reflected in np.ndenumerate(device.reflected_inertia):
        if reflected:
            H[i][j] = H[i][j] + R.num(float(reflected))
    return H, G


def _christoffel(R: _Ring, H: list) -> list:
    """``C`` of eq. 2.50: the column of the pair ``(j, k)`` holds ``Gamma_ijk`` when ``j = k`` and
    ``2 Gamma_ijk`` when ``j < k``, ``Gamma_ijk = (dH_ij/dq_k + dH_ik/dq_j - dH_jk/dq_i) / 2``."""
    n = len(H)
    dH = [[[R.d_dq(H[i][j], k) for k in range(n)] for j in range(n)] for i in range(n)]
    pairs = pair_index(n)
    C = [[R.ring(0)] * len(pairs) for _ in range(n)]
    for i in range(n):
        for col, (j, k) in enumerate(pairs):
            gamma2 = dH[i][j][k] + dH[i][k][j] - dH[j][k][i]
            C[i][col] = gamma2 * R.domain.convert(Fraction(1, 2)) if j == k else gamma2
    return C


def derive(device: Device, symbolic: str = "all", started: Callable[[], None] | None = None) -> SymbolicEquations:
    """Exact H, C, G of ``device`` with the parameters named in ``symbolic`` kept as symbols; ``started()`` is called
    once the request is checked, before the symbolic work (seconds on six joints).

    Open chains only: the equations of a device with closed loops hold on the closure manifold,
    with its passive joints fixed by the closures (no closed form here, see
    :mod:`hapticdesign.analysis.dynamics.closed_loop`); the loop-opened tree's equations would
    treat passive joints as driven and leave out the closure forces, so they are refused.
    """
    if not has_trigonometric_basis(device.mechanism):
        passive = ", ".join(device.mechanism.coordinates[k] for k in device.mechanism.loops.passive)
        raise UserError(f"{device.name} has closed loops (passive joints {passive}): its equations of motion are "
                        "reduced to the actuated joints numerically at each pose and have no symbolic form here")
    keep = _symbolic_names(device, symbolic)
    if started is not None:
        started()
    aff = _affine_offsets(device, [k for k in device.kinematic if k in keep])
    inertial = [name for name in device.inertial_names() if name in keep]
    R = _Ring.build(aff, inertial)
    H, G = _mass_and_gravity(R, device, aff)
    C = _christoffel(R, H)

    coordinates = device.mechanism.coordinates
    n = len(coordinates)
    theta = [sp.Symbol(name, real=True) for name in coordinates]
    sym = {name: sp.Symbol(name, real=True) for name in R.names}
    back = {sym[f"s{k + 1}"]: sp.sin(theta[k]) for k in range(n)}
    back.update({sym[f"c{k + 1}"]: sp.cos(theta[k]) for k in range(n)})
    back.update({sym[f"q{k + 1}"]: theta[k] for k in range(n) if R.prismatic[k]})
    symbols_in_order = [sym[nm] for nm in R.names]

    def to_expr(p):
        return p.as_expr(*symbols_in_order).xreplace(back)

    return SymbolicEquations(
        device=device.name,
        H=sp.Matrix([[to_expr(x) for x in row] for row in H]),
        C=sp.Matrix([[to_expr(x) for x in row] for row in C]),
        G=sp.Matrix([to_expr(x) for x in G]),
        theta=theta,
        thetad=[sp.Symbol(f"{name}d", real=True) for name in coordinates],
        thetadd=[sp.Symbol(f"{name}dd", real=True) for name in coordinates],
        parameters=[sym[nm] for nm in aff.names + inertial],
    )


def rounded(eqs: SymbolicEquations, digits: int = 6, relative: float = 1e-12) -> SymbolicEquations:
    """``eqs`` for reading: each of H, C and G with the terms whose number is below ``relative`` times the
    matrix's largest dropped (the exact rationals of a design's floating-point values carry their round-off,
    e.g. ``17*sin(theta3)/31250000000000`` beside terms of order 0.01) and numbers to ``digits`` significant
    digits."""

    def matrix(m: sp.Matrix) -> sp.Matrix:
        expanded = m.applyfunc(sp.expand)
        terms = [[t.as_coeff_Mul() for t in sp.Add.make_args(e)] for e in expanded]
        largest = max((abs(float(c)) for entry in terms for c, _ in entry), default=0.0)
        kept = [sp.Add(*[sp.Float(c, digits) * rest for c, rest in entry if abs(float(c)) >= relative * largest])
                for entry in terms]
        return sp.Matrix(m.shape[0], m.shape[1], kept)

    return replace(eqs, H=matrix(eqs.H), C=matrix(eqs.C), G=matrix(eqs.G))


def export(eqs: SymbolicEquations, fmt: str, part: str = "tau") -> str:
    """The equations as LaTeX, Python source (a function with common subexpressions) or text."""
    check_export(fmt, part)
    parts = {"tau": eqs.tau, "H": eqs.H, "C": eqs.C, "G": eqs.G}
    chosen = parts if part == "all" else {part: parts[part]}
    if fmt == "latex":
        lines = []
        for name, mat in chosen.items():
            for idx in np.ndindex(mat.shape):
                label = name if mat.shape[1] == 1 and name in ("tau", "G") else name
                sub = f"{idx[0] + 1}" if mat.shape[1] == 1 else f"{idx[0] + 1},{idx[1] + 1}"
                lines.append(f"{label}_{{{sub}}} = {sp.latex(mat[idx])}")
        return "\n".join(lines)
    if fmt == "text":
        return "\n".join(f"{name}[{','.join(str(i + 1) for i in idx)}] = {mat[idx]}" for name, mat in chosen.items() for idx in np.ndindex(mat.shape))
    return _python_source(eqs, chosen)


def check_export(fmt: str, part: str) -> None:
    """A one-line error unless ``fmt`` is latex, python or text and ``part`` tau, H, C, G or all (:func:`export`'s)."""
    if fmt not in ("latex", "python", "text"):
        raise InputError(f"format: expected latex, python or text, got {fmt!r}", "format")
    if part not in ("tau", "H", "C", "G", "all"):
        raise InputError(f"part: expected tau, H, C, G or all, got {part!r}", "part")


def _python_source(eqs: SymbolicEquations, chosen: dict[str, sp.Matrix]) -> str:
    """A plain NumPy function; ``sin``/``cos`` of each angle are computed once up front."""
    from sympy.printing.numpy import NumPyPrinter

    args = [*eqs.theta, *eqs.thetad, *eqs.thetadd, *eqs.parameters]
    for a in args:
        python_identifier(a.name)
    trig = {}
    for k, th in enumerate(eqs.theta):
        trig[sp.sin(th)] = sp.Symbol(f"s{k + 1}")
        trig[sp.cos(th)] = sp.Symbol(f"c{k + 1}")
    printer = NumPyPrinter()
    lines = [
        f'"""Equations of motion of {docstring_text(eqs.device)} (generated by hapticdesign; seed 000 eq. 2.50)."""',
        "import numpy",
        "",
        "",
        f"def equations({', '.join(str(a) for a in args)}):",
        f'    """Return {", ".join(chosen)} as nested lists (SI units)."""',
    ]
    for trig_expr, name in trig.items():
        lines.append(f"    {name} = {printer.doprint(trig_expr)}")
    for name, mat in chosen.items():
        rows = []
        for i in range(mat.shape[0]):
            row = [printer.doprint(mat[i, j].xreplace(trig)) for j in range(mat.shape[1])]
            rows.append("[" + ", ".join(row) + "]")
        lines.append(f"    {name} = [{', '.join(rows)}]")
    lines.append(f"    return {', '.join(chosen)}")
    return "\n".join(lines) + "\n"
