"""Manufacturing tolerances of the R-CUBE: seeded Monte Carlo (seed 001 ch. 8, future work).

Seed 001 ch. 8 asks for "sensitivity of the manipulator ... for possible dimensional errors which
may occur in manufacturing", to make sure that "the manufactured links does not cause any self
collision or singularity". Each sample gives every chain its own errors, drawn uniformly within
the tolerance band ``+-t``:

- link lengths ``l1, l2, l3`` of that chain (eq. 5.5-5.9);
- the position of its actuated joint (the chain base ``H(0,i0)`` of eq. 5.2; three components in
  the base frame; the one along the chain's own axis is an error of ``S``).

Length and base-position errors keep every joint axis direction, so each chain still moves the
platform in pure translation and decouples as in eq. 5.28-5.45: chain ``i`` is the nominal chain
with its own geometry, evaluated at the platform position minus its base's sideways error.
Angular errors of the joint axes are not modelled (they would let the platform rotate).

Per sample: ``K_C`` at home (eq. 5.121-5.123 with per-chain geometry), the share of the
workspace cube (a grid, §6.1.3) that stays reachable and regular (eq. 5.30, 5.39, 5.72-5.73), the
smallest singular value and the largest condition number of the chain Jacobians ``J_i``
(eq. 5.53-5.55) over that cube, and the smallest clearance between non-adjacent links, modelled
as capsules of the tubes' outer radii around the link axes.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from math import isfinite

import numpy as np

from hapticdesign.analysis.kinematics import poses_and_jacobians
from hapticdesign.errors import InputError, UserError
from hapticdesign.analysis.rcube.design import RCubeDesign
from hapticdesign.analysis.rcube.kinematics import chain_angles, chain_jacobian, cube_grid, passive_reach
from hapticdesign.analysis.rcube.stiffness import chain_stiffness_matrices
from hapticdesign.files import parse_structured, quote, read_text, save_figure as write_figure
from hapticdesign.model.rcube import RCubeGeometry, axis_permutation, chain_mechanism

SECONDS_PER_SAMPLE = 0.012
"""Measured fixed cost of one sample on the 2-core reference machine (s)."""
SECONDS_PER_GRID_POINT = 1.6e-5
"""Measured cost per sample and workspace grid point (s)."""
DEFAULT_MAX_SECONDS = 120.0
"""Runs estimated above this are refused unless the caller allows them."""
SINGULAR_TOLERANCE = 1e-6
"""``|cos q_i1|`` or ``|sin q_i3|`` below this counts as singular (eq. 5.72-5.73), as in the metric maps."""


@dataclass(frozen=True)
class Tolerances:
    """Half-widths ``+-t`` (m) of uniform manufacturing errors: link lengths ``l1, l2, l3`` and the
    position of each chain's actuated joint (each of its three components)."""

    lengths: tuple[float, float, float] = (0.0, 0.0, 0.0)
    joint_offset: float = 0.0

    def __post_init__(self) -> None:
        values = (*self.lengths, self.joint_offset)
        if len(self.lengths) != 3 or not all(isfinite(v) and v >= 0.0 for v in values):
            raise UserError(f"tolerances must be non-negative lengths in metres, got {values!r}")

    def check_design(self, design: RCubeDesign) -> None:
        """A one-line error unless every tolerance is below :data:`LARGEST_SHARE` of the link lengths it perturbs
        (the joint offset: of the shortest link), checked before a run is announced."""
        shortest = min(design.lengths)
        for name, t, length in (*zip(("l1", "l2", "l3"), self.lengths, design.lengths),
                                ("joint_offset", self.joint_offset, shortest)):
            if not t < LARGEST_SHARE * length:
                raise InputError(f"the tolerance of {name} must be below {LARGEST_SHARE:g} of the link length "
                                 f"{length:g} m (a manufacturing error, not another mechanism), got {t:g} m",
                                 f"tol_{name.replace('joint_offset', 'joint')}")


LARGEST_SHARE = 0.1
"""The largest tolerance as a share of a link's length: manufacturing tolerances are fractions of a per cent of it
(ISO 2768-m: 0.3 mm on 120 mm); at a link's own length the drawn mechanism has links of length 0 and no longer reaches
its home."""


