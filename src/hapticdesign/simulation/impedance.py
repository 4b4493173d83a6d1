"""Stable impedance range of one joint (seed 000 §4.1.2-4.1.3, Tables 4.1-4.3).

A virtual spring ``K`` on the wall joint (equilibrium 0.01 rad, start 0) is stable when
- the peak excursion from the start stays below ``overshoot_limit`` (0.012 rad: the seed's
  "overshoot" and the safety switch's 0.06 rad = 5 x 0.012 are both measured from the joint's
  reference point, so 0.012 rad is a 20 % overshoot of the 0.01 rad step; our reading),
- the response has settled at the end: in the last ``settle_window`` seconds the joint stays
  within ``settle_tolerance`` of the equilibrium,
- the safety switch (0.06 rad) has not tripped and the simulation has not diverged,
- where the loop linearized at the start pose gives the exact local growth boundary (type 1, and type
  2 when the driven motion does not reach the wall joint's equations, e.g. LN = 0 designs), the
  linearized sampled loop does not grow (spectral radius below 1): a stiffness above the growth
  boundary is not stable even when a slow growth stays inside the criteria for the run's duration.

The limits are stated for the seed's 0.01-rad step and scale with the wall's step
(:meth:`~.criteria.Criteria.for_step`).

The seed scans K = 1, 2, 3, ... and reports the last stable K. :func:`fast_search` returns the
same answer with an exponential bracket and a bisection over integers whenever the stable set
is ``{1, ..., K_max}`` (monotone criterion; the tests compare both on several designs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from hapticdesign.analysis.configuration import configuration_of, handle_pose
from hapticdesign.analysis.dynamics.device import gravity_gradient, mass_matrix
from hapticdesign.analysis.sampled_loop import SampledLoop, handle_intervals
from hapticdesign.analysis.stiffness.drive import device_drive
from hapticdesign.errors import InputError, UserError
from hapticdesign.model.compensator_model import model_device
from hapticdesign.model.device import Device
from hapticdesign.simulation.analytic import GROWS, AnalyticProblem, linear_loop
from hapticdesign.simulation.boundary import envelope_grows, growth_onset
from hapticdesign.simulation.config import (
    REST_STEPS, LoopConfig, Wall, compensator_device, handle_jacobian, loop_model, normal_jacobian, renamed,
    require_device, require_options, rest_pose, spring_rest, unit_direction,
)
from hapticdesign.simulation.loop import simulate, tables_of
from hapticdesign.simulation.criteria import Criteria, Verdict, WallProblem, require_closed, type_paths
from hapticdesign.simulation.paths import Held
from hapticdesign.workload import require_plant_steps


def wall_rest(trace, wall: Wall) -> float:
    """Where the wall's spring rests: the joint angle ``equilibrium``, or ``equilibrium`` metres along a
    Cartesian wall's direction from the handle's start (the first recorded row)."""
    return float(trace.wall_position[0]) + wall.equilibrium if wall.cartesian else wall.equilibrium


@dataclass
class ImpedanceProblem(WallProblem):
    """One device, one simulation type: runs single gains and caches the dynamics tables."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.rest = rest_pose(self.device)
        self.paths = type_paths(self.sim_type, self.device.n_dof, self.wall_joint, self.rest)
        self.plant = tables_of(self.device)
        self.model = tables_of(compensator_device(self.device, self.config))
        self.config = replace(self.config, safety_limit=self.criteria.safety_limit,
                              stop_excursion=self.criteria.overshoot_limit)

    @cached_property
    def linear(self) -> AnalyticProblem | None:
        """The linearized loop where its growth decides the wall's stability
        (:attr:`.AnalyticProblem.growth_is_exact`), else None; built at the first verdict that needs it (along
        a driven motion that costs a few tenths of a second)."""
        if not linear_loop(self.device, self.config):
            return None
        linear = AnalyticProblem(self.device, self.sim_type, self.wall_joint, self.equilibrium, self.criteria,
                                 self.config)
        return linear if linear.growth_is_exact else None

    def estimate(self) -> float:
        """Starting guess: the 1-DOF limit ``b^2 / H_ww`` of full inertial compensation at the start
        pose (see :mod:`.boundary`), or ``2 b / T`` without it, divided by ``J_n,w^2`` for a Cartesian
        wall; only a guess, never the answer."""
        w = self.wall_joint
        q0 = self.rest
        b = (self.config.damping or self.device.damping)[w]
        h = mass_matrix(self.device, q0)[w, w]
        guess = b * b / h if self.config.switches[0] else 2 * b / self.config.loop.period
        if self.config.wall.cartesian:
            guess /= float(normal_jacobian(self.device, self.config.wall, q0)[w]) ** 2
        return guess if math.isfinite(guess) and guess > 0 else 1.0

    @property
    def wall_equilibrium(self) -> float:
        """Where a joint wall's spring rests: ``equilibrium`` from the rest pose (absolute for an open chain,
        whose rest pose is 0); a Cartesian wall's equilibrium is already relative to the handle's start."""
        return self.equilibrium + (0.0 if self.config.wall.cartesian else float(self.rest[self.wall_joint]))

    def verdict(self, stiffness: float) -> Verdict:
        """Simulate the wall at ``stiffness`` and apply the criteria."""
        cfg = replace(self.config, wall=replace(self.config.wall, joint=self.wall_joint, stiffness=float(stiffness),
                                                equilibrium=self.wall_equilibrium))
        trace = simulate(self.device, cfg, self.paths, plant=self.plant, model=self.model)
        require_closed(trace, f"type {self.sim_type} at K = {stiffness:g}")
        peak = trace.peak
        if trace.diverged or not math.isfinite(peak):
            return Verdict(stiffness, False, "diverged", peak, math.nan, trace.end_time)
        if trace.stopped_at_excursion or peak >= self.criteria.overshoot_limit:
            stopped = trace.end_time if trace.stopped_at_excursion else None
            return Verdict(stiffness, False, "overshoot", peak, math.nan, stopped)
        tail = trace.wall_position[trace.t >= trace.t[-1] - self.criteria.settle_window]
        final = float(np.max(np.abs(tail - wall_rest(trace, cfg.wall))))
        if trace.tripped:
            return Verdict(stiffness, False, "safety switch", peak, final)
        if final > self.criteria.settle_tolerance:
            return Verdict(stiffness, False, "not settled", peak, final)
        if self.linear is not None and self.linear.grows(stiffness):
            return Verdict(stiffness, False, GROWS, peak, final)
        return Verdict(stiffness, True, "stable", peak, final)


