"""The seed's stability criteria and the motions of the other joints (seed 000 §4.1.2-4.1.3, Table 4.3).

Shared by the simulated search (:mod:`.impedance`) and the analytic one (:mod:`.analytic`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from hapticdesign.errors import InputError, UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.config import LoopConfig, normal_jacobian, rest_pose
from hapticdesign.simulation.paths import Held, Path, Sine

REACH_FLOOR = 1e-12
"""Smallest ``|J_n,w|`` (m/rad or m/m) of a Cartesian wall's joint that counts as moving the handle along it."""


SEED_STEP = 0.01
"""The seed's step: the wall's spring rests 0.01 rad from the joint's start (seed 000 §4.1.2)."""


@dataclass(frozen=True)
class Criteria:
    """Stability criteria of the seed's method (all configurable), stated for the seed's 0.01-rad step.

    The seed's limits are 120 % (overshoot), 20 % (settling band) and 600 % (safety switch) of that
    step. A wall whose step is another size (a Cartesian wall's rest ``0.01 J_n,w`` m from the handle's
    start is well below a millimetre on a small device) is judged by the same ratios: :meth:`for_step`
    scales every length by ``|step| / 0.01``. With fixed limits a growing oscillation that starts at a
    fraction of a millimetre never crosses a 12-mm overshoot or a 2-mm settling band in 5 s.
    """

    overshoot_limit: float = 0.012
    settle_tolerance: float = 0.002
    settle_window: float = 0.5
    safety_limit: float = 0.06

    def __post_init__(self) -> None:
        for name in ("overshoot_limit", "settle_tolerance", "settle_window", "safety_limit"):
            value = getattr(self, name)
            if not (value > 0 and math.isfinite(value)):
                raise UserError(f"{name.replace('_', ' ')} must be positive, got {value}")

    def for_step(self, step: float) -> "Criteria":
        """The same criteria for a wall whose spring rests ``step`` from the start (rad, m): the limits
        (not the settling window, a time) scaled by ``|step| / 0.01``; the seed's step leaves them as they are."""
        factor = abs(float(step)) / SEED_STEP
        if factor == 1.0:
            return self
        if not (factor > 0 and math.isfinite(factor)):
            raise UserError(f"the wall's equilibrium must be a non-zero distance from the start, got {step}")
        return Criteria(self.overshoot_limit * factor, self.settle_tolerance * factor, self.settle_window,
                        self.safety_limit * factor)


@dataclass(frozen=True)
class Verdict:
    """Outcome of one gain: stable, or the criterion that failed first.

    ``peak`` is the largest excursion from the start over every plant step; ``stopped_at`` is the
    time a run ended early (excursion limit reached or diverged), ``None`` for a full run.
    """

    stiffness: float
    stable: bool
    criterion: str
    peak: float
    final_error: float
    stopped_at: float | None = None

    def as_dict(self) -> dict:
        return {"k": float(self.stiffness), "stable": self.stable, "criterion": self.criterion,
                "peak": self.peak, "final_error": self.final_error, "stopped_at": self.stopped_at}


def type_paths(sim_type: int, n_dof: int, wall_joint: int = 0, rest: np.ndarray | None = None) -> dict[int, Path]:
    """Motions of the other joints: type 1 held at 0, type 2 driven at 0.52 sin(3 pi t) (Table 4.3);
    about ``rest`` instead of 0 when given (a closed-loop device's home, :func:`~.config.rest_pose`)."""
    if sim_type not in (1, 2):
        raise UserError(f"simulation type must be 1 or 2, got {sim_type}")
    centre = np.zeros(n_dof) if rest is None else np.asarray(rest, dtype=float)

    def path(j: int) -> Path:
        return Held(float(centre[j])) if sim_type == 1 else Sine(0.52, 3 * np.pi, float(centre[j]))

    return {j: path(j) for j in range(n_dof) if j != wall_joint}


def require_closed(trace, what: str) -> None:
    """A closed-loop device's run that left the assembly branch is a user error (one line), not a verdict."""
    if trace.loop_lost:
        raise UserError(f"{what}: the loops stopped closing on the assembly branch at t = {trace.end_time:.4g} s "
                        "(the motion reaches a singular pose or another branch; try a smaller motion or a pose "
                        "nearer home)")


@dataclass
class WallProblem:
    """One device, one simulation type, the wall on one joint: what a stable-range search is asked.

    ``criteria`` are stated for the seed's 0.01 step and judged relative to ``equilibrium``
    (:meth:`Criteria.for_step`).

    :class:`~hapticdesign.simulation.impedance.ImpedanceProblem` answers each stiffness by
    simulation, :class:`~hapticdesign.simulation.analytic.AnalyticProblem` from the exact linear
    response; the searches take either."""

    device: Device
    sim_type: int = 1
    wall_joint: int = 0
    equilibrium: float = 0.01
    criteria: Criteria = field(default_factory=Criteria)
    config: LoopConfig = field(default_factory=LoopConfig)

    def __post_init__(self) -> None:
        check_settle_window(self.criteria, self.config.duration)
        self.config.require_simulated()
        require_inertia(self.device, rest_pose(self.device), self.wall_joint)
        if self.config.wall.cartesian:
            require_reach(self.device, self.config, self.wall_joint)
        self.criteria = self.criteria.for_step(self.equilibrium)


def require_inertia(device: Device, q: np.ndarray, wall_joint: int) -> None:
    """The wall joint is the one free joint of a search (:func:`type_paths` prescribes every other), so the
    plant ``H_ww qdd_w = tau_w - ...`` needs ``H_ww > 0`` at the start pose: a wall joint whose bodies are all
    massless has no inertia and no motion to simulate or to bound. The other joints' inertia does not enter
    (they follow their paths whatever their torques), so massless links elsewhere are not refused."""
    from hapticdesign.analysis.dynamics.device import mass_matrix

    if not 0 <= wall_joint < device.n_dof:
        raise UserError(f"unknown joint {wall_joint + 1}; the device has joints 1..{device.n_dof}")
    h = np.atleast_2d(mass_matrix(device, q))[wall_joint, wall_joint]
    if not h > 0.0:
        k = wall_joint + 1
        raise UserError(f"joint {k} has no inertia at the start pose (H{k}{k} = {h:g}): its bodies are massless, "
                        "so it has no dynamics to simulate")


def require_reach(device: Device, config: LoopConfig, wall_joint: int) -> None:
    """A Cartesian wall needs the wall joint to move the handle along its direction at the start pose
    (``J_n,w = n^T J_v,w`` not 0): otherwise the wall acts on nothing and every stiffness is "stable"."""
    reach = float(normal_jacobian(device, config.wall, rest_pose(device))[wall_joint])
    if not (math.isfinite(reach) and abs(reach) > REACH_FLOOR):
        raise UserError(f"joint {wall_joint + 1} does not move the handle along the wall direction "
                        f"{', '.join(f'{v:g}' for v in config.wall.direction)} at the start pose")


def check_settle_window(criteria: Criteria, duration: float) -> None:
    """The settling test needs a window within the run, or every stiffness is "not settled"."""
    if criteria.settle_window >= duration:
        raise InputError(f"the settle window ({criteria.settle_window:g} s) must be shorter than the simulated "
                         f"time ({duration:g} s): a window that holds the start counts every stiffness as not settled",
                         "settle_window", "duration")
