"""Method ``convex``: seed 000's LN minimization over inertial parameters as one exact convex program.

LN is a positive semi-definite quadratic form in the standard inertial parameters ``pi`` (seed 000 eq.
3.1-3.4, :mod:`hapticdesign.analysis.linearity.form`), and a body's realizability is a linear matrix
inequality in them (:mod:`hapticdesign.analysis.linearity.convex`): rigid-body (pseudo-inertia positive
semi-definite) or the seed's eq. 3.28 (positive definite inertia about the mass centre). A study whose one
objective is ``ln`` (``sense: min``) over inertial-parameter variables is therefore solved exactly by
:func:`~hapticdesign.analysis.linearity.verdict.minimum_ln`: each variable's ``[low, high]`` bounds its seed
variable (eq. 3.29-3.32 are such bounds), the parameters that are not variables stay at the device file's
values, and the program's relaxation gives a lower bound on the minimum (the run's ``notes["lower_bound"]``).

Expression constraints are kept when they are linear in ``pi``: a sum of masses (``m2 + m3a <= 0.4``), or
of one body's mass-centre coordinates (``r2x - r2y >= 0``, i.e. ``h2x - h2y >= 0 m2``). Anything else the
program cannot express is refused in one line: several objectives, another index, an index constraint, a
variable that is not an inertial parameter, a discrete choice, and a moment or product of inertia that stays
fixed while a mass-centre coordinate it depends on varies (``Iyy2`` fixed with ``r2x`` varying: the moment about
the frame origin, ``Iyy2 + m2 (r2x^2 + r2z^2)``, is then not convex in ``pi``).
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.linearity.bounds import SeedBox
from hapticdesign.analysis.linearity.convex import COUPLED
from hapticdesign.analysis.linearity.form import device_form
from hapticdesign.analysis.linearity.verdict import minimum_ln
from hapticdesign.errors import UserError
from hapticdesign.model.inertia import SEED_FIELDS, Realizability, seed_parameter_name
from hapticdesign.optimization.study_evaluation import BoundStudy
from hapticdesign.optimization.study_file import Choice, ExpressionConstraint, StudySpec
from hapticdesign.optimization.study_run import Answer, StudyRun, record_of


def _refuse(spec: StudySpec, bound: BoundStudy) -> None:
    """One-line refusals of what the convex program cannot do."""
    objectives = spec.objectives
    if len(objectives) != 1 or objectives[0].index != "ln" or objectives[0].sense != "min":
        raise UserError("method convex minimizes one objective, {index: ln, sense: min}; use method nsga2 for "
                        + ("several objectives" if len(objectives) != 1 else f"{objectives[0].sense} "
                           f"{objectives[0].index}"))
    if objectives[0].options:
        raise UserError("method convex: index ln takes no options")
    if spec.parameters or spec.keep:
        raise UserError("method convex: `parameters` and `keep` are settings of method nsga2 (the convex program "
                        "varies inertial parameters only and has one design)")
    others = [c.label for c in spec.constraints if not isinstance(c, ExpressionConstraint)]
    if others:
        raise UserError(f"method convex: constraint {others[0]} is an index; only affine expressions of masses or of "
                        "one body's mass-centre coordinates are convex in the inertial parameters (use method nsga2)")
    for v in bound.space.variables:
        if v.kind != "inertial":
            raise UserError(f"method convex: variable {v.name} is not an inertial parameter (LN is convex only in "
                            "those; use method nsga2)")
        if isinstance(spec.variables[v.name], Choice):
            raise UserError(f"method convex: variable {v.name} is a discrete choice; give it bounds [low, high]")


def _places(bound: BoundStudy) -> dict[str, tuple[int, int]]:
    """Each variable's (body index, seed field index) in the device."""
    bodies = bound.space.base.body_names
    out = {}
    for v in bound.space.variables:
        field = next(f for f in SEED_FIELDS if seed_parameter_name(f, v.target) == v.name)
        out[v.name] = (bodies.index(v.target), SEED_FIELDS.index(field))
    return out


