"""The Z-width of a 1-DOF haptic display, exact for the sampled-data loop (seed 000 ch. 5 future work).

Seed 000 asks for the requirements of stable interaction "in terms of design parameters of the
haptic manipulator, parameters of the virtual environment and simulation conditions (i.e.,
sampling time)". For one joint of inertia ``J`` and viscous damping ``b`` under a zero-order hold
of period ``T`` the answer is exact: the plant is discretized exactly (``control.c2d``, ZOH), the
digital side is a discrete state-space system, and the pair ``(K, B)`` of virtual spring and
damper is stable when every pole of the interconnection (``control.feedback``) lies inside the
unit circle. The law, as in the simulation engine (:mod:`.kernel`), with a computation delay of
``N`` samples (the torque held during interval k is computed from the samples of k - N)::

    u_k = -K q_(k-N) - B v^_(k-N) + c (u_(k-N-1) - b v_(k-N))

``v^`` is the sampled velocity (the seed's perfect sensor) or the backward difference
``(q_(k-N) - q_(k-N-1)) / T`` of sampled positions (Colgate & Brown 1994); the last term is the
inertial compensator ``c J a`` with the acceleration read just before the sample under the held
torque (``c = 1 - E/100`` for a modelling error of E percent, 0 without compensation; with a
physical spring ``k_p`` in the plant the acceleration carries ``- k_p q`` too).

Beside it: the passivity condition ``b > K T / 2 + |B|`` (Colgate & Schenkel 1997), with a delay
``t_d = N T`` ``b > K (T/2 + t_d) + |B|`` (as we read Hulin, Albu-Schäffer & Hirzinger 2014), i.e.
``K_pass = 2 (b - |B|) / (T (1 + 2 N))``, and the linear approximation of the stability boundary
for short delays, as we read Gil, Sánchez, Hulin, Preusche & Hirzinger (2009):
``K_lin = 2 (b + B) / (T (1 + 2 N))``. Passivity ignores that a virtual damper stabilizes the loop,
so it is the more conservative the larger B is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import control
import numpy as np
from scipy.optimize import brentq

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.errors import InputError, UserError

VELOCITIES = ("sampled", "difference")
MAX_DAMPERS = 1000
"""Most virtual dampers of one Z-width (each one bisects K_max over about 100 eigenvalue problems)."""


@dataclass(frozen=True)
class DisplayLoop:
    """A 1-DOF haptic display: inertia ``J`` [kg m^2], damping ``b`` [N m s/rad], period ``T`` [s],
    delay in samples, velocity estimate, compensator fraction ``c`` (0: none, 1: exact) and a
    physical spring ``k_p`` [N m/rad] in the plant (a hand's stiffness; 0 by default)."""

    inertia: float
    damping: float
    period: float
    delay: int = 0
    velocity: str = "sampled"
    fraction: float = 0.0
    plant_stiffness: float = 0.0

    def __post_init__(self) -> None:
        for name in ("inertia", "period"):
            value = getattr(self, name)
            if not (value > 0 and math.isfinite(value)):
                raise UserError(f"the {name} must be positive and finite, got {value}")
        if not (self.damping >= 0 and math.isfinite(self.damping)):
            raise UserError(f"the damping must be non-negative and finite, got {self.damping}")
        if not (isinstance(self.delay, int) and 0 <= self.delay <= 200):
            raise UserError(f"the delay must be a whole number of samples between 0 and 200, got {self.delay}")
        if self.velocity not in VELOCITIES:
            raise UserError(f"the velocity must be one of {', '.join(VELOCITIES)}, got {self.velocity!r}")
        if not (math.isfinite(self.fraction) and 0.0 <= self.fraction < 2.0):
            raise UserError(f"the compensator fraction must lie in [0, 2), got {self.fraction}")
        if not (self.plant_stiffness >= 0 and math.isfinite(self.plant_stiffness)):
            raise UserError(f"the plant stiffness must be non-negative and finite, got {self.plant_stiffness}")
        scales = (self.inertia / self.period, self.damping / self.inertia * self.period,
                  self.period / self.inertia * self.period, self.plant_stiffness / self.inertia * self.period * self.period)
        if not all(math.isfinite(v) for v in scales) or not np.all(np.isfinite(plant(self).A)):
            raise UserError(f"the inertia {self.inertia:g}, damping {self.damping:g} and period {self.period:g} are "
                            "outside the range this computation can resolve (their ratios overflow)")


@lru_cache(maxsize=256)
def plant(loop: DisplayLoop) -> control.StateSpace:
    """``J qdd + b qd + k_p q = u`` with outputs ``(q, qd)``, discretized exactly with a zero-order hold."""
    a = np.array([[0.0, 1.0], [-loop.plant_stiffness / loop.inertia, -loop.damping / loop.inertia]])
    b = np.array([[0.0], [1.0 / loop.inertia]])
    return control.c2d(control.ss(a, b, np.eye(2), np.zeros((2, 1))), loop.period, method="zoh")


def controller(loop: DisplayLoop, stiffness: float, virtual_damping: float) -> control.StateSpace:
    """The digital side as a discrete state-space system from ``(q_k, v_k)`` to ``u_k``.

    State: ``q_(k-1..k-N-1)``, ``v_(k-1..k-N)``, ``u_(k-1..k-N-1)``.
    """
    n, T = loop.delay, loop.period
    nq, nv, nu = n + 1, n, n + 1
    size = nq + nv + nu
    C, D = np.zeros((1, size)), np.zeros((1, 2))

    def add(signal: str, lag: int, gain: float) -> None:
        """Add ``gain * signal_(k - lag)`` to the output."""
        if lag == 0:
            D[0, "qv".index(signal)] += gain
            return
        start = {"q": 0, "v": nq, "u": nq + nv}[signal]
        C[0, start + lag - 1] += gain

    add("q", n, -stiffness)
    if loop.velocity == "sampled":
        add("v", n, -virtual_damping)
    else:
        add("q", n, -virtual_damping / T)
        add("q", n + 1, virtual_damping / T)
    add("v", n, -loop.fraction * loop.damping)
    add("q", n, -loop.fraction * loop.plant_stiffness)
    add("u", n + 1, loop.fraction)
    A, B = np.zeros((size, size)), np.zeros((size, 2))
    B[0, 0] = 1.0  # q_k enters the position line
    A[1:nq, 0:nq - 1] = np.eye(nq - 1)
    if nv:
        B[nq, 1] = 1.0
        A[nq + 1:nq + nv, nq:nq + nv - 1] = np.eye(nv - 1)
    A[nq + nv] = C[0]  # u_k enters the torque line
    B[nq + nv] = D[0]
    A[nq + nv + 1:, nq + nv:size - 1] = np.eye(nu - 1)
    return control.ss(A, B, C, D, T)


def spectral_radius(loop: DisplayLoop, stiffness: float, virtual_damping: float = 0.0) -> float:
    """Largest pole magnitude of the closed loop (stable below 1)."""
    closed = control.feedback(plant(loop), controller(loop, stiffness, virtual_damping), sign=1)
    return float(np.max(np.abs(control.poles(closed))))


def _tiny_spring(loop: DisplayLoop) -> float:
    return 1e-9 * max(1.0, loop.damping / loop.period)


def max_stiffness(loop: DisplayLoop, virtual_damping: float = 0.0, k_limit: float = 1e9) -> float:
    """The largest stable ``K`` for a virtual damper ``B`` (0 when even a tiny spring is unstable)."""
    lo = _tiny_spring(loop)
    if spectral_radius(loop, lo, virtual_damping) >= 1.0:
        return 0.0
    hi = 2.0 * lo
    while spectral_radius(loop, hi, virtual_damping) < 1.0:
        lo, hi = hi, 2.0 * hi
        if hi > k_limit:
            return math.inf
    return brentq(lambda k: spectral_radius(loop, k, virtual_damping) - 1.0, lo, hi, xtol=1e-12, rtol=1e-10)


def passivity_stiffness(loop: DisplayLoop, virtual_damping: float) -> float:
    """The passivity bound ``K < 2 (b - |B|) / (T (1 + 2 N))`` (Colgate & Schenkel; delay as Hulin et al.)."""
    return max(0.0, 2.0 * (loop.damping - abs(virtual_damping)) / (loop.period * (1 + 2 * loop.delay)))


def linear_approximation(loop: DisplayLoop, virtual_damping: float) -> float:
    """Short-delay linear boundary ``K = 2 (b + B) / (T + 2 N T)`` (Gil et al. 2009, as we read it)."""
    return max(0.0, 2.0 * (loop.damping + virtual_damping) / (loop.period * (1 + 2 * loop.delay)))


def along_wall(loop: DisplayLoop, reach: float) -> DisplayLoop:
    """The joint's loop seen along a Cartesian wall (K in N/m, B in N s/m along n at the handle).

    With the other joints held the wall acts on the joint as ``K J_n^2`` and ``B J_n^2`` (``reach =
    J_n = n^T J_v`` of the joint, m/rad), so dividing the joint's equation by ``J_n^2`` gives the same
    loop in the handle's wall-normal coordinate ``x = J_n q``: inertia ``J / J_n^2`` (kg), damping
    ``b / J_n^2`` (N s/m) and a plant spring ``k_p / J_n^2`` (N/m); its Z-width is in N/m over N s/m.
    """
    if not (math.isfinite(reach) and abs(reach) > 1e-12):
        raise UserError("the joint does not move the handle along the wall direction at this pose")
    r2 = reach * reach
    return DisplayLoop(loop.inertia / r2, loop.damping / r2, loop.period, loop.delay, loop.velocity, loop.fraction,
                       loop.plant_stiffness / r2)


@dataclass(frozen=True)
class ZWidth:
    """The boundary ``K_max(B)`` at the given virtual dampers, with the two approximations beside it
    (``None`` with an inertial compensator, which neither formula models)."""

    B: list[float]
    K: list[float]
    passivity: list[float] | None
    linear: list[float] | None

    def as_dict(self) -> dict:
        return {"B": self.B, "K": self.K, "passivity_K": self.passivity, "linear_approximation_K": self.linear,
                "units": {"B": "N m s/rad", "K": "N m/rad"}}


def damping_grid(loop: DisplayLoop, points: int = 25) -> list[float]:
    """Virtual dampers from 0 to where a damper alone destabilizes the loop (bisected to 0.1 %)."""
    if not 2 <= points <= 1000:
        raise UserError(f"the damper grid needs 2 to 1000 points, got {points}")
    spring = _tiny_spring(loop)

    def usable(b: float) -> bool:
        return spectral_radius(loop, spring, b) < 1.0

    lo, hi = 0.0, 4.0 * loop.inertia / loop.period + 4.0 * loop.damping
    while usable(hi):
        lo, hi = hi, 2.0 * hi
    while hi - lo > 1e-3 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if usable(mid) else (lo, mid)
    return [float(b) for b in np.linspace(0.0, lo, points)]


def zwidth(loop: DisplayLoop, dampers: list[float] | None = None, points: int = 25) -> ZWidth:
    """The Z-width: ``K_max`` for each virtual damper (default: a grid up to the largest usable one)."""
    if dampers is not None and not 1 <= len(dampers) <= MAX_DAMPERS:
        raise InputError(f"give 1 to {MAX_DAMPERS} virtual dampers, got {len(dampers):,}", "b_values")
    values = damping_grid(loop, points) if dampers is None else [float(b) for b in dampers]
    if any(not (math.isfinite(b) and b >= 0.0) for b in values):
        raise InputError(f"the virtual dampers must be finite and >= 0, got "
                         f"{min(values, key=lambda b: b if math.isfinite(b) else -math.inf):g}", "b_values")
    bounds = loop.fraction == 0.0 and loop.plant_stiffness == 0.0
    return ZWidth(values, [max_stiffness(loop, b) for b in values],
                  [passivity_stiffness(loop, b) for b in values] if bounds else None,
                  [linear_approximation(loop, b) for b in values] if bounds else None)


@dataclass(frozen=True)
class StiffnessMap:
    """``K_max`` of one joint (virtual damper B) over a grid of two other joints' angles."""

    axes: tuple[int, int]
    first: list[float]
    second: list[float]
    K: list[list[float]]


def stiffness_map(device, joint: int, axes: tuple[int, int], n: int, period: float = 1e-3, delay: int = 0,
                  velocity: str = "sampled", fraction: float = 0.0, virtual_damping: float = 0.0,
                  span: tuple[float, float] = (-math.pi, math.pi)) -> StiffnessMap:
    """The Z-width's K at one B over the workspace: ``J = H_jj(q)`` on an ``n x n`` grid of joints
    ``axes`` (the others at 0), each cell exact for the sampled loop with the other joints held."""
    if not 2 <= n <= 101:
        raise UserError(f"the map needs 2 to 101 points per axis, got {n}")
    if len(set(axes)) != 2 or joint in axes or not all(0 <= a < device.n_dof for a in axes):
        raise UserError(f"the map needs two joints other than the wall joint, of 1..{device.n_dof}")
    grid = np.linspace(span[0], span[1], n)
    values = []
    for x in grid:
        row = []
        for y in grid:
            q = np.zeros(device.n_dof)
            q[axes[0]], q[axes[1]] = x, y
            loop = DisplayLoop(float(mass_matrix(device, q)[joint, joint]), float(device.damping[joint]), period, delay,
                               velocity, fraction)
            row.append(max_stiffness(loop, virtual_damping))
        values.append(row)
    return StiffnessMap(axes, grid.tolist(), grid.tolist(), values)