@dataclass(frozen=True)
class StabilityLimit:
    """The exact stability limit of a wall (N/m along a Cartesian wall, N m/rad or N/m on a joint) under the loop
    settings ``loop``, linearized at ``pose``, the pose the wall holds (actuated coordinates), and ``lower``, the
    softest stable spring: 0, or above it where gravity pulls the handle off the wall faster than the loop holds it
    (over-compensation, an inverted pose), so that only springs from ``lower`` to ``stiffness`` are stable."""

    stiffness: float
    pose: np.ndarray
    loop: SampledLoop
    lower: float = 0.0


def wall_pose(device: Device, wall_joint: int = 0, equilibrium: float = 0.01, direction=None) -> np.ndarray:
    """The pose the wall holds, from the rest pose (:func:`~.config.rest_pose`): the wall joint moved by
    ``equilibrium`` for a joint wall; for a Cartesian wall the handle moved ``equilibrium`` metres along the
    direction, by inverse kinematics from the rest pose (closed loops closed; to first order in the equilibrium the
    pose a free handle comes to rest at)."""
    rest = rest_pose(device)
    if direction is None:
        pose = rest.copy()
        pose[wall_joint] += equilibrium
        return pose
    start = configuration_of(device).pose(rest)[:3, 3]
    return handle_pose(device, start + equilibrium * unit_direction(direction), start=rest).q


