"""What a sampled-data simulation is configured with and what it returns (seed 000 §4.1.1).

Shared by the fast loop (:mod:`.loop`, :mod:`.kernel`) and the independent SciPy loop
(``tests/helpers/reference.py``), so that neither imports the other. The loop's settings are the one
:class:`~hapticdesign.analysis.sampled_loop.SampledLoop` of every command; defaults follow the seed: plant step
1e-4 s, sample period 1 ms, perfect sensors (condition ix), no modelling error (condition vi), no
hand (condition vii), safety switch at 0.06 rad (Fig. 4.7).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics.device import gravity, gravity_gradient, mass_matrix
from hapticdesign.analysis.sampled_loop import Hand, SampledLoop
from hapticdesign.errors import InputError, RenamedWarning, UserError
from hapticdesign.model.device import Device
from hapticdesign.model.compensator_model import model_device

STATUS_COMPLETED = 0
STATUS_EXCURSION = 1
STATUS_DIVERGED = 2
STATUS_LOOP_LOST = 3
"""A closed-loop device's loops stopped closing on the assembly branch (no closure, a singular or a
changed branch), in the plant or in the compensator's model: the run ends at the last closed pose."""

STEP_CONTROLS = ("auto", "fixed", "adaptive")
ADAPTIVE_TOLERANCE = 1e-9
"""Local error per adaptive step, relative to ``1 + |y|`` for each joint's position (rad or m) and
velocity (rad/s or m/s) (:func:`hapticdesign.simulation.kernel.run_loop`)."""

FRICTION_VELOCITY = 1e-3
"""Coulomb friction acts as ``F_c tanh(qd / v_f)`` with ``v_f`` = 1e-3 rad/s (or m/s): the sign function
made smooth enough for a fixed-step integrator; above 3 v_f it is within 0.5 % of ``F_c sign(qd)``."""


def renamed(old: str, new: str, stacklevel: int = 4) -> None:
    """One :class:`~hapticdesign.errors.RenamedWarning` for an old keyword of the simulation's records and calls, taken
    one release more."""
    warnings.warn(f"{old} is now {new}; {old} will be removed", RenamedWarning, stacklevel=stacklevel)


@dataclass(frozen=True)
class Wall:
    """The virtual wall: a joint wall, or a Cartesian wall when ``direction`` is given; its damper is the loop's
    ``wall_damping`` (:class:`~hapticdesign.analysis.sampled_loop.SampledLoop`).

    Joint wall: ``tau_imp = K (q_j - q_eq) + B qd_j`` on joint ``joint`` (K in N m/rad, B in N m s/rad,
    ``equilibrium`` the angle q_eq; N/m, N s/m and m for a prismatic joint).

    Cartesian wall: a spring K (N/m) and damper B (N s/m) along the unit ``direction`` n at the
    device's handle (its end-effector frame), ``F = -(K (x.n - x_eq) + B v.n) n`` on the handle,
    ``tau = J^T F`` on the joints with the frame's geometric Jacobian (so ``tau_imp = J_n^T (K (x.n -
    x_eq) + B J_n qd)``, ``J_n = n^T J_v``). ``equilibrium`` is then the rest of the spring in metres
    along n from the handle's start, and ``joint`` only names the joint the seed's experiments leave
    free (:func:`~.criteria.type_paths`). Like the joint wall it pulls from both sides of its rest.
    ``damping`` is the damper's former place, taken one release (a :class:`LoopConfig` moves it to its loop).
    """

    joint: int = 0
    stiffness: float = 1.0
    damping: float | None = None
    equilibrium: float = 0.01
    direction: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        if self.damping is not None:
            renamed("Wall(damping=...)", "SampledLoop(wall_damping=...) of LoopConfig(loop=...)")

    @property
    def cartesian(self) -> bool:
        return self.direction is not None

    @property
    def units(self) -> dict[str, str]:
        """Units of the stiffness and damping (Cartesian, or of a revolute joint)."""
        if self.cartesian:
            return {"K": "N/m", "B": "N s/m"}
        return {"K": "N m/rad", "B": "N m s/rad"}


