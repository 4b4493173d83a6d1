"""The Z-width of a 1-DOF haptic display, exact for the sampled-data loop (seed 000 ch. 5 future work).

Seed 000 asks for the requirements of stable interaction "in terms of design parameters of the
haptic manipulator, parameters of the virtual environment and simulation conditions (i.e.,
sampling time)". For one joint of inertia ``J`` and viscous damping ``b`` under a zero-order hold
of period ``T`` the answer is exact: the loop of the settings ``loop``
(:class:`~hapticdesign.analysis.sampled_loop.SampledLoop`: delay, velocity estimate, compensation, the same
defaults as every command) with the virtual damper ``B`` is the one-joint loop of
:func:`hapticdesign.analysis.sampled_loop.joint_limits` (the plant discretized exactly, the digital side and the
spring ``K`` one linear map of the sampled state), and ``K_max(B)`` is the spring at which its spectral radius
reaches 1. The law, as in the simulation engine (:mod:`.kernel`), with a computation delay of ``N`` samples (the
torque held during interval k is computed from the samples of k - N)::

    u_k = -K q_(k-N) - B v^_(k-N) + c (u_(k-N-1) - b v_(k-N))

``v^`` is the sampled velocity (the seed's perfect sensor) or the backward difference
``(q_(k-N) - q_(k-N-1)) / T`` of sampled positions (Colgate & Brown 1994); the last term is the
inertial compensator ``c J a`` of full compensation with the acceleration read just before the sample under the held
torque (``c = 1 - E/100`` for a modelling error of E percent, 0 without it).

A device's Cartesian wall acts with every actuated joint free (:func:`wall_zwidth`): its ``K_max(B)`` is the exact
n-joint limit of ``impedance-range --wall-direction`` and the spec sheet at each damper; the 1-DOF view of one joint
with the others held (:func:`along_wall`) is another question, asked by name (``zwidth --one-dof``).

Beside it: the passivity condition ``b > K T / 2 + |B|`` (Colgate & Schenkel 1997), with a delay
``t_d = N T`` ``b > K (T/2 + t_d) + |B|`` (as we read Hulin, Albu-Schäffer & Hirzinger 2014), i.e.
``K_pass = 2 (b - |B|) / (T (1 + 2 N))``, and the linear approximation of the stability boundary
for short delays, as we read Gil, Sánchez, Hulin, Preusche & Hirzinger (2009):
``K_lin = 2 (b + B) / (T (1 + 2 N))``. Passivity ignores that a virtual damper stabilizes the loop,
so it is the more conservative the larger B is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.sampled_loop import (
    FLOOR, MAX_WALL_DAMPING, SampledLoop, joint_limit, joint_limits, joint_loops,
)
from hapticdesign.errors import InputError, UserError
from hapticdesign.model.compensator_model import model_device
from hapticdesign.simulation.config import handle_jacobian, unit_direction

MAX_DAMPERS = 1000
"""Most virtual dampers of one Z-width (each one a search of K_max over about 60 eigenvalue problems)."""


def max_stiffness(inertia: float, damping: float, loop: SampledLoop, wall_damping: float = 0.0,
                  k_limit: float = 1e9, model_inertia: float | None = None) -> float:
    """The largest stable ``K`` of the joint for a virtual damper ``B`` (0 when even a tiny spring is unstable, inf
    when none up to ``k_limit`` destabilizes it); ``model_inertia`` the full compensator's inertia (default ``c
    J``)."""
    return joint_limit(inertia, damping, replace(loop, wall_damping=wall_damping), k_limit, model_inertia)


def passivity_stiffness(damping: float, loop: SampledLoop, wall_damping: float) -> float:
    """The passivity bound ``K < 2 (b - |B|) / (T (1 + 2 N))`` (Colgate & Schenkel; delay as Hulin et al.)."""
    return max(0.0, 2.0 * (damping - abs(wall_damping)) / (loop.period * (1 + 2 * loop.delay)))


def linear_approximation(damping: float, loop: SampledLoop, wall_damping: float) -> float:
    """Short-delay linear boundary ``K = 2 (b + B) / (T + 2 N T)`` (Gil et al. 2009, as we read it)."""
    return max(0.0, 2.0 * (damping + wall_damping) / (loop.period * (1 + 2 * loop.delay)))


def along_wall(inertia: float, damping: float, reach: float) -> tuple[float, float]:
    """The joint seen along a Cartesian wall (K in N/m, B in N s/m along n at the handle): its inertia and damping.

    With the other joints held the wall acts on the joint as ``K J_n^2`` and ``B J_n^2`` (``reach =
    J_n = n^T J_v`` of the joint, m/rad), so dividing the joint's equation by ``J_n^2`` gives the same
    loop in the handle's wall-normal coordinate ``x = J_n q``: inertia ``J / J_n^2`` (kg) and damping
    ``b / J_n^2`` (N s/m); its Z-width is in N/m over N s/m.
    """
    if not (math.isfinite(reach) and abs(reach) > 1e-12):
        raise UserError("the joint does not move the handle along the wall direction at this pose")
    r2 = reach * reach
    return inertia / r2, damping / r2


@dataclass(frozen=True)
class ZWidth:
    """The boundary ``K_max(B)`` at the given virtual dampers, with the two approximations beside it
    (``None`` with an inertial compensator or a hand, which neither formula models)."""

    B: list[float]
    K: list[float]
    passivity: list[float] | None
    linear: list[float] | None
    units: tuple[str, str] = ("N m s/rad", "N m/rad")
    """B's and K's: a joint's, or a Cartesian wall's N s/m and N/m."""

    def as_dict(self) -> dict:
        return {"B": self.B, "K": self.K, "passivity_K": self.passivity, "linear_approximation_K": self.linear,
                "units": {"B": self.units[0], "K": self.units[1]}}


def damping_grid(inertia: float, damping: float, loop: SampledLoop, points: int = 25,
                 model_inertia: float | None = None) -> list[float]:
    """Virtual dampers from 0 to where a damper alone destabilizes the loop (bisected to 0.1 %), at most
    :data:`~hapticdesign.analysis.sampled_loop.MAX_WALL_DAMPING`."""
    def usable(b: float) -> bool:
        loops = joint_loops(inertia, damping, replace(loop, wall_damping=b), model_inertia)
        return bool(loops.radii(np.array([FLOOR]))[0] < 1.0)

    return _grid(usable, 4.0 * inertia / loop.period + 4.0 * damping, points)


def _grid(usable, start: float, points: int) -> list[float]:
    """``points`` dampers from 0 to the largest ``usable`` one (doubled from ``start``, bisected to 0.1 %), at most
    :data:`~hapticdesign.analysis.sampled_loop.MAX_WALL_DAMPING`."""
    if not 2 <= points <= 1000:
        raise UserError(f"the damper grid needs 2 to 1000 points, got {points}")
    lo, hi = 0.0, min(start, MAX_WALL_DAMPING)
    while usable(hi):
        if hi == MAX_WALL_DAMPING:  # usable up to the largest damper a loop takes
            return [float(b) for b in np.linspace(0.0, hi, points)]
        lo, hi = hi, min(2.0 * hi, MAX_WALL_DAMPING)
    while hi - lo > 1e-3 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if usable(mid) else (lo, mid)
    return [float(b) for b in np.linspace(0.0, lo, points)]


def zwidth(inertia: float, damping: float, loop: SampledLoop, dampers: list[float] | None = None,
           points: int = 25, model_inertia: float | None = None) -> ZWidth:
    """The Z-width of a joint under the settings ``loop``: ``K_max`` for each virtual damper (default: a grid up to
    the largest usable one); ``model_inertia`` the full compensator's inertia (a device's model's ``H_jj``; default
    ``c J``, :attr:`~hapticdesign.analysis.sampled_loop.SampledLoop.fraction`)."""
    if dampers is not None and not 1 <= len(dampers) <= MAX_DAMPERS:
        raise InputError(f"give 1 to {MAX_DAMPERS} virtual dampers, got {len(dampers):,}", "b_values")
    _check_resolvable(inertia, damping, loop)
    values = (damping_grid(inertia, damping, loop, points, model_inertia) if dampers is None
              else _dampers(dampers, loop))
    bounds = loop.fraction == 0.0 and loop.hand is None
    return ZWidth(values, [max_stiffness(inertia, damping, loop, b, model_inertia=model_inertia) for b in values],
                  [passivity_stiffness(damping, loop, b) for b in values] if bounds else None,
                  [linear_approximation(damping, loop, b) for b in values] if bounds else None)


def wall_zwidth(device, pose: np.ndarray, direction, loop: SampledLoop, dampers: list[float] | None = None,
                points: int = 25) -> ZWidth:
    """The Z-width of a device's Cartesian wall along ``direction`` held at ``pose``, every actuated joint free but
    ``loop.held``: ``K_max`` (N/m) for each virtual damper (N s/m), each the exact limit of
    :func:`~.impedance.wall_interval` (the one ``impedance-range --wall-direction`` and the spec sheet take; gravity's
    gradient at the pose in the loop). The default dampers reach the largest with which some spring is stable
    (doubled from ``4 m_u / T``, ``m_u`` the handle's mass along the wall). No 1-DOF approximation stands beside it."""
    from hapticdesign.simulation.impedance import wall_interval

    jv = handle_jacobian(device, pose)[:3]
    unit = unit_direction(direction)
    mobility = float(unit @ jv @ np.linalg.solve(mass_matrix(device, pose), jv.T) @ unit)

    def limit(b: float) -> float:
        return wall_interval(device, pose, replace(loop, wall_damping=b), direction=unit)[1]

    limit(0.0)  # a direction the handle does not move along, or a bad pose, refused before any search
    values = (_grid(lambda b: limit(b) > 0.0, 4.0 / (mobility * loop.period), points) if dampers is None
              else _dampers(dampers, loop))
    return ZWidth(values, [limit(b) for b in values], None, None, ("N s/m", "N/m"))


def _dampers(dampers: list[float], loop: SampledLoop) -> list[float]:
    """The virtual dampers given, each checked as a loop's (one line naming ``--b-values``)."""
    if not 1 <= len(dampers) <= MAX_DAMPERS:
        raise InputError(f"give 1 to {MAX_DAMPERS} virtual dampers, got {len(dampers):,}", "b_values")
    values = [float(b) for b in dampers]
    if any(not (math.isfinite(b) and b >= 0.0) for b in values):
        raise InputError(f"the virtual dampers must be finite and >= 0, got "
                         f"{min(values, key=lambda b: b if math.isfinite(b) else -math.inf):g}", "b_values")
    try:  # each damper's loop, validated before any search
        for b in values:
            replace(loop, wall_damping=b)
    except InputError as exc:
        raise InputError(str(exc), "b_values") from None
    return values


def _check_resolvable(inertia: float, damping: float, loop: SampledLoop) -> None:
    """Refuse a joint whose values are not a plant's or whose ratios overflow double precision (before any grid
    search)."""
    if not (math.isfinite(inertia) and inertia > 0):
        raise UserError(f"the inertia must be positive, got {inertia:g}")
    if not (math.isfinite(damping) and damping >= 0):
        raise UserError(f"the damping must be non-negative, got {damping:g}")
    t = loop.period
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        scales = (inertia / t, damping / inertia * t, t / inertia * t, 4.0 * inertia / t + 4.0 * damping)
        plant = joint_loops(inertia, damping, loop).base if all(math.isfinite(v) for v in scales) else None
    if plant is None or not np.all(np.isfinite(plant)):
        raise UserError(f"the inertia {inertia:g}, damping {damping:g} and period {t:g} are outside the range this "
                        "computation can resolve (their ratios overflow)")


@dataclass(frozen=True)
class StiffnessMap:
    """``K_max`` of one joint (virtual damper B) over a grid of two other joints' angles."""

    axes: tuple[int, int]
    first: list[float]
    second: list[float]
    K: list[list[float]]


def check_map(device, joint: int, axes: tuple[int, int], n: int) -> None:
    """The grid of :func:`stiffness_map` (``n`` points per axis of two joints ``axes`` other than the wall
    ``joint``), checked before it or any other work is done."""
    if not 2 <= n <= 101:
        raise UserError(f"the map needs 2 to 101 points per axis, got {n}")
    if len(set(axes)) != 2 or joint in axes or not all(0 <= a < device.n_dof for a in axes):
        raise UserError(f"the map needs two joints other than the wall joint, of 1..{device.n_dof}")


def stiffness_map(device, joint: int, axes: tuple[int, int], n: int, loop: SampledLoop,
                  span: tuple[float, float] = (-math.pi, math.pi)) -> StiffnessMap:
    """The Z-width's K at the loop's virtual damper over the workspace: ``J = H_jj(q)`` on an ``n x n`` grid of
    joints ``axes`` (the others at 0), each cell exact for the sampled loop with the other joints held (the cells
    searched at once, :func:`~hapticdesign.analysis.sampled_loop.joint_limits`; the compensator's inertia that of
    the model device, :func:`~.config.model_device`)."""
    check_map(device, joint, axes, n)
    grid = np.linspace(span[0], span[1], n)
    poses = np.zeros((n * n, device.n_dof))
    poses[:, axes[0]], poses[:, axes[1]] = np.repeat(grid, n), np.tile(grid, n)
    inertia = mass_matrix(device, poses)[:, joint, joint]
    model = (mass_matrix(model_device(device, loop.error_percent), poses)[:, joint, joint] if loop.error_percent
             else None)
    values = joint_limits(inertia, float(device.damping[joint]), loop, model_inertia=model).reshape(n, n)
    return StiffnessMap(axes, grid.tolist(), grid.tolist(), values.tolist())