TOLERANCE_KEYS = ("l1", "l2", "l3", "joint_offset")
"""Keys of a design file's ``tolerances`` mapping (m)."""


@dataclass(frozen=True)
class SampleErrors:
    """Errors of ``n`` samples: ``lengths (n, 3 chains, 3 links)`` and ``base (n, 3 chains, 3)`` (m)."""

    lengths: np.ndarray
    base: np.ndarray


def draw_errors(tolerances: Tolerances, samples: int, seed: int) -> SampleErrors:
    """Uniform errors within the tolerance bands from ``numpy.random.default_rng(seed)``."""
    if samples < 1:
        raise InputError(f"samples must be at least 1, got {samples}", "samples")
    rng = np.random.default_rng(seed)
    t = np.asarray(tolerances.lengths, dtype=float)
    lengths = rng.uniform(-1.0, 1.0, (samples, 3, 3)) * t
    base = rng.uniform(-1.0, 1.0, (samples, 3, 3)) * tolerances.joint_offset
    return SampleErrors(lengths, base)


def estimate_seconds(samples: int, grid: int) -> float:
    """Rough run time of :func:`monte_carlo` (s) from the measured per-sample costs."""
    return samples * (SECONDS_PER_SAMPLE + SECONDS_PER_GRID_POINT * grid**3)


def check_budget(samples: int, grid: int, max_seconds: float = DEFAULT_MAX_SECONDS, allow: bool = False) -> float:
    """Refuse a run estimated above ``max_seconds`` unless ``allow``; returns the estimate."""
    seconds = estimate_seconds(samples, grid)
    if seconds > max_seconds and not allow:
        raise InputError(
            f"{samples} samples on a {grid}^3 grid would take about {seconds:.0f} s (limit {max_seconds:.0f} s); "
            "lower the samples or the grid, or allow the long run",
            "samples", "grid", "allow_long",
        )
    return seconds


def chain_geometry(design: RCubeDesign, length_errors: np.ndarray, base_error: np.ndarray, chain: int) -> RCubeGeometry:
    """Chain ``chain``'s own geometry: perturbed lengths and ``S`` plus its base error along its axis."""
    g = design.geometry
    a = axis_permutation(chain)[0]
    l1, l2, l3 = (L + e for L, e in zip(design.lengths, length_errors))
    return RCubeGeometry(float(l1), float(l2), float(l3), float(g.S + base_error[a]), g.sigma)


def sideways(base_error: np.ndarray, chain: int) -> np.ndarray:
    """The base error across chain ``chain``'s axis: it shifts the positions the chain must reach."""
    out = np.array(base_error, dtype=float)
    out[axis_permutation(chain)[0]] = 0.0
    return out