def loop_config(loop: SampledLoop, wall: Wall | None = None, counts_per_revolution: int | None = None,
                **simulation) -> LoopConfig:
    """``LoopConfig(loop=loop, wall=wall, counts=counts_per_revolution, **simulation)``, its former spelling, taken
    one release."""
    renamed("loop_config(loop, wall, counts)", "LoopConfig(loop=loop, wall=wall, counts=counts)")
    return LoopConfig(loop=loop, wall=wall or Wall(), counts=counts_per_revolution, **simulation)


def unit_direction(direction) -> np.ndarray:
    """A wall direction as a unit 3-vector; anything else is a :class:`UserError`."""
    try:
        n = np.asarray(direction, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise UserError(f"the wall direction must be three numbers, got {direction!r}") from None
    if n.shape != (3,) or not np.all(np.isfinite(n)):
        raise UserError(f"the wall direction must be three finite numbers, got {np.atleast_1d(n).tolist()[:6]}")
    largest = float(np.abs(n).max())
    if largest == 0.0:
        raise UserError("the wall direction must not be the zero vector")
    n = n / largest  # scaled first: the norm of (0, 1e308, 0) overflows
    return n / float(np.linalg.norm(n))


@dataclass(frozen=True)
class Compensator:
    """How the compensator's model departs from the loop's compensation (§4.1.1.2): which of its terms are kept and
    how its modelling error (the loop's ``error_percent``) spreads over the parameters.

    ``inertial``, ``coriolis``, ``gravity`` keep (True) or drop each term the loop's ``compensation`` feeds forward
    (``full``: all three; ``gravity``: gravity only; ``none``: none): an ablation of the seed's law. The loop's
    ``error_percent`` scales every inertial parameter by ``1 - E/100`` (the seed's "error %" of masses, inertias
    and mass centres alike). ``group_errors`` gives each group its own error in percent on top: ``{"mass": E_m,
    "centre": E_r, "inertia": E_I}`` (masses ``m``; mass-centre offsets ``rx ry rz``; inertia entries ``Ixx ...
    Iyz``); with ``error_seed`` each parameter of a group gets a random sign (``numpy.random.default_rng(error_seed)``,
    in the order of the device's parameter names), so the model over- and underestimates as a real identification
    would. ``error_percent`` is the error's former place, taken one release (a :class:`LoopConfig` moves it to its
    loop).
    """

    inertial: bool = True
    coriolis: bool = True
    gravity: bool = True
    error_percent: float | None = None
    group_errors: tuple[tuple[str, float], ...] = ()
    error_seed: int | None = None

    def __post_init__(self) -> None:
        if self.error_percent is not None:
            renamed("Compensator(error_percent=...)", "SampledLoop(error_percent=...) of LoopConfig(loop=...)")


@dataclass(frozen=True)
class Sensors:
    """The former record of the sample period, encoder counts and delay, taken one release: a :class:`LoopConfig`
    moves them to its ``loop`` (``period``, ``delay``) and ``counts``."""

    period: float = 1e-3
    counts_per_revolution: int | None = None
    delay_samples: int = 0

    def __post_init__(self) -> None:
        renamed("Sensors(period, counts_per_revolution, delay_samples)",
                 "LoopConfig(loop=SampledLoop(period=..., delay=...), counts=...)")
        if isinstance(self.delay_samples, bool) or self.delay_samples != int(self.delay_samples) or self.delay_samples < 0:
            raise InputError(f"the sensor delay must be a non-negative number of samples, got {self.delay_samples}", "delay")


@dataclass(frozen=True)
class LoopConfig:
    """A run of the sampled loop: its settings ``loop`` (a :class:`~hapticdesign.analysis.sampled_loop.SampledLoop`,
    the one record of every command: period, delay, compensation with its modelling error, wall damper, hand; the
    seed's by default, seed 000 §4.1.1) and the run's own fields (duration, plant step, encoder ``counts`` per
    revolution, the compensator's departures, the wall's spring and rest, plant damping and friction, safety switch,
    recording, step control). The simulated damper uses the sampled velocity (:meth:`require_simulated`).
    ``sensors``, ``hand`` and the damper and error of ``wall`` and ``compensator`` are
    the settings' former places, taken one release (moved into ``loop`` here)."""

    duration: float = 5.0
    step: float = 1e-4
    loop: SampledLoop = field(default_factory=SampledLoop.seed)
    compensator: Compensator = field(default_factory=Compensator)
    wall: Wall = field(default_factory=Wall)
    damping: tuple[float, ...] | None = None
    coulomb: tuple[float, ...] | None = None
    """Coulomb friction torque (N m) or force (N) per joint in the plant; None: the device's (or none)."""
    safety_limit: float | None = 0.06
    counts: int | None = None
    """Encoder counts per revolution (position quantization); None: none."""
    record_stride: int | None = None
    stop_excursion: float | None = None
    step_control: str = "auto"
    """``fixed``: every step is one plant step ``step`` (the seed's fixed-step RK4); ``adaptive``: a step
    spans several plant steps within a sample period when RK4's local error estimate stays below
    ``tolerance`` (:func:`~.kernel.run_loop`); ``auto``: fixed for a tree (its results on the seed's
    grid), adaptive for a closed-loop device (each evaluation of its dynamics solves the loops)."""
    tolerance: float = ADAPTIVE_TOLERANCE
    sensors: Sensors | None = None
    hand: Hand | None = None

    def __post_init__(self) -> None:
        self._fold_former()
        if not isinstance(self.loop, SampledLoop):
            raise UserError(f"loop must be a SampledLoop, got {type(self.loop).__name__}")
        if self.counts is not None and not self.counts >= 1:
            raise InputError(f"the encoder counts per revolution must be at least 1, got {self.counts}", "counts")
        if not (math.isfinite(self.duration) and self.duration > 0):
            raise InputError(f"the simulated time must be a positive number of seconds, got {self.duration}", "duration")
        self.steps_per_sample()
        self.adaptive(False)

    def _fold_former(self) -> None:
        """Move the settings given in their former places into ``loop`` (and ``counts``)."""
        for name, kind in (("wall", Wall), ("compensator", Compensator), ("sensors", (Sensors, type(None)))):
            if not isinstance(getattr(self, name), kind):
                raise UserError(f"{name} must be a {name.capitalize()}, got {type(getattr(self, name)).__name__}")
        changes, sensors = {}, self.sensors
        if sensors is not None:
            changes.update(period=sensors.period, delay=int(sensors.delay_samples))
            object.__setattr__(self, "counts", sensors.counts_per_revolution)
        if self.hand is not None:
            renamed("LoopConfig(hand=...)", "SampledLoop(hand=...) of LoopConfig(loop=...)")
            changes["hand"] = self.hand
        if self.wall.damping is not None:
            changes["wall_damping"] = self.wall.damping
            object.__setattr__(self, "wall", replace(self.wall, damping=None))
        if self.compensator.error_percent is not None:
            changes["error_percent"] = self.compensator.error_percent
            object.__setattr__(self, "compensator", replace(self.compensator, error_percent=None))
        if changes:
            object.__setattr__(self, "loop", replace(self.loop, **changes))
        object.__setattr__(self, "sensors", None)
        object.__setattr__(self, "hand", None)

    def require_simulated(self) -> None:
        """The run's loop can be simulated: its damper uses the sampled velocity (a backward-difference damper is
        analysed exactly only)."""
        if self.loop.velocity == "difference" and self.loop.wall_damping > 0:
            raise InputError("the simulated wall's damper uses the sampled velocity; a backward-difference damper is "
                             "analysed exactly only", "velocity")

    @property
    def switches(self) -> tuple[bool, bool, bool]:
        """The inertial, Coriolis and gravity terms the compensator feeds forward: the loop's compensation's, less
        those the :class:`Compensator` drops."""
        full, comp = self.loop.compensation == "full", self.compensator
        return (full and comp.inertial, full and comp.coriolis, self.loop.compensation != "none" and comp.gravity)

    def adaptive(self, closed_loop: bool) -> bool:
        """Whether the run controls its steps by error (``step_control``, for a closed-loop device or not)."""
        if self.step_control not in STEP_CONTROLS:
            raise InputError(f"unknown step control {str(self.step_control)[:40]!r}; choose one of "
                             f"{', '.join(STEP_CONTROLS)}", "step_control")
        if not (self.tolerance > 0 and math.isfinite(self.tolerance)):
            raise InputError(f"the step tolerance must be a positive number, got {self.tolerance}", "tolerance")
        return self.step_control == "adaptive" or (self.step_control == "auto" and closed_loop)

    def steps_per_sample(self) -> int:
        if not (self.step > 0 and math.isfinite(self.step)):
            raise InputError(f"the plant step must be positive, got {self.step}", "step")
        period = self.loop.period
        ratio = period / self.step
        if not math.isfinite(ratio):
            raise InputError(f"the sample period {period} s over the plant step {self.step} s overflows", "period", "step")
        if abs(ratio - round(ratio)) > 1e-9 * ratio or round(ratio) < 1:
            raise InputError(f"the plant step {self.step} s does not divide the sample period {period} s", "step", "period")
        return int(round(ratio))


@dataclass
class Trace:
    """Recorded signals (rows every ``stride`` plant steps) and how the run ended.

    ``wall_position`` is the wall coordinate at the recorded rows: the wall joint's position, or the handle's
    position along a Cartesian wall's direction (m). ``peak`` is its largest excursion from the
    start, checked at every plant step (not only at the recorded rows; inside an adaptive step from
    the interpolated wall coordinate); ``end_time`` is when the run
    ended (early when it diverged, reached the excursion stop or, for a closed-loop device, left the
    assembly branch)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    u: np.ndarray
    tau_f: np.ndarray
    tau_imp: np.ndarray
    tau_c: np.ndarray
    status: int
    trip_time: float | None
    peak: float = math.nan
    end_time: float = math.nan
    wall_position: np.ndarray | None = None
    steps: int | None = None
    """Integration steps taken (plant steps with a fixed step, fewer with an adaptive one; None from the
    SciPy loop)."""

    @property
    def diverged(self) -> bool:
        return self.status == STATUS_DIVERGED

    @property
    def stopped_at_excursion(self) -> bool:
        return self.status == STATUS_EXCURSION

    @property
    def loop_lost(self) -> bool:
        """A closed-loop device's loops stopped closing on the assembly branch (:data:`STATUS_LOOP_LOST`)."""
        return self.status == STATUS_LOOP_LOST

    @property
    def tripped(self) -> bool:
        return self.trip_time is not None


def require_device(device: object) -> Device:
    """``device`` itself when it is a :class:`Device`; anything else is a :class:`UserError`."""
    if not isinstance(device, Device):
        raise UserError(f"expected a Device (e.g. hapticdesign.preset('phantom-3dof')), got {type(device).__name__} "
                        f"{str(device)[:40]!r}")
    return device


def require_options(sim_type: object, config: object, config_type: type) -> None:
    """The simulation type is 1 or 2 and ``config`` (when given) a ``config_type``."""
    if isinstance(sim_type, bool) or sim_type not in (1, 2):
        raise UserError(f"simulation type must be 1 or 2, got {sim_type!r}")
    if config is not None and not isinstance(config, config_type):
        raise UserError(f"config must be a {config_type.__name__}, got {type(config).__name__}")


def compensator_device(device: Device, config: LoopConfig) -> Device:
    """The device the compensator of the run ``config`` models, with the loop's modelling error spread as its
    :class:`Compensator` says (:func:`model_device`)."""
    comp = config.compensator
    return model_device(device, config.loop.error_percent, comp.group_errors, comp.error_seed)


def loop_model(device: Device, loop: SampledLoop, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The compensator's own inertia ``H_m`` and gravity gradient ``dG_m/dq`` at the actuated ``pose`` under the
    settings ``loop``: those of :func:`model_device` with the loop's modelling error (which scales the mass centres
    too, so ``H_m`` and ``G_m`` are not ``(1 - E/100)`` times the device's, and motors' rotors are not scaled); None
    without a modelling error (the model is the device). The exact limits take them
    (:func:`hapticdesign.analysis.sampled_loop.handle_loops`), as the simulation's compensator does."""
    if loop.error_percent == 0:
        return None
    model = model_device(device, loop.error_percent)
    return mass_matrix(model, pose), gravity_gradient(model, pose)


REST_STEPS = 30
"""Most Newton steps of :func:`spring_rest` (and of the fixed points that call it)."""


def spring_rest(device: Device, model: Device | None, rest: np.ndarray, row: np.ndarray, stiffness: float,
                free: list[int], hand: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray | None:
    """Where a wall's spring ``stiffness`` along the joint row ``row`` (``w``, resting at the actuated pose ``rest``)
    holds ``device`` against the gravity its compensator leaves, ``tau_r = -(G - G_m)`` (``model`` the compensator's
    device, None without gravity compensation) and a hand's spring ``hand = (K_h, q_h)`` (``-K_h (q - q_h)``): the
    pose ``rest + delta d`` (``d = w / |w|^2`` over the ``free`` joints, the least joint motion that moves the wall
    coordinate by one) where ``d^T tau = K delta``, by Newton's method on ``delta`` (slope ``K + d^T (K_G - K_Gm +
    K_h) d``). ``rest`` itself (the same array) when nothing pushes there; None when the spring and the static
    stiffness do not hold the device (a non-positive slope) or no balance is found in :data:`REST_STEPS` steps. Along
    the wall nothing but gravity's own stiffness resists the leftover torque: the other directions stay (a drift the
    loop deflates)."""
    k_h, q_h = (np.zeros((device.n_dof, device.n_dof)), rest) if hand is None else hand
    d = np.zeros(device.n_dof)
    d[free] = row[free] / float(row[free] @ row[free])
    delta = 0.0
    for _ in range(REST_STEPS):
        q = rest + delta * d
        torque = -gravity(device, q) + (0.0 if model is None else gravity(model, q)) - k_h @ (q - q_h)
        balance = float(d @ torque) - stiffness * delta
        if delta == 0.0 and balance == 0.0:
            return rest
        stiff = gravity_gradient(device, q) - (0.0 if model is None else gravity_gradient(model, q)) + k_h
        slope = stiffness + float(d @ stiff @ d)
        if not slope > 0.0:
            return None
        step = balance / slope
        delta += step
        if abs(step) <= 1e-12 * max(1.0, abs(delta)):
            return rest + delta * d
    return None


def rest_pose(device: Device) -> np.ndarray:
    """Where the experiments start and the joint paths are centred: q = 0 for an open chain (the seed's),
    the file's ``home`` actuated pose for a closed-loop device (whose loops need not close at 0)."""
    return configuration_of(device).home.copy()


def plant_friction(device: Device, config: LoopConfig) -> tuple[np.ndarray, np.ndarray]:
    """The plant's Coulomb friction ``(A, f)``: torque ``sum_k f_k sign(a_k^T qd) a_k`` (rows ``a_k`` of ``A``).

    The configuration's values act one per joint (``A = I``); else the device's motors with friction act on
    the combinations they turn (:attr:`~hapticdesign.model.device.Device.friction`); else there is none."""
    if config.coulomb is None:
        return device.friction
    friction = np.asarray(config.coulomb, dtype=float)
    if friction.shape != (device.n_dof,) or not np.all(np.isfinite(friction)) or np.any(friction < 0):
        raise UserError(f"expected {device.n_dof} finite, non-negative Coulomb friction values, got "
                        f"{np.atleast_1d(friction).tolist()[:8]}")
    return np.eye(device.n_dof), friction


def plant_damping(device: Device, config: LoopConfig) -> np.ndarray:
    """The plant's viscous damping matrix: ``diag`` of the configuration's values, else the device's
    (:attr:`~hapticdesign.model.device.Device.damping_matrix`, motors on combinations of joints included)."""
    if config.damping is not None:
        return np.diag(np.asarray(config.damping, dtype=float))
    return device.damping_matrix


def handle_jacobian(device: Device, q: np.ndarray) -> np.ndarray:
    """The handle's geometric Jacobian (6 x n) over the actuated coordinates at ``q``: ``J`` of a tree,
    ``J T`` of a closed-loop device at its closed pose on the assembly branch."""
    return configuration_of(device).jacobian(np.asarray(q, dtype=float))


def normal_jacobian(device: Device, wall: Wall, q: np.ndarray) -> np.ndarray:
    """``J_n = n^T J_v`` (1 x n): the handle's velocity along a Cartesian wall's direction per actuated joint velocity."""
    return unit_direction(wall.direction) @ handle_jacobian(device, q)[:3]


def hand_matrices(device: Device, hand: Hand | None, q0: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hand mass, damping and stiffness in (actuated) joint space: ``x J_v^T J_v`` at the start pose ``q0``,
    ``J_v`` of :func:`handle_jacobian` (``J_v T`` for a closed-loop device)."""
    n = len(q0)
    if hand is None:
        return np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    jv = handle_jacobian(device, q0)[:3]
    jtj = jv.T @ jv
    return hand.mass * jtj, hand.damping * jtj, hand.stiffness * jtj
