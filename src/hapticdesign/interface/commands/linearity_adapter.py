"""The Linearity Number commands' work: resolve the device, run the engines, shape and write the output.

The engines live in :mod:`hapticdesign.analysis.linearity`; this module parses the command-line
options (its errors name the flags), writes the files and formats the text. The commands in
:mod:`.linearity` import it when they run, so ``hapticdesign --help`` does not load the solvers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hapticdesign.analysis.dynamics.model import has_trigonometric_basis
from hapticdesign.analysis.linearity.bounds import practical_bounds
from hapticdesign.analysis.linearity.closed_form import closed_form
from hapticdesign.analysis.linearity.conditions import linear_conditions, seed_conditions
from hapticdesign.analysis.linearity.design_sets import DesignSet, Method, design_set
from hapticdesign.analysis.linearity.form import PARTS, LinearityForm, device_form
from hapticdesign.analysis.linearity.linear_designs import find_linear_designs
from hapticdesign.analysis.linearity.region import resolve_region
from hapticdesign.analysis.linearity.verdict import decide_linearizable, minimum_ln, scaled_minimum
from hapticdesign.analysis.linearity.weights import read_weights
from hapticdesign.devices.loading import resolve_device
from hapticdesign.errors import UserError
from hapticdesign.files import write_atomically
from hapticdesign.model.inertia import Realizability
from hapticdesign.workload import require_designs


@dataclass(frozen=True)
class LNResult:
    device: str
    region: str
    ln: float
    parts: dict[str, float]


def _device_and_form(preset, device_file, params_file, strict, region_text, weights_file):
    """The device the options name, its LN region (default: its joint limits) and its LN form."""
    device = resolve_device(preset, device_file, params_file, strict)
    region = resolve_region(region_text, device.joint_limits())
    weights = read_weights(weights_file, device.n_dof) if weights_file is not None else None
    return device, region, device_form(device, region, weights)


def evaluate_ln(
    preset: str | None,
    device_file: Path | None,
    params_file: Path | None,
    strict: bool,
    region_text: str | None,
    weights_file: Path | None,
) -> LNResult:
    device, region, form = _device_and_form(preset, device_file, params_file, strict, region_text, weights_file)
    parts = form.parts(device.standard_parameters())
    return LNResult(
        device.name,
        region.describe(device.mechanism.coordinates),
        float(parts.sum()),
        {k: float(v) for k, v in zip(PARTS, parts)},
    )


def symbolic_ln(
    preset: str | None,
    device_file: Path | None,
    params_file: Path | None,
    strict: bool,
    region_text: str | None,
    weights_file: Path | None,
    fmt: str,
    part: str,
    symbolic_gravity: bool,
) -> str:
    """The closed-form LN (Appendix B.1 / B.2 equivalent) as text, LaTeX or Python source."""
    device, _, form = _device_and_form(preset, device_file, params_file, strict, region_text, weights_file)
    return closed_form(device, form, symbolic_gravity).export(fmt, part)


def require_seed(seed: int) -> None:
    """Random seeds are non-negative integers (NumPy's ``default_rng`` refuses others)."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise UserError(f"the random seed must be a non-negative integer, got {seed!r}")


def parse_realizability(text: str) -> Realizability:
    choices = {"rigid-body": Realizability.RIGID_BODY, "seed": Realizability.POSITIVE_DEFINITE}
    if text not in choices:
        raise UserError(f"--realizability: choose rigid-body or seed, got {text!r}")
    return choices[text]


def parse_levels(text: str) -> tuple[float, ...]:
    try:
        levels = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise UserError(f"--levels: expected comma-separated numbers, got {text!r}") from None
    if not levels:
        raise UserError("--levels: give at least one level")
    for level in levels:
        if not math.isfinite(level) or level < 0:
            raise UserError(f"--levels: LN levels must be finite and >= 0, got {level:g}")
    return levels


def require_tree(device, command: str) -> None:
    """Refuse ``linearize``/``designs`` on a device with closed loops, before any work.

    The conditions for LN = 0 (seed 000 eq. 3.12-3.27) are linear equations in the coefficients of
    the exact trigonometric basis of a tree's H, C and G; a closed loop's entries are not
    trigonometric polynomials of the actuated joints, so those equations do not exist (its LN,
    from converged quadrature, is what ``ln`` gives).
    """
    if not has_trigonometric_basis(device.mechanism):
        raise UserError(
            f"{command} needs a tree device: {device.name} has closed loops, whose equations of motion have no exact "
            "trigonometric basis for the LN = 0 conditions (eq. 3.12-3.27); 'hapticdesign ln' gives its LN"
        )


def _designs_csv(names: list[str], designs: np.ndarray, form: LinearityForm, level: float = 0.0) -> str:
    parts = form.parts_seed(designs)
    return DesignSet(np.full(len(designs), level), parts, designs).to_csv(names)


def linearize(
    preset: str | None,
    device_file: Path | None,
    params_file: Path | None,
    strict: bool,
    find: int,
    seed: int,
    out: Path | None,
    realizability: str,
) -> dict:
    """``hapticdesign linearize`` as data: the conditions for LN = 0, then the seed-variable solution,
    free parameters and constant H (eq. 3.12-3.27), or the verdict with its certificate and the
    minimum LN (eq. 3.40-3.42) when no realizable design is fully linear."""
    kind = parse_realizability(realizability)
    if find < 0:
        raise UserError("--find: the number of designs must be >= 0")
    require_seed(seed)
    require_designs(f"finding {find:,} fully linear designs", find, "linear")
    device = resolve_device(preset, device_file, params_file, strict)
    require_tree(device, "linearize")
    form = device_form(device)
    conditions = linear_conditions(device, form)
    result: dict = {"device": device.name, "conditions": conditions.equations()}
    verdict = decide_linearizable(device, form, kind)
    result["linear_possible"] = verdict.linear_possible
    names = device.inertial_names()
    if not verdict.linear_possible:
        cert = verdict.certificate
        mins = minimum_ln(device, form, practical_bounds(device), kind)
        result["verdict"] = {
            "realizability": kind.value,
            "certificate": {"bodies": cert.support(), "min_eigenvalue": cert.min_eigenvalue(), "residual": cert.residual},
            "exact": [{"body": body, "entry": k + 1} for body, k in verdict.exact],
            "minimum_ln": {"ln": mins.ln, "lower_bound": mins.lower_bound, "within_bounds": mins.within_bounds,
                           "realizable": mins.realizable, "design": dict(zip(names, mins.design.ravel()))},
            "scaled_minimum_ln": scaled_minimum(device, mins),
        }
        return result
    solved = seed_conditions(device, conditions)
    pi = device.standard_parameters()
    result.update(
        seed_conditions={str(k): str(v) for k, v in solved.solution.items()},
        free_parameters=[s.name for s in solved.free],
        constant_H=conditions.constant_h @ pi,
        ln=form.ln(pi),
    )
    if find:
        designs = find_linear_designs(device, form, conditions, practical_bounds(device), find, seed, kind)
        text = _designs_csv(names, designs, form)
        result["designs"] = {"count": find, "max_ln": form.ln_seed(designs).max()}
        if out is None:
            result["designs"]["values"] = [dict(zip(names, row)) for row in designs]
            result["designs"]["csv"] = text
        else:
            write_atomically(out, text)
            result["designs"]["path"] = str(out)
    return result


def linearize_report(result: dict) -> list[str]:
    """Text of ``hapticdesign linearize`` from :func:`linearize`'s result."""
    lines = [f"device {result['device']}: LN = 0 exactly when these {len(result['conditions'])} linear equations hold",
             "in the standard parameters (m, h = m r, J about the body frame origin):"]
    lines += ["  " + eq for eq in result["conditions"]]
    if not result["linear_possible"]:
        v = result["verdict"]
        cert, mins = v["certificate"], v["minimum_ln"]
        lines += [
            "",
            f"verdict: NO realizable ({v['realizability']}) design with LN = 0 exists (any bounds, incl. eq. 3.40-3.42).",
            f"certificate: PSD blocks Z_i on bodies {', '.join(cert['bodies'])} (sum of traces 1, smallest eigenvalue "
            f"{cert['min_eigenvalue']:.2e}) with |sum_i tr(Z_i F_i(pi))| <= {cert['residual']:.2e} |z|_1 on every fully",
            "  linear design pi = N z; hence min_i lambda_min(F_i(pi)) <= that bound, i.e. no strictly realizable one.",
            "exact certificate (Z = e_k e_k^T): these diagonal entries of the realizability matrix vanish on every",
            "  fully linear design: " + ", ".join(f"body {e['body']} entry ({e['entry']},{e['entry']})" for e in v["exact"]),
            f"minimum LN under practical bounds: {mins['ln']:.6g} (convex lower bound {mins['lower_bound']:.6g}); "
            f"design within bounds: {mins['within_bounds']}, realizable ({v['realizability']}): {mins['realizable']}",
            "  design (seed variables):",
        ]
        lines += [f"    {n} = {x:.8g}" for n, x in mins["design"].items()]
        lines.append("minimum LN under eq. 3.40-3.42: 0 is the infimum (LN scales with the square of the inertial")
        lines.append(f"  parameters), e.g. {v['scaled_minimum_ln']:.3g} with the design above scaled to the 1e-15 bounds; never attained.")
        return lines
    lines += ["", "in the seed's design variables (cf. eq. 3.12-3.26):"]
    lines += [f"  {k} = {x}" for k, x in result["seed_conditions"].items()]
    free = result["free_parameters"]
    lines += ["", f"free parameters ({len(free)}, cf. Table 3.2): " + ", ".join(free)]
    lines += ["", "constant inertia matrix on the solution set (eq. 3.27), for the current parameters:"]
    lines += ["  [" + ", ".join(f"{x:.6g}" for x in row) + "]" for row in result["constant_H"]]
    lines.append(f"current LN = {result['ln']:.3g}")
    designs = result.get("designs")
    if designs:
        if "path" in designs:
            lines.append(f"wrote {designs['count']} realizable fully linear designs (max LN {designs['max_ln']:.2g}) to {designs['path']}")
        else:
            lines += ["", designs["csv"].rstrip()]
    return lines


def write_design_set(
    preset: str | None,
    device_file: Path | None,
    params_file: Path | None,
    strict: bool,
    levels_text: str,
    count: int,
    seed: int,
    out: Path,
    method: str,
    realizability: str,
) -> str:
    kind = parse_realizability(realizability)
    levels = parse_levels(levels_text)
    try:
        chosen = Method(method)
    except ValueError:
        raise UserError(f"--method: choose fast or de, got {method!r}") from None
    if count < 1:
        raise UserError("--count: the number of designs per level must be at least 1")
    require_seed(seed)
    require_designs(f"a design set of {count:,} designs at each of {len(levels)} levels ({chosen.value} method)",
                    count * len(levels), chosen.value)
    device = resolve_device(preset, device_file, params_file, strict)
    require_tree(device, "designs")
    form = device_form(device)
    conditions = linear_conditions(device, form)
    result = design_set(device, form, conditions, practical_bounds(device), levels, count, seed, chosen, kind)
    write_atomically(out, result.to_csv(device.inertial_names()))
    return f"wrote {len(result.levels)} designs ({count} per level at {', '.join(f'{v:g}' for v in levels)}) to {out}"