def stability_limit(device: Device, loop: SampledLoop | None = None, wall_joint: int = 0, equilibrium: float = 0.01,
                    direction=None, k_max: float = 1e9) -> StabilityLimit:
    """The exact stability limit of a wall on ``wall_joint`` (or along the Cartesian ``direction`` at the handle)
    with every actuated joint free but ``loop.held``, linearized where the wall holds the device
    (:func:`hapticdesign.analysis.sampled_loop.handle_intervals`; gravity through its gradient there, the share the
    compensator leaves and the one it feeds back late). Coulomb friction and quantization are left out: this is the
    limit of the loop's linear part.

    Where the wall holds the device: at its spring's rest (:func:`wall_pose`) when gravity is compensated exactly
    (the default). Otherwise the gravity the compensator leaves (none, or a model error) presses the handle into the
    spring, and it rests where the spring balances that torque along the wall (:func:`~.config.spring_rest`); the pose depends
    on the spring, so the limit is the fixed point ``K = limit(pose(K))``, found by iterating from the spring's rest
    (at most :data:`~.config.REST_STEPS` times, to ``1e-9 K``). Along the wall nothing but gravity's own stiffness resists
    the leftover torque: there the handle drifts (the neutral motion the loop deflates), as without a hand it
    would."""
    require_device(device)
    loop = loop or SampledLoop()
    rest = wall_pose(device, wall_joint, equilibrium, direction)
    pose, found = rest, None
    exact = loop.compensation != "none" and loop.error_percent == 0.0
    for _ in range(1 if exact else REST_STEPS):
        low, high = wall_interval(device, pose, loop, wall_joint, direction, k_max)
        settled = found is not None and abs(high - found.stiffness) <= 1e-9 * found.stiffness
        found = StabilityLimit(high, pose, loop, low)
        if settled or not (0.0 < high < np.inf):
            break
        model = None if loop.compensation == "none" else model_device(device, loop.error_percent)
        moved = spring_rest(device, model, rest, _wall_row(device, rest, wall_joint, direction), high,
                            [j for j in range(device.n_dof) if j not in set(loop.held)])
        if moved is None:
            break
        pose = moved
    return found


def wall_interval(device: Device, pose: np.ndarray, loop: SampledLoop, wall_joint: int = 0, direction=None,
                  k_max: float = 1e9) -> tuple[float, float]:
    """The exact stable springs ``[low, high]`` of a wall on ``wall_joint`` (or along the Cartesian ``direction``) held
    at ``pose``, every actuated joint free but ``loop.held`` (:func:`stability_limit`'s at one pose; ``low`` 0 unless
    gravity pulls the handle off the wall)."""
    jv = handle_jacobian(device, pose)[:3][None]
    low, high = handle_intervals(jv, mass_matrix(device, pose)[None],
                                 device.damping_matrix, _wall_row(device, pose, wall_joint, direction)[None], loop,
                                 k_max=k_max, gravity=gravity_gradient(device, pose)[None],
                                 model=loop_model(device, loop, pose),
                                 transmission=device_drive(device, configuration_of(device).full(pose)[None], jv))
    return float(low[0]), float(high[0])


def _wall_row(device: Device, pose: np.ndarray, wall_joint: int, direction) -> np.ndarray:
    """The wall's row ``w`` at ``pose``: ``e_j`` on a joint, ``n^T J_v`` along a Cartesian direction ``n``."""
    if direction is None:
        return np.eye(device.n_dof)[wall_joint]
    jv = handle_jacobian(device, pose)[:3]
    row = unit_direction(direction) @ jv
    if not np.linalg.norm(row) > 1e-12 * max(np.linalg.norm(jv), 1e-300):
        raise UserError("the handle does not move along the wall's direction at the pose the wall holds")
    return row