def chain_reach(geometry: RCubeGeometry, chain: int, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(q (P, 3), reachable (P,))`` of one chain with its own geometry (eq. 5.30, 5.39-5.45)."""
    a = axis_permutation(chain)[0]
    ok = (np.abs((positions[:, a] - geometry.S) / geometry.l1) < 1.0)
    ok &= np.abs(passive_reach(geometry, positions)[:, chain]) < 1.0
    return chain_angles(geometry, chain, positions), ok


def chain_stiffness_at(design: RCubeDesign, geometry: RCubeGeometry, chain: int, position: np.ndarray) -> np.ndarray:
    """``K_Ci`` (6 x 6) of one chain with its own geometry (eq. 5.121-5.122) at ``position``."""
    return chain_stiffness_matrices(design.with_geometry(geometry), position)[chain]


def link_segments(geometry: RCubeGeometry, chain: int, q: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """Axes of links 1-3 as segments ``(P, 3 links, 2 ends, 3)`` from the chain's frames (eq. 5.5-5.18)."""
    mech = chain_mechanism(geometry, chain)
    points = [poses_and_jacobians(mech, q, f)[0][:, :3, 3] for f in ("link1", "tip1", "tip2", "tip3")]
    P = np.stack(points, axis=1) + shift
    return np.stack([P[:, :-1], P[:, 1:]], axis=2)


def segment_distance(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """Shortest distance between segments ``p0-p1`` and ``q0-q1`` (broadcast over leading axes).

    Minimizes ``|p0 + s u - q0 - t v|`` over ``s, t in [0, 1]``: the unconstrained minimum clipped to
    the square, then each edge of the square (the minimum of a convex quadratic lies either inside
    or on an edge).
    """
    u, v, w = p1 - p0, q1 - q0, p0 - q0
    a, b, c = (u * u).sum(-1), (u * v).sum(-1), (v * v).sum(-1)
    d, e = (u * w).sum(-1), (v * w).sum(-1)
    tiny = 1e-300
    den = a * c - b * b
    s_in = np.clip((b * e - c * d) / np.maximum(den, tiny), 0.0, 1.0)
    t_in = np.clip((a * e - b * d) / np.maximum(den, tiny), 0.0, 1.0)
    candidates = [(s_in, t_in)]
    for s_fix in (0.0, 1.0):
        candidates.append((np.full_like(a, s_fix), np.clip((e + b * s_fix) / np.maximum(c, tiny), 0.0, 1.0)))
    for t_fix in (0.0, 1.0):
        candidates.append((np.clip((b * t_fix - d) / np.maximum(a, tiny), 0.0, 1.0), np.full_like(a, t_fix)))
    dist = [np.linalg.norm(w + s[..., None] * u - t[..., None] * v, axis=-1) for s, t in candidates]
    return np.min(dist, axis=0)


def non_adjacent_pairs() -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """Pairs of (chain, link) that share no joint: within a chain links 1 and 3; across chains all
    pairs except the links 3, which meet at the platform."""
    links = [(i, j) for i in range(3) for j in range(3)]
    pairs = []
    for k, (i, j) in enumerate(links):
        for (m, n) in links[k + 1:]:
            if i == m and abs(j - n) == 1:
                continue
            if i != m and j == 2 and n == 2:
                continue
            pairs.append(((i, j), (m, n)))
    return pairs


def clearance(segments: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Smallest surface gap between non-adjacent link capsules per pose, ``segments (P, 3, 3, 2, 3)``."""
    gaps = []
    for (i, j), (m, n) in non_adjacent_pairs():
        s, t = segments[:, i, j], segments[:, m, n]
        gaps.append(segment_distance(s[:, 0], s[:, 1], t[:, 0], t[:, 1]) - radii[j] - radii[n])
    return np.min(gaps, axis=0)


@dataclass(frozen=True)
class SampleResult:
    """One mechanism: ``K_C`` at home, cube coverage, worst ``J_i`` over the cube, smallest clearance."""

    K_C: np.ndarray
    coverage: float
    min_singular_value: float
    max_condition: float
    singular_inside: bool
    min_clearance: float


def evaluate_sample(design: RCubeDesign, length_errors: np.ndarray, base_errors: np.ndarray,
                    side: float = 0.12, grid: int = 7) -> SampleResult:
    """All checks for one mechanism with per-chain errors ``(3, 3)`` and ``(3, 3)`` (m)."""
    home = design.geometry.home
    positions = cube_grid(design.geometry, side, grid).reshape(-1, 3)
    reach = np.ones(len(positions), dtype=bool)
    sigma_min = np.full(len(positions), np.inf)
    cond = np.ones(len(positions))
    regular = np.ones(len(positions), dtype=bool)
    segments = np.zeros((len(positions), 3, 3, 2, 3))
    K = np.zeros((6, 6))
    for i in range(3):
        g = chain_geometry(design, length_errors[i], base_errors[i], i)
        shift = sideways(base_errors[i], i)
        q, ok = chain_reach(g, i, positions - shift)
        reach &= ok
        regular &= (np.abs(np.cos(q[:, 0])) > SINGULAR_TOLERANCE) & (np.abs(np.sin(q[:, 2])) > SINGULAR_TOLERANCE)
        s = np.linalg.svd(chain_jacobian(g, i, q), compute_uv=False)
        sigma_min = np.minimum(sigma_min, s[:, -1])
        cond = np.maximum(cond, s[:, 0] / np.maximum(s[:, -1], 1e-300))
        segments[:, i] = link_segments(g, i, q, shift)
        K += chain_stiffness_at(design, g, i, home - shift)
    good = reach & regular
    radii = np.array([link.section.D / 2 for link in design.links])
    gap = clearance(segments[good], radii) if good.any() else np.array([np.nan])
    return SampleResult(
        K_C=K,
        coverage=float(good.mean()),
        min_singular_value=float(sigma_min[good].min()) if good.any() else 0.0,
        max_condition=float(cond[good].max()) if good.any() else float("inf"),
        singular_inside=bool(not good.all()),
        min_clearance=float(np.min(gap)),
    )


def nominal_errors() -> tuple[np.ndarray, np.ndarray]:
    """Zero errors: the nominal mechanism."""
    return np.zeros((3, 3)), np.zeros((3, 3))


def monte_carlo(design: RCubeDesign, tolerances: Tolerances, samples: int, seed: int,
                side: float = 0.12, grid: int = 7, report=None) -> list[SampleResult]:
    """Evaluate ``samples`` mechanisms with errors from ``default_rng(seed)``."""
    if grid < 2:
        raise InputError(f"grid must be at least 2, got {grid}", "grid")
    if not (isfinite(side) and side > 0.0):
        raise InputError(f"side must be a positive length, got {side!r}", "side")
    tolerances.check_design(design)
    errors = draw_errors(tolerances, samples, seed)
    out = []
    for k in range(samples):
        if report:
            report("samples", k, samples)
        out.append(evaluate_sample(design, errors.lengths[k], errors.base[k], side, grid))
    return out


def summarize(values: np.ndarray) -> dict[str, float]:
    """Mean, standard deviation (ddof = 1 when more than one value), minimum, maximum."""
    v = np.asarray(values, dtype=float)
    return {
        "mean": float(v.mean()),
        "std": float(v.std(ddof=1)) if len(v) > 1 else 0.0,
        "min": float(v.min()),
        "max": float(v.max()),
    }


def summary(nominal: SampleResult, results: list[SampleResult], load: float = 20.0) -> dict:
    """Spread of ``K_C`` (translational diagonal, eq. 6.54), of the deflection under ``load`` N along
    each axis, and the workspace, singularity and collision checks over all samples."""
    K = np.stack([r.K_C for r in results])
    F = np.zeros(6)
    deflection = []
    for axis in range(3):
        F[:] = 0.0
        F[axis] = load
        deflection.append(np.linalg.norm(np.linalg.solve(K, F)[:, :3], axis=-1))
    worst = np.max(deflection, axis=0)
    return {
        "samples": len(results),
        "load": load,
        "K_C_diagonal": {name: summarize(K[:, k, k]) for k, name in enumerate(("Kxx", "Kyy", "Kzz"))},
        "K_C_diagonal_nominal": [float(nominal.K_C[k, k]) for k in range(3)],
        "deflection_worst_axis": summarize(worst),
        "coverage": summarize([r.coverage for r in results]),
        "min_singular_value": summarize([r.min_singular_value for r in results]),
        "max_condition": summarize([r.max_condition for r in results]),
        "min_clearance": summarize([r.min_clearance for r in results]),
        "samples_singular_inside": int(sum(r.singular_inside for r in results)),
        "samples_colliding": int(sum(r.min_clearance < 0.0 for r in results)),
        "nominal": {
            "coverage": nominal.coverage, "min_singular_value": nominal.min_singular_value,
            "max_condition": nominal.max_condition, "min_clearance": nominal.min_clearance,
        },
    }


def with_tolerances(tolerances: Tolerances, lengths=None, joint_offset=None) -> Tolerances:
    """Override some tolerances (command-line values over the design file's)."""
    out = tolerances
    if lengths is not None:
        out = replace(out, lengths=tuple(float(v) for v in lengths))
    if joint_offset is not None:
        out = replace(out, joint_offset=float(joint_offset))
    return out


ISO_2768_MEDIUM = ((3e-3, 0.1e-3), (6e-3, 0.1e-3), (30e-3, 0.2e-3), (120e-3, 0.3e-3), (400e-3, 0.5e-3),
                   (1000e-3, 0.8e-3), (2000e-3, 1.2e-3))
"""ISO 2768-1 class m: (upper end of the nominal-length range, permissible deviation +-t), metres."""


def iso2768_medium(length: float) -> float:
    """General tolerance +-t of a linear dimension, ISO 2768-1 class m ("medium")."""
    for upper, t in ISO_2768_MEDIUM:
        if length <= upper:
            return t
    raise UserError(f"ISO 2768-m covers lengths up to 2 m, got {length!r}")


def default_tolerances(design: RCubeDesign) -> Tolerances:
    """ISO 2768-m general tolerances of the link lengths and of the offset ``S`` (the joint positions)."""
    return Tolerances(tuple(iso2768_medium(L) for L in design.lengths), iso2768_medium(design.geometry.S))


def tolerances_from_file(path, design: RCubeDesign) -> Tolerances:
    """The design file's ``tolerances: {l1, l2, l3, joint_offset}`` (m, each ``+-t >= 0``); missing keys
    take ISO 2768-m. The file is read as the design is (:func:`~.design_io.load_design`)."""
    data = parse_structured(read_text(path, "design file"), "yaml", str(path))  # JSON is YAML too
    base = default_tolerances(design)
    entry = data.get("tolerances", {}) if isinstance(data, dict) else {}
    if not isinstance(entry, dict):
        raise UserError(f"{path}: 'tolerances' must map {', '.join(TOLERANCE_KEYS)} to lengths in metres")
    unknown = sorted(map(str, set(entry) - set(TOLERANCE_KEYS)))
    if unknown:
        raise UserError(f"{path}: tolerances: unknown key(s) {', '.join(quote(k) for k in unknown[:5])}; use "
                        f"{', '.join(TOLERANCE_KEYS)}")
    defaults = dict(zip(TOLERANCE_KEYS, (*base.lengths, base.joint_offset)))
    values = {}
    for key in TOLERANCE_KEYS:
        value = entry.get(key, defaults[key])
        number = None if isinstance(value, bool) else _float_or_none(value)
        if number is None or not (isfinite(number) and number >= 0.0):
            raise UserError(f"{path}: tolerances.{key} must be a non-negative length in metres, got {quote(value)}")
        values[key] = number
    return Tolerances(tuple(values[k] for k in TOLERANCE_KEYS[:3]), values["joint_offset"])


def _float_or_none(value) -> float | None:
    try:
        return float(value)
    except (TypeError, ValueError):
        return None


def save_figure(nominal: SampleResult, results: list[SampleResult], path) -> None:
    """Histograms of the samples' ``K_xx``, worst ``J_i`` singular value, coverage and clearance."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [
        ("K_xx at home / nominal [-]", [r.K_C[0, 0] / nominal.K_C[0, 0] for r in results], 1.0),
        ("smallest singular value of J_i over the cube [mm/rad]",
         [r.min_singular_value * 1e3 for r in results], nominal.min_singular_value * 1e3),
        ("share of the workspace cube reachable and regular [-]", [r.coverage for r in results], nominal.coverage),
        ("smallest clearance between links [mm]", [r.min_clearance * 1e3 for r in results], nominal.min_clearance * 1e3),
    ]
    fig, axes = plt.subplots(2, 2, figsize=(8.0, 6.0))
    for ax, (label, values, ref) in zip(axes.ravel(), panels):
        ax.hist(values, bins=min(30, max(5, len(values) // 5)), color="0.6")
        ax.axvline(ref, color="k", lw=1.0, label="nominal")
        ax.set_xlabel(label, fontsize=8)
        ax.set_ylabel("samples")
        ax.legend(fontsize=7)
    fig.suptitle(f"R-CUBE manufacturing tolerances: {len(results)} samples", fontsize=10)
    fig.tight_layout()
    write_figure(fig, path, dpi=150)
    plt.close(fig)
