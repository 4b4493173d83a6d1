"""Study steps that work for any device of the engine (seed 000 ch. 2-3 applied beyond the Phantom).

Each takes the device from ``ctx.settings.device()``: equations of motion (eq. 2.50-2.52), the
Linearity Number (eq. 3.1-3.4), the analytic linearization with realizable linear designs
(§3.2.1, eq. 3.12-3.32) and the verdict whether a realizable fully linear design exists (§3.3).
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.dynamics.device import gravity, inverse_dynamics, mass_matrix
from hapticdesign.analysis.dynamics.model import has_trigonometric_basis
from hapticdesign.analysis.dynamics.symbolic import derive, export, rounded
from hapticdesign.analysis.linearity.bounds import practical_bounds
from hapticdesign.analysis.linearity.conditions import (
    linear_conditions,
    seed_conditions,
)
from hapticdesign.analysis.linearity.linear_designs import find_linear_designs as find
from hapticdesign.analysis.linearity.form import device_form
from hapticdesign.analysis.linearity.verdict import decide_linearizable as decide
from hapticdesign.analysis.linearity.verdict import minimum_ln
from hapticdesign.analysis.view.figure import device_figure
from hapticdesign.analysis.view.page import render_page
from hapticdesign.analysis.view.skeleton import export as view_data
from hapticdesign.analysis.view.skeleton import home_pose
from hapticdesign.errors import UserError
from hapticdesign.studies.steps import Context, Outcome, Page, Skipped, Table, figure_from_matplotlib


def matrix_text(name: str, m: np.ndarray) -> str:
    rows = [" ".join(f"{v: .6e}" for v in row) for row in np.atleast_2d(m)]
    return f"{name} =\n  " + "\n  ".join(rows)


def device_view(ctx: Context) -> Outcome:
    """The device at its home pose (seed 000 §2.1-2.3: frames and links): a static figure and the interactive page."""
    device = ctx.settings.device()
    q = home_pose(device)
    mech = device.mechanism
    loops = f", {len(mech.loops.closures)} loop closures" if mech.loops.closures else ""
    return Outcome(
        summary=f"{device.name}: {len(mech.frames)} frames, {len(mech.bodies)} bodies, "
                f"{mech.n_actuated} actuated joints{loops}.",
        paragraphs=["The figure shows the device at its home pose; the linked page is the same device in 3D with a "
                    "slider per actuated joint (it runs its own script and needs no network)."],
        figures=[figure_from_matplotlib(device_figure(device, q), "device", "The device at its home pose")],
        pages=[Page("device", "Interactive 3D view", render_page(view_data(device, q)))],
        numbers={"frames": len(mech.frames), "bodies": len(mech.bodies), "actuated": mech.n_actuated},
    )


READABLE_RELATIVE = 1e-8
READABLE = ("to 6 significant digits, terms below 1e-8 of the matrix's largest dropped (below the precision of "
            "values given to 9 significant digits, as seed 000's tables give them)")
NO_SYMBOLIC_LOOPS = ("a closed-loop device has no symbolic tree equations: its passive joints are solved numerically "
                     "from the loop closures, so H, C and G are not closed-form expressions of the actuated joints")


def closed_loop_evaluations(device) -> Outcome:
    """Seed 000 eq. 2.50-2.52 on a closed-loop device: the compiled H, G and tau in the actuated coordinates at
    home and at two poses 0.1 rad either side (the symbolic form does not exist, see :data:`NO_SYMBOLIC_LOOPS`)."""
    n = device.n_dof
    home = home_pose(device)
    poses = [home, home + 0.1, home - 0.1]
    qd, qdd = np.full(n, 0.5), np.full(n, 1.0)
    rows = []
    for q in poses:
        h, g = mass_matrix(device, q), gravity(device, q)
        rows.append([", ".join(f"{v:.4f}" for v in q), *np.diag(h), *g, *inverse_dynamics(device, q, qd, qdd)])
    columns = ["q", *[f"H{i}{i}" for i in range(1, n + 1)], *[f"G{i}" for i in range(1, n + 1)],
               *[f"tau{i}" for i in range(1, n + 1)]]
    h_home = mass_matrix(device, home)
    return Outcome(
        summary=f"{device.name}: tau = H(q) qdd + C(q, qd) qd + G(q) (eq. 2.50) in its {n} actuated coordinates, "
                "evaluated by the compiled closed-loop model; no symbolic form (" + NO_SYMBOLIC_LOOPS + ").",
        paragraphs=["H, C and G of the loop-opened tree are projected onto the actuated joints (H_a = T^T H T, "
                    "G_a = T^T G with T = [I; -Phi_p^-1 Phi_a]) at each pose, the passive joints solved from home on "
                    "the assembly branch.",
                    f"Evaluations in SI units (rad or m, N m or N): joint rates {qd[0]} and accelerations {qdd[0]} on "
                    "every joint."],
        listings=[("H at home (compiled model):", matrix_text("H", h_home))],
        tables=[Table("evaluations", "H diagonal, G and tau at home and home +- 0.1 rad", columns, rows)],
        numbers={"H_at_home": h_home},
    )


def equations_of_motion(ctx: Context) -> Outcome:
    """Seed 000 eq. 2.50-2.52: exact H and G of the design, evaluations, and the size of the symbolic form."""
    import sympy as sp
    device = ctx.settings.device()
    if not has_trigonometric_basis(device.mechanism):
        return closed_loop_evaluations(device)
    numeric = derive(device, "none")
    full = derive(device, "all")
    full_text = export(full, "text", "all")
    n = device.n_dof
    rng = np.random.default_rng(ctx.settings.seed)
    poses = [np.zeros(n), np.resize([0.3, -0.4, 0.7], n), rng.uniform(-np.pi, np.pi, n)]
    qd, qdd = np.full(n, 0.5), np.full(n, 1.0)
    h_sym = sp.lambdify(numeric.theta, numeric.H, "numpy")
    g_sym = sp.lambdify(numeric.theta, numeric.G, "numpy")
    rows, worst = [], 0.0
    for q in poses:
        h, g = mass_matrix(device, q), gravity(device, q)
        worst = max(worst, float(np.abs(np.array(h_sym(*q), dtype=float) - h).max()),
                    float(np.abs(np.array(g_sym(*q), dtype=float).ravel() - g).max()))
        tau = inverse_dynamics(device, q, qd, qdd)
        rows.append([", ".join(f"{v:.4f}" for v in q), *np.diag(h), *g, *tau])
    columns = ["q", *[f"H{i}{i}" for i in range(1, n + 1)], *[f"G{i}" for i in range(1, n + 1)],
               *[f"tau{i}" for i in range(1, n + 1)]]
    terms = sum(len(sp.Add.make_args(sp.expand(e))) for e in (*full.H, *full.C, *full.G))
    return Outcome(
        summary=f"{device.name}: tau = H(theta) thetadd + C(theta) thetad^2 + G(theta) (eq. 2.50), "
                f"{n} joints; the symbolic and compiled forms agree to {worst:.1e}.",
        paragraphs=[
            "H and G below are exact in the joint coordinates with the design's numbers substituted, shown "
            f"{READABLE} "
            "(`hapticdesign eom --symbolic none`). " + ctx.settings.design_note(),
            f"With every length and inertial parameter kept as a symbol (`--symbolic all`) the equations have "
            f"{terms} terms ({len(full_text)} characters of text).",
            f"Evaluations in SI units (rad or m, N m or N): joint rates {qd[0]} and accelerations {qdd[0]} on every joint.",
        ],
        listings=[(f"H, {READABLE}:", export(rounded(numeric, relative=READABLE_RELATIVE), "text", "H")),
                  (f"G, {READABLE}:", export(rounded(numeric, relative=READABLE_RELATIVE), "text", "G")),
                  ("H at q = 0 (compiled model):", matrix_text("H", mass_matrix(device, np.zeros(n))))],
        tables=[Table("evaluations", "H diagonal, G and tau at three poses", columns, rows)],
        numbers={"symbolic_terms": terms, "symbolic_characters": len(full_text), "max_symbolic_vs_compiled": worst,
                 "H_at_zero": mass_matrix(device, np.zeros(n))},
    )


def linearity_number(ctx: Context) -> Outcome:
    """Seed 000 eq. 3.1-3.4 on the torus (box regions for prismatic joints as the engine defines them)."""
    device = ctx.settings.device()
    parts = device_form(device).parts(device.standard_parameters())
    return Outcome(
        summary=f"{device.name}: LN = {parts.sum():.4g} (H {parts[0]:.3g}, C {parts[1]:.3g}, G {parts[2]:.3g}).",
        tables=[Table("parts", "Linearity Number and its parts", ["device", "LN", "H part", "C part", "G part"],
                      [[device.name, parts.sum(), *parts]])],
        numbers={"ln": float(parts.sum()), "ln_parts": dict(zip("HCG", map(float, parts)))},
    )


def link_table(device) -> list[list]:
    """Per body with mass: principal moments about the mass centre, positive definiteness, triangle inequality."""
    from hapticdesign.model.inertia import check_body

    rows = []
    for name in device.body_names:
        body = device.body(name)
        if body.m == 0:
            continue
        eig = np.linalg.eigvalsh(body.inertia_at_com)
        report = check_body(name, body)
        rows.append([name, body.m, *eig, bool(eig[0] > 0), bool(eig[0] + eig[1] >= eig[2] * (1 - 1e-12)),
                     report.error or report.warning or ""])
    return rows


def found_designs(ctx: Context, device, form, conditions, count: int = 3) -> Table:
    """Realizable fully linear designs from the engine (practical bounds, rigid-body realizability)."""
    try:
        designs = find(device, form, conditions, practical_bounds(device), count, ctx.settings.seed)
    except UserError as exc:  # none exists within the bounds (the verdict step says whether any exists at all)
        return Table("found", "Realizable fully linear designs within the practical bounds", ["result"], [[str(exc)]])
    names = device.inertial_names()
    shown = [k for k in names if k.startswith(("m", "r"))][:8]
    rows = []
    for i, seed in enumerate(designs):
        d = device.with_params(dict(zip(names, seed)))
        rows.append([f"L{i + 1}", float(form.ln_seed(seed)), all(r[5] and r[6] for r in link_table(d)),
                     *(seed[names.index(k)] for k in shown)])
    return Table("found", "Realizable fully linear designs found by the engine (practical bounds, eq. 3.29-3.32)",
                 ["design", "LN", "realizable", *shown], rows)


def linearization(ctx: Context) -> Outcome:
    """Seed 000 §3.2.1: the conditions for LN = 0 (eq. 3.12-3.26) in the seed's variables, the free
    parameters (Table 3.2), the constant H (eq. 3.27), the design's realizability and linear designs."""
    device = ctx.settings.device()
    if not has_trigonometric_basis(device.mechanism):
        raise Skipped("the conditions for LN = 0 (eq. 3.12-3.27) are linear equations in the coefficients of a tree's "
                      "exact trigonometric basis; a closed loop's H, C and G entries are not trigonometric polynomials "
                      "of the actuated joints (its LN, by quadrature, is in the Linearity Number step)")
    form = device_form(device)
    conditions = linear_conditions(device, form)
    try:
        solved = seed_conditions(device, conditions)
        listing = ("Conditions in the seed's variables:", "\n".join(f"{k} = {v}" for k, v in solved.solution.items()))
        free = f"Free parameters: {', '.join(str(s) for s in solved.free)}."
    except ValueError as exc:  # no one-at-a-time solution in the seed's variables: show the linear form
        listing = ("Conditions in the standard parameters (m, h = m r, J about the body frame origin):",
                   "\n".join(conditions.equations()))
        free = f"The engine could not rewrite them in the seed's variables ({exc})."
    pi = device.standard_parameters()
    h_const = conditions.constant_h @ pi
    ln = float(form.ln(pi))
    rng = np.random.default_rng(ctx.settings.seed)
    spread = max(float(np.abs(mass_matrix(device, q) - h_const).max()) for q in rng.uniform(-np.pi, np.pi, (20, device.n_dof)))
    rows = link_table(device)
    realizable = all(r[5] and r[6] for r in rows)
    linear = ln < 1e-12
    return Outcome(
        summary=f"LN = 0 is {len(conditions.pivots)} linear equations; {len(conditions.free)} standard parameters stay "
                f"free; the design has LN = {ln:.2g} and every link realizable: {realizable}.",
        paragraphs=[
            f"{len(conditions.pivots)} linear conditions in the standard inertial parameters (for the Phantom compare "
            "eq. 3.12-3.26).",
            free,
            (f"The design is fully linear: H stays within {spread:.1e} of the constant matrix of eq. 3.27 over 20 random "
             "poses." if linear else "The design is not fully linear; the matrix below is eq. 3.27 evaluated at its "
             "parameters, which H equals only on the solution set."),
            "Every link of the design is " + ("a realizable rigid body (positive definite, triangle inequality)."
                                              if realizable else "NOT a realizable rigid body: see the table."),
        ],
        listings=[listing,
                  ("Constant inertia matrix (eq. 3.27) at the design's parameters:", matrix_text("H", h_const))],
        tables=[Table("realizability", "Realizability of the design's links (principal moments about the mass centre)",
                      ["link", "m [kg]", "I1", "I2", "I3", "positive definite", "triangle inequality", "note"], rows),
                found_designs(ctx, device, form, conditions)],
        numbers={"conditions": len(conditions.pivots), "free_standard_parameters": len(conditions.free), "ln": ln,
                 "realizable": realizable, "h_constant_spread": spread if linear else None},
    )