def device_counts(device: Device) -> int | None:
    """The encoder counts per joint revolution the simulation quantizes with: the coarsest of the device's motors
    (``cpr`` x quadrature x gear ratio), None when a motor states no encoder."""
    counts = [a.counts_per_radian for a in device.actuators]
    if not counts or any(c is None for c in counts):
        return None
    return max(1, int(round(2.0 * math.pi * min(counts))))


ESCAPE = 10.0
"""A simulated wall whose coordinate leaves its start by this many times the spring's rest has grown."""


def simulated_limit(device: Device, loop: SampledLoop | None = None, wall_joint: int = 0, equilibrium: float = 0.01,
                    direction=None, counts: int | None = None, duration: float = 2.0, rel_tol: float = 1e-2,
                    start: float | None = None, k_limit: float = 1e7, friction: bool = True,
                    pose: np.ndarray | None = None) -> float:
    """The simulated growth boundary of the wall, every joint free but ``loop.held``: the device's Coulomb friction
    (smoothed, :data:`~.config.FRICTION_VELOCITY`) and ``counts`` (encoder quantization) in the loop, the spring
    bisected (to ``rel_tol``) on the growth of the wall coordinate's oscillation about its rest over ``duration``
    (the last quarter's envelope against the second's; a run leaving the start by :data:`ESCAPE` times the rest's
    distance grows, whatever pose it wanders to and settles at); ``friction`` False leaves the device's friction out;
    ``pose`` the actuated pose the runs start at (default: :func:`~.config.rest_pose`). Where the loop is linear it
    converges to :func:`stability_limit` (the tests check it). ``start``: the first stiffness tried (default: the
    exact limit of the linear part at the rest pose); inf when nothing up to ``k_limit`` grows."""
    loop = loop or SampledLoop()
    rest = rest_pose(device) if pose is None else np.asarray(pose, dtype=float)
    paths = {j: Held(float(rest[j])) for j in loop.held}
    if direction is not None:
        direction = tuple(unit_direction(direction).tolist())
    wall = Wall(wall_joint, 1.0, equilibrium=equilibrium + (0.0 if direction else float(rest[wall_joint])),
                direction=direction)
    base = LoopConfig(duration=duration, loop=loop, wall=wall, counts=counts, safety_limit=None,
                      stop_excursion=ESCAPE * abs(equilibrium) if equilibrium else 1e-3,
                      coulomb=None if friction else (0.0,) * device.n_dof)
    plant, model = tables_of(device), tables_of(compensator_device(device, base))

    def grows(k: float) -> bool:
        cfg = replace(base, wall=replace(base.wall, stiffness=k))
        trace = simulate(device, cfg, paths, q0=rest, plant=plant, model=model)
        if trace.status != 0:  # diverged, or a closed-loop device's growing motion left the assembly branch
            return True
        return envelope_grows(trace.wall_position - wall_rest(trace, cfg.wall))

    k = start if start is not None else stability_limit(device, loop, wall_joint, equilibrium, direction).stiffness
    k = min(max(k, 1e-6), k_limit) if math.isfinite(k) else k_limit
    if not grows(k):
        return growth_onset(grows, k, 2.0 * k, rel_tol, k_limit)
    lo, hi = 0.0, k
    while lo == 0.0 and hi > 1e-6:
        if grows(hi / 2.0):
            hi /= 2.0
        else:
            lo = hi / 2.0
    return growth_onset(grows, lo, hi, rel_tol, k_limit, hi_grows=True)