def _boxes(spec: StudySpec, bound: BoundStudy, places: dict[str, tuple[int, int]]) -> dict[str, SeedBox]:
    """Each body with a variable: the variables' bounds, its other seed variables fixed at the file's values."""
    device = bound.space.base
    low: dict[int, np.ndarray] = {}
    high: dict[int, np.ndarray] = {}
    for name, (k, f) in places.items():
        if k not in low:
            body = device.body(device.body_names[k])
            low[k] = np.array([getattr(body, field) for field in SEED_FIELDS], dtype=float)
            high[k] = low[k].copy()
        low[k][f], high[k][f] = spec.variables[name]
    for name, (k, f) in places.items():  # a fixed moment or product of a varying mass centre is not convex
        if f in (1, 2, 3):
            body = device.body_names[k]
            for m, coupled in enumerate(COUPLED):
                moment = seed_parameter_name(SEED_FIELDS[4 + m], body)
                if f - 1 in coupled and moment not in places:
                    raise UserError(f"method convex: {moment} is fixed while {name} varies, which is not convex in the "
                                    f"inertial parameters; make {moment} a variable too, or fix {name}")
    boxes = {}
    for k in low:
        if high[k][0] <= 0:
            raise UserError(f"method convex: body {device.body_names[k]} needs a positive mass (its mass bounds or "
                            "value)")
        boxes[device.body_names[k]] = SeedBox(low[k], high[k])
    return boxes


def _affine(spec: StudySpec, places: dict[str, tuple[int, int]], n_params: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The expression constraints as ``A pi <= b`` (see the module), or a one-line refusal."""
    rows, limits = [], []
    for c in spec.constraints:
        parsed = c.parsed
        fields = {places[name][1] for name, _ in parsed.terms}
        bodies = {places[name][0] for name, _ in parsed.terms}
        row = np.zeros(n_params)
        if fields <= {0}:  # masses: linear as they are
            for name, coefficient in parsed.terms:
                row[10 * places[name][0]] += coefficient
            mass = None
        elif fields <= {1, 2, 3} and len(bodies) == 1:  # one body's r: sum c r <= b  <=>  sum c h <= b m
            for name, coefficient in parsed.terms:
                row[10 * places[name][0] + places[name][1]] += coefficient
            mass = 10 * bodies.pop()
        else:
            raise UserError(f"method convex: constraint {c.expression!r} is not convex in the inertial parameters; "
                            "only sums of masses, or of one body's mass-centre coordinates, are")
        for value, sign, _ in c.sides:
            limit = value - parsed.constant
            out = sign * row
            if mass is None:
                rows.append(out)
                limits.append(sign * limit)
            else:
                out[mass] -= sign * limit
                rows.append(out)
                limits.append(0.0)
    return (np.array(rows), np.array(limits)) if rows else None


def run_convex(bound: BoundStudy, seed: int) -> StudyRun:
    """The study's LN minimum as one evaluated design (the front when it is within the bounds and realizable),
    with the relaxation's lower bound; ``seed`` is kept for the record (the program is deterministic)."""
    spec = bound.study.spec
    _refuse(spec, bound)
    places = _places(bound)
    device = bound.space.base
    try:
        boxes = _boxes(spec, bound, places)
        affine = _affine(spec, places, 10 * len(device.body_names))
        result = minimum_ln(device, device_form(device), boxes, Realizability(spec.algorithm.realizability), affine)
    except UserError as exc:
        raise UserError(f"{bound.study.path}: {exc}") from None
    values = {name: float(result.design[k, f]) for name, (k, f) in places.items()}
    reason = ("" if result.within_bounds and result.realizable else
              f"the solver's design is {'not within the bounds' if not result.within_bounds else 'not realizable'}")
    x = [values[name] for name in spec.variables]
    record = record_of(spec, 1, x, values, Answer((result.ln,), reason))
    return StudyRun(spec, seed, [record], [0] if record.feasible else [], notes={"lower_bound": result.lower_bound})


def ln_of(bound: BoundStudy, values: dict[str, float]) -> Answer:
    """The LN of the design of variable ``values`` over the program's region (the device's joint limits), exactly as
    the program's design is evaluated (:func:`run_convex`): the device file's design beside it."""
    try:
        device = bound.space.device(bound.device_values(values))
    except UserError as exc:
        return Answer((np.nan,), str(exc))
    return Answer((float(device_form(device).ln(device.standard_parameters())),))