def verdict(ctx: Context, device=None) -> Outcome:
    """Seed 000 §3.3, Appendix D: does a physically realizable design with LN = 0 exist? The verdict with its
    certificate, and the smallest LN under the practical bounds."""
    device = device or ctx.settings.device()
    form = device_form(device)
    found = decide(device, form)
    ctx.update(1, 2)
    lowest = minimum_ln(device, form, practical_bounds(device))
    ctx.update(2, 2)
    paragraphs = []
    rows = [["realizable design with LN = 0 exists", found.linear_possible],
            ["realizability condition", found.kind.value],
            ["minimum LN under the practical bounds", lowest.ln],
            ["convex lower bound on that minimum", lowest.lower_bound],
            ["minimizing design within the bounds", lowest.within_bounds]]
    if found.certificate is not None:
        cert = found.certificate
        rows += [["certificate: bodies carrying the dual blocks", ", ".join(cert.support())],
                 ["certificate: residual |sum tr(Z_i F_i)| per unit |z|_1", cert.residual],
                 ["certificate: smallest eigenvalue of the blocks", cert.min_eigenvalue()]]
        paragraphs.append("Certificate: positive semi-definite blocks Z_i (traces summing to 1) whose pairing with the "
                          "realizability matrices F_i vanishes on every fully linear design, so no fully linear design is "
                          "strictly realizable. Exact part: these diagonal entries of F_i vanish on every fully linear "
                          "design: " + ", ".join(f"body {b} entry ({k + 1},{k + 1})" for b, k in found.exact) + ".")
    return Outcome(
        summary=(f"{device.name}: a realizable fully linear design exists" if found.linear_possible else
                 f"{device.name}: no physically realizable design has LN = 0")
                + f"; smallest LN under the practical bounds {lowest.ln:.3g}.",
        paragraphs=paragraphs,
        tables=[Table("verdict", f"Verdict for {device.name}", ["item", "value"], rows)],
        numbers={"linear_possible": bool(found.linear_possible), "minimum_ln_practical": float(lowest.ln),
                 "minimum_ln_lower_bound": float(lowest.lower_bound)},
    )