@dataclass(frozen=True)
class RangeResult:
    """The maximum stable impedance (0 when no grid value passes) and the first failing verdict.

    ``k_min`` is the lowest passing grid value (``None`` when none passes); ``resolution`` the grid
    spacing (1 for the seed's integer scan).
    """

    k_max: float
    criterion: str
    simulations: int
    first_unstable: Verdict | None
    method: str
    k_min: float | None = None
    resolution: float = 1.0
    exact: bool | None = None
    """For the analytic method: whether the linearized loop is exact for this device and type."""
    k_true_boundary: float | None = None
    """The oscillation-growth boundary (:func:`growth_boundary`), when asked for."""
    limit: StabilityLimit | None = None
    """For the ``limit`` method: the stability limit itself (off the grid) and where it was taken."""

    @property
    def verdict(self) -> str:
        """What decided ``k_max``: the stability limit of the sampled loop, or the seed's performance criteria."""
        if self.method == "limit":
            return "stability limit (spectral radius of the sampled loop at the wall's equilibrium)"
        return "seed performance criteria (overshoot, settling, safety switch; seed 000 §4.1.2)"

    def as_dict(self) -> dict:
        first = self.first_unstable
        extra = {} if self.exact is None else {"analytic_exact": self.exact}
        if self.limit is not None:
            extra = {"k_limit_exact": self.limit.stiffness, "k_limit_lower": self.limit.lower,
                     "pose": self.limit.pose.tolist(), "settings": self.limit.loop.as_dict()}
        return {
            "verdict": self.verdict,
            **extra,
            "k_max": float(self.k_max),
            "k_min": self.k_min,
            "resolution": self.resolution,
            "criterion": first.criterion if first else "none (limit reached)",
            "first_unstable_k": None if first is None else float(first.stiffness),
            "peak_at_first_unstable": None if first is None or math.isnan(first.peak) else first.peak,
            "stopped_at_first_unstable": None if first is None else first.stopped_at,
            "simulations": self.simulations,
            "method": self.method,
            **({} if self.k_true_boundary is None else {"k_true_boundary": self.k_true_boundary
                                                        if math.isfinite(self.k_true_boundary) else None}),
        }


def planned_simulations(method: str, k_limit: float, resolution: float | None = None,
                        true_boundary: bool = False) -> int:
    """The most simulations a search can run: gallop and bisect (fast, grid), one per K (linear)."""
    if resolution is not None:
        runs = 6 * math.ceil(math.log2(max(k_limit / resolution, 1.0) + 1)) + 2
    elif method == "linear":
        runs = max(int(k_limit), 1)
    else:
        runs = 4 * math.ceil(math.log2(max(k_limit, 1) + 1)) + 2
    return runs + (40 if true_boundary else 0)


def require_search_workload(config: LoopConfig, runs: int) -> None:
    """Refuse a search whose plant steps (runs x duration / step) exceed the workload limit."""
    steps = config.duration / config.step
    require_plant_steps(f"{runs:,} simulations of {config.duration:g} s at a plant step of {config.step:g} s",
                        runs * steps)


def linear_scan(problem: ImpedanceProblem, k_limit: int = 200) -> RangeResult:
    """The seed's method: K = 1, 2, 3, ... until a criterion fails; the previous K is the maximum."""
    for k in range(1, k_limit + 1):
        v = problem.verdict(k)
        if not v.stable:
            return RangeResult(k - 1, v.criterion, k, v, "linear", 1.0 if k > 1 else None)
    return RangeResult(k_limit, "none", k_limit, None, "linear", 1.0)


def fast_search(problem: ImpedanceProblem, k_limit: int = 200, start: int | None = None) -> RangeResult:
    """Same answer as :func:`linear_scan` for a monotone criterion, in a few runs.

    Gallops with doubling steps from ``start`` (default: :meth:`ImpedanceProblem.estimate`) to a
    stable/unstable pair, then bisects over the integers between them.
    """
    runs = 0

    def check(k: int) -> Verdict:
        nonlocal runs
        runs += 1
        return problem.verdict(k)

    k = min(max(1, start if start is not None else int(problem.estimate())), k_limit)
    v = check(k)
    step = 1
    if v.stable:
        good, bad, bad_verdict = k, None, None
        while good < k_limit:
            k = min(good + step, k_limit)
            v = check(k)
            if not v.stable:
                bad, bad_verdict = k, v
                break
            good, step = k, 2 * step
        if bad is None:
            return RangeResult(good, "none", runs, None, "fast", 1.0)
    else:
        good, bad, bad_verdict = 0, k, v
        while bad > 1:
            k = max(bad - step, 1)
            v = check(k)
            if v.stable:
                good = k
                break
            bad, bad_verdict, step = k, v, 2 * step
    while bad - good > 1:
        mid = (good + bad) // 2
        v = check(mid)
        if v.stable:
            good = mid
        else:
            bad, bad_verdict = mid, v
    return RangeResult(good, bad_verdict.criterion, runs, bad_verdict, "fast", 1.0 if good >= 1 else None)


def grid_search(problem: ImpedanceProblem, resolution: float, k_limit: float = 200.0) -> RangeResult:
    """Stable range on the grid ``R, 2R, 3R, ...`` (N m/rad, or N/m for a prismatic joint).

    ``k_min`` is the lowest passing grid value and ``k_max`` the largest one such that every grid
    value from ``k_min`` up to it passes; below ``k_min`` the spring is too soft to settle within
    the run. Assuming the passing set is one interval of the grid (the tests compare with a scan
    of every grid value), a passing value is found first (halving down from half the
    :meth:`~ImpedanceProblem.estimate`, then doubling up), and each end is found by galloping
    away from it and bisecting.
    """
    if not (resolution > 0 and math.isfinite(resolution)):
        raise InputError(f"the stiffness resolution must be a positive number, got {resolution}", "resolution")
    n_limit = int(math.floor(k_limit / resolution + 1e-9))
    if n_limit < 1:
        raise InputError(f"the stiffness limit {k_limit} is below the resolution {resolution}", "k_limit",
                         "resolution")
    seen: dict[int, Verdict] = {}

    def check(n: int) -> Verdict:
        if n not in seen:
            seen[n] = problem.verdict(n * resolution)
        return seen[n]

    start = min(max(1, int(0.5 * problem.estimate() / resolution)), n_limit)
    candidates = [start]
    while candidates[-1] > 1:
        candidates.append(candidates[-1] // 2)
    up = start
    while up < n_limit:
        up = min(2 * up, n_limit)
        candidates.append(up)
    passing = next((n for n in candidates if check(n).stable), None)
    if passing is None:
        worst = check(candidates[0])
        return RangeResult(0.0, worst.criterion, len(seen), worst, "grid", None, resolution)

    def edge(direction: int) -> int:
        good, step = passing, 1
        while True:
            n = min(max(good + direction * step, 1), n_limit)
            if n == good:
                return good
            if not check(n).stable:
                bad = n
                break
            good, step = n, 2 * step
        while abs(bad - good) > 1:
            mid = (good + bad) // 2
            if check(mid).stable:
                good = mid
            else:
                bad = mid
        return good

    top, bottom = edge(+1), edge(-1)
    first = seen.get(top + 1)
    return RangeResult(top * resolution, first.criterion if first else "none", len(seen), first, "grid",
                       bottom * resolution, resolution)


def growth_boundary(problem: ImpedanceProblem, rel_tol: float = 1e-4, margin: float | None = None,
                  k_limit: float = 1e5) -> float:
    """Stiffness at which the oscillation of the wall joint starts to grow (no overshoot criterion).

    Each run lasts the configured duration without safety switch; the envelope of the last quarter
    is compared with the second quarter, and runs that leave the joint by more than 1 rad count as
    growing. ``margin`` (default 0 for type 1, 5 % for type 2, whose forced motion of the other
    joints keeps a periodic component in the envelope) is the relative growth that counts. For
    type 1 with full inertial compensation the answer converges to the exact ``b^2 / H_ww`` of
    :mod:`.boundary` (bisection to ``rel_tol``).
    """
    if margin is None:
        margin = 0.0 if problem.sim_type == 1 else 0.05
    cfg = replace(problem.config, safety_limit=None, stop_excursion=1.0)

    def grows(k: float) -> bool:
        wall = replace(cfg.wall, joint=problem.wall_joint, stiffness=k, equilibrium=problem.wall_equilibrium)
        trace = simulate(problem.device, replace(cfg, wall=wall), problem.paths, plant=problem.plant,
                         model=problem.model)
        if trace.status != 0:
            return True
        return envelope_grows(trace.wall_position - wall_rest(trace, wall), margin)

    return growth_onset(grows, 0.0, 1.0, rel_tol, k_limit)


UNSTABLE = "unstable (spectral radius of the sampled loop above 1)"
"""The verdict of the first grid stiffness above the stability limit (method ``limit``)."""


TOUCH = 0.001
"""The wall's rest from the start (m, or rad on a joint) of a simulated limit asked at the start pose: a touch (small
enough that the free handle's drift along the wall stays small, large against one encoder count)."""
SIMULATED_CAP = 1e5
"""N/m: a simulated limit of the spec sheet or a study stops its search here (inf above it)."""


def limit_range(device: Device, loop: SampledLoop | None = None, k_limit: float = 200.0, wall_joint: int = 0,
                equilibrium: float = 0.01, resolution: float | None = None, wall_direction=None,
                counts: int | None = None, simulate: bool = False) -> RangeResult:
    """The stable range on the grid ``R, 2R, 3R ...`` (``R`` = ``resolution``, default 1) from the exact stability
    limit of the sampled loop at the wall's equilibrium (:func:`stability_limit`): every grid stiffness from its
    lower end (0, unless gravity pulls the handle off the wall) up to the limit is stable, the first one above it is
    not; no performance criteria. With ``simulate`` the simulated limit
    with the device's dry friction and quantization (``counts``, default the device's encoders) is added beside it
    (:func:`simulated_limit`, the wall resting ``equilibrium`` or :data:`TOUCH` from the start)."""
    grid = 1.0 if resolution is None else float(resolution)
    limit = stability_limit(device, loop, wall_joint, equilibrium, wall_direction)
    top = int(math.floor(k_limit / grid + 1e-9))
    count = min(int(math.floor(limit.stiffness / grid)) if math.isfinite(limit.stiffness) else top, top)
    first = max(1, int(math.ceil(limit.lower / grid - 1e-9)))
    count = count if count >= first else 0
    above = Verdict((count + 1) * grid, False, UNSTABLE, math.nan, math.nan) if count < top else None
    simulated = None
    if simulate:
        simulated = simulated_limit(device, loop, wall_joint, equilibrium or TOUCH, wall_direction,
                                    device_counts(device) if counts is None else counts,
                                    start=max(limit.stiffness, 1e-3) if math.isfinite(limit.stiffness) else None)
    return RangeResult(count * grid, above.criterion if above else "none", 0, above, "limit",
                       first * grid if count >= 1 else None, grid, k_true_boundary=simulated, limit=limit)


def impedance_range(device: Device, sim_type: int = 1, method: str = "fast", k_limit: int = 200,
                    criteria: Criteria | None = None, config: LoopConfig | None = None,
                    wall_joint: int = 0, equilibrium: float = 0.01,
                    resolution: float | None = None, wall_direction=None, true_boundary: bool = False,
                    loop: SampledLoop | None = None, counts: int | None = None, simulate: bool = False) -> RangeResult:
    """Maximum stable impedance of ``wall_joint`` for simulation type 1 or 2 (seed §4.1.2) under the run ``config``
    (its loop settings ``config.loop``; default: the seed's settings, practice's for the limit method).

    ``method="limit"`` answers from the stability limit of the sampled loop ``config.loop`` at the wall's
    equilibrium, every joint free (:func:`limit_range`, with ``simulate`` its simulated limit with dry friction and
    ``config.counts`` beside it; ``sim_type``, ``criteria`` and the run's other fields do not enter);
    the other methods judge the seed's performance criteria on simulated (or exact linear) runs of type 1 or 2
    under ``config``. ``loop`` and ``counts`` are the settings' former places, taken one release (moved into
    ``config``).

    With ``wall_direction`` (x, y, z) the wall is Cartesian: K in N/m along that direction at the
    handle, ``equilibrium`` in metres from the handle's start, the criteria on the handle's
    wall-normal displacement, ``wall_joint`` the joint the experiment leaves free (:class:`.Wall`).

    Without ``resolution`` the seed's integer scan K = 1, 2, 3 ... (``method`` "linear", or "fast"
    for the same answer in fewer runs); with it, :func:`grid_search` on ``R, 2R, 3R ...``.
    ``method="analytic"`` answers the same searches from the exact linear response of the sampled
    loop (:mod:`.analytic`; no ODE integration; exact for type 1 and, along the driven motion
    (:mod:`.analytic_driven`), for type 2 on a cyclic wall joint such as the Phantom's joint 1).
    ``true_boundary`` also bisects the oscillation-growth boundary (simulated methods,
    :func:`growth_boundary`) into :attr:`RangeResult.k_true_boundary`.
    For a closed-loop device the joints start at, and move about, its home pose and a joint wall's
    ``equilibrium`` is measured from there (:func:`~.config.rest_pose`); a run whose loops stop closing on
    the assembly branch is a :class:`~hapticdesign.errors.UserError`.
    """
    require_device(device)
    require_options(sim_type, config, LoopConfig)
    if criteria is not None and not isinstance(criteria, Criteria):
        raise UserError(f"criteria must be a Criteria, got {type(criteria).__name__}")
    if method not in ("fast", "linear", "analytic", "limit"):
        raise InputError(f"method (of the search) must be 'limit', 'fast', 'linear' or 'analytic', got {method!r}",
                         "method")
    if isinstance(k_limit, bool) or not isinstance(k_limit, (int, float)) or not math.isfinite(k_limit):
        raise UserError(f"the stiffness limit must be a number, got {k_limit!r}")
    if k_limit < 1:
        raise InputError("the stiffness limit must be at least 1 (N m/rad, or N/m)", "k_limit")
    if resolution is not None and not (resolution > 0 and math.isfinite(resolution)):
        raise InputError(f"the stiffness resolution must be a positive number, got {resolution}", "resolution")
    if resolution is not None and resolution > k_limit:
        raise InputError(f"the stiffness resolution {resolution:g} is above the stiffness limit {k_limit:g}",
                         "resolution", "k_limit")
    if loop is not None or counts is not None:
        renamed("impedance_range(loop=..., counts=...)", "impedance_range(config=LoopConfig(loop=..., counts=...))", 3)
        config = replace(config or LoopConfig(loop=loop or SampledLoop()), **({} if loop is None else {"loop": loop}),
                         **({} if counts is None else {"counts": counts}))
    if method == "limit":
        if true_boundary:
            raise InputError("the growth boundary is a simulated check of the seed's searches; the limit method is "
                             "the boundary itself", "true_boundary", "method")
        config = config or LoopConfig(loop=SampledLoop())
        return limit_range(device, config.loop, k_limit, wall_joint, equilibrium, resolution, wall_direction,
                           config.counts, simulate)
    config = config or LoopConfig()
    if wall_direction is not None:
        config = replace(config, wall=replace(config.wall, direction=tuple(unit_direction(wall_direction).tolist())))
    require_search_workload(config, planned_simulations(method, k_limit, resolution, true_boundary))
    wall = (device, sim_type, wall_joint, equilibrium, criteria or Criteria(), config)
    problem = AnalyticProblem(*wall) if method == "analytic" else ImpedanceProblem(*wall)
    if resolution is not None:
        found = grid_search(problem, resolution, k_limit)
    else:
        found = (linear_scan if method == "linear" else fast_search)(problem, k_limit)
    if method == "analytic":
        found = replace(found, method="analytic", exact=problem.exact)
    if true_boundary:
        simulated = problem if isinstance(problem, ImpedanceProblem) else ImpedanceProblem(*wall)
        found = replace(found, k_true_boundary=growth_boundary(simulated))
    return found
