"""The stable impedance range without integrating an ODE: the sampled loop linearized about the pose.

With the other joints held (type 1) the wall joint of any device is a 1-DOF system about the start
pose ``q0`` (eq. 2.50 at rest there): inertia ``J = H_ww(q0)``, damping ``b_w``, gravity's stiffness
``dG_w/dq_w``, a hand's mass, damping and spring (``x J_v^T J_v``), and a constant torque, the gravity
the compensator leaves (``G_w - s_G G_model,w``). Coriolis terms vanish at rest. The compensator feeds its
own model's ``H_model,ww a`` forward (its model has no hand; a modelling error changes it) and its
gravity stiffness ``s_G dG_model,w/dq_w`` on the sensed pose. That loop is the one-joint case of the one
sampled loop of every command, :func:`hapticdesign.analysis.sampled_loop.handle_loops` (:func:`wall_loops`),
under the seed's sampled velocity. For joint 1 of the Phantom (vertical axis, cyclic) this is exact for
every design. In type 2 the other joints move: when the wall joint's row of H, C, G does not depend on
them (LN = 0 designs) the same 1-DOF loop is exact; otherwise the loop is linear time-varying along the
motion and :mod:`.analytic_driven` answers with the product of its one-sample transition matrices (exact
for a cyclic wall joint such as the Phantom's joint 1, linearized in the wall joint otherwise). A
Cartesian wall, a hand or a closed-loop device in type 2 keeps the start-pose loop (``exact`` false). The
growth check (:meth:`AnalyticProblem.grows`) takes the loop where the wall holds the joint
(:func:`equilibrium_pose`): the free joint travels to the spring's rest and oscillates there, so
stability is decided there, not at the start.

The seed's criteria are then evaluated on the exact linear response: the loop about the start pose is
affine (the constant torque, the springs' rests), so the deviation from its fixed point follows the
linear map, sample by sample, and the exact sub-sample transition of the plant under the held torque
gives the excursion at every plant step (as the simulation checks it). No ODE is integrated.
Quantized encoders and Coulomb friction are not linear: the analytic method refuses them.

A Cartesian wall (spring K in N/m, damper B in N s/m along n at the handle) acts on the free joint w
as the joint wall ``K J_n,w^2``, ``B J_n,w^2`` (the joint-space stiffness ``J_n^T K J_n`` of the
held chain, ``J_n = n^T J_v`` at the start pose), and its criteria apply to the wall-normal output
``J_n,w (q_w - q_w0)``. That is exact when the handle moves linearly along n with the free joint
(``J_n,w`` constant over its travel and the driven motion, e.g. a prismatic joint); otherwise a
small-displacement approximation, and ``exact`` says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
from threadpoolctl import ThreadpoolController

from hapticdesign.analysis.dynamics.device import (
    coriolis_centrifugal, dynamics_of, gravity, gravity_gradient, mass_matrix,
)
from hapticdesign.analysis.dynamics.model import has_trigonometric_basis
from hapticdesign.analysis.sampled_loop import Hand, SampledLoop, SpringLoops, handle_loops, held_plant
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.analytic_driven import DrivenLoop
from hapticdesign.simulation.config import (
    LoopConfig, compensator_device, handle_jacobian, normal_jacobian, plant_friction, rest_pose, spring_rest,
)
from hapticdesign.simulation.criteria import Verdict, WallProblem, type_paths


GROWS = "oscillation grows"
"""The verdict of a stiffness whose linearized loop is unstable although the run met the criteria."""


@lru_cache(maxsize=1)
def _threads() -> ThreadpoolController:
    """The process's thread pools, found once (finding them reads the loaded libraries)."""
    return ThreadpoolController()


def one_blas_thread():
    """A context with BLAS on one thread: the matrices here are of order 6 to 20, and on a shared
    machine a BLAS thread pool costs 20 x the arithmetic (measured)."""
    return _threads().limit(limits=1, user_api="blas")


@dataclass(frozen=True)
class WallJoint:
    """The wall joint linearized at a pose (eq. 2.50 at rest there): its inertia ``H_ww`` and damping ``b_w`` (a
    hand's are added by the loop through ``reach``, the joint's column of ``J_v``), gravity's stiffness
    ``dG_w/dq_w``, the compensator's inertia ``H_m,ww`` and gravity stiffness ``dG_m,w/dq_w`` (0 where its switches
    leave them out), the constant torque it leaves (``-(G_w - s_G G_m,w)``), whether this 1-DOF loop is exact, and
    ``scale``, the wall coordinate per unit of the joint (1 for a joint wall, ``J_n,w`` for a Cartesian wall: its
    spring and damper act on the joint as ``K J_n,w^2`` and ``B J_n,w^2``)."""

    inertia: float
    damping: float
    reach: np.ndarray
    gravity: float
    model_inertia: float
    model_gravity: float
    torque: float
    exact: bool
    scale: float = 1.0

    @property
    def fraction(self) -> float:
        """The compensator's share ``c = H_m,ww / H_ww`` of the inertia it feeds forward."""
        return self.model_inertia / self.inertia

    def plant(self, hand: Hand | None) -> tuple[float, float, float]:
        """The joint's inertia, damping and stiffness with the hand (``x J_v^T J_v``, its spring resting at the
        start) and gravity's stiffness."""
        hand = hand or Hand()
        r2 = float(self.reach @ self.reach)
        return self.inertia + hand.mass * r2, self.damping + hand.damping * r2, hand.stiffness * r2 + self.gravity


def wall_loop(config: LoopConfig) -> SampledLoop:
    """The settings of :func:`wall_loops` from ``config``: its period, delay, wall damper and hand, the sampled
    velocity and the full compensator (each wall's own model)."""
    return replace(config.loop, velocity="sampled", compensation="full", error_percent=0.0, held=())


def wall_loops(walls: list[WallJoint], config: LoopConfig) -> SpringLoops:
    """The sampled loops of the walls' joints under the settings of ``config`` (its period, delay, wall damper and
    hand; the sampled velocity, the seed's): the one-joint case of
    :func:`hapticdesign.analysis.sampled_loop.handle_loops`, with each wall's own compensator model."""
    loop = wall_loop(config)
    column = np.array([[[w.inertia]] for w in walls]), np.array([[[w.damping]] for w in walls])
    model = np.array([[[w.model_inertia]] for w in walls]), np.array([[[w.model_gravity]] for w in walls])
    loop.require_exact(1, len(walls))
    return handle_loops(np.array([w.reach for w in walls])[:, :, None], *column,
                        np.array([[w.scale] for w in walls]), loop,
                        gravity=np.array([[[w.gravity]] for w in walls]), model=model)[0]


def linear_loop(device: Device, config: LoopConfig) -> bool:
    """Whether the sampled loop is linear about a pose: no encoder quantization, no Coulomb friction."""
    return config.counts is None and not np.any(plant_friction(device, config)[1] > 0)


def start_pose(device: Device, sim_type: int, wall_joint: int) -> tuple[np.ndarray, np.ndarray, dict]:
    """The rest pose, the pose a run starts at (the other joints at their paths' start) and the paths."""
    rest = rest_pose(device)
    paths = type_paths(sim_type, device.n_dof, wall_joint, rest)
    q0 = rest.copy()
    for j, path in paths.items():
        q0[j] = float(path.sample(np.zeros(1))[0][0])
    return rest, q0, paths


def equilibrium_pose(device: Device, sim_type: int, wall_joint: int, config: LoopConfig,
                     equilibrium: float) -> np.ndarray:
    """The pose the wall holds: the start pose with the free joint where the spring rests, ``q_w0 + equilibrium``
    for a joint wall, and for a Cartesian wall where the handle has moved ``equilibrium`` metres along the wall's
    direction from its start, ``n^T (x(q) - x(q_0)) = equilibrium``, solved for ``q_w`` by Newton's method on
    ``J_n,w`` (closed loops closed at every iterate by :func:`~.config.handle_jacobian`'s configuration)."""
    from hapticdesign.analysis.configuration import configuration_of

    _, q0, _ = start_pose(device, sim_type, wall_joint)
    q = q0.copy()
    if not config.wall.cartesian:
        q[wall_joint] += equilibrium
        return q
    space = configuration_of(device)
    n = np.asarray(config.wall.direction, dtype=float)
    x0 = float(n @ space.pose(q0)[:3, 3])
    for _ in range(50):
        miss = equilibrium - (float(n @ space.pose(q)[:3, 3]) - x0)
        if abs(miss) <= 1e-13 * max(1.0, abs(equilibrium)):
            return q
        reach = float(normal_jacobian(device, config.wall, q)[wall_joint])
        if abs(reach) < 1e-12:
            break
        q[wall_joint] += miss / reach
    raise UserError(f"the wall's rest {equilibrium:g} m along its direction is not reached by joint {wall_joint + 1} "
                    "from the start pose")


def linearize(device: Device, sim_type: int, wall_joint: int, config: LoopConfig,
              pose: np.ndarray | None = None) -> WallJoint:
    """The 1-DOF sampled loop of the wall joint at ``pose`` (default: the start pose; see the module docstring)."""
    if config.counts is not None:
        raise UserError("the analytic method has no encoder quantization (not linear): use the simulation")
    if np.any(plant_friction(device, config)[1] > 0):
        raise UserError("the analytic method has no Coulomb friction (not linear): use the simulation")
    rest, q0, paths = start_pose(device, sim_type, wall_joint)
    if pose is not None:
        q0 = np.asarray(pose, dtype=float)
    w = wall_joint
    damping = np.asarray(config.damping if config.damping is not None else device.damping, dtype=float)
    model = compensator_device(device, config)
    inertial, _, gravity_term = config.switches
    reach = handle_jacobian(device, q0)[:3, w]
    wall = WallJoint(
        inertia=float(mass_matrix(device, q0)[w, w]), damping=float(damping[w]), reach=reach,
        gravity=float(gravity_gradient(device, q0)[w, w]),
        model_inertia=float(mass_matrix(model, q0)[w, w]) if inertial else 0.0,
        model_gravity=float(gravity_term * gravity_gradient(model, q0)[w, w]),
        torque=-(float(gravity(device, q0)[w]) - gravity_term * float(gravity(model, q0)[w])),
        exact=sim_type == 1 or _decoupled(device, w, paths, rest))
    if not config.wall.cartesian:
        return wall
    scale = float(normal_jacobian(device, config.wall, q0)[w])
    if abs(scale) < 1e-12:
        raise UserError(f"joint {w + 1} does not move the handle along the wall direction at the start pose")
    return replace(wall, scale=scale, exact=wall.exact and _linear_along_wall(device, config, w, q0, paths))


def _linear_along_wall(device: Device, config: LoopConfig, w: int, q0: np.ndarray, paths: dict) -> bool:
    """True when ``J_n = n^T J_v`` of the free joint is the same over its travel and the driven motion,
    i.e. the handle moves linearly along the wall direction (a prismatic joint along it)."""
    t = np.linspace(0.0, 2.0, 9)
    qs = np.tile(q0, (len(t), 1))
    for j, path in paths.items():
        qs[:, j] = path.sample(t)[0]
    qs[:, w] += np.linspace(-0.1, 0.1, len(t))
    rows = np.array([normal_jacobian(device, config.wall, q)[w] for q in qs])
    return bool(np.all(np.abs(rows - rows[0]) <= 1e-9 * max(abs(rows[0]), 1e-12)))


def _decoupled(device: Device, w: int, paths: dict, rest: np.ndarray) -> bool:
    """True when the wall joint's row of H, C, G does not change along the driven motion."""
    t = np.linspace(0.0, 2.0, 9)
    qs = np.tile(rest, (len(t), 1))
    for j, path in paths.items():
        qs[:, j] = path.sample(t)[0]
    rows = [np.concatenate([mass_matrix(device, q)[w], coriolis_centrifugal(device, q)[w], [gravity(device, q)[w]]]) for q in qs]
    scale = max(float(np.abs(rows[0]).max()), 1e-12)
    return all(np.abs(r - rows[0]).max() <= 1e-9 * scale for r in rows)


def _sub_steps(plant: tuple[np.ndarray, np.ndarray], count: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Exact transitions of ``(q, qd)`` over ``0, h, ..., (count - 1) h`` under a held torque, from the plant's
    one-step ``(Phi_h, Gamma_h)``: ``Phi_(j+1) = Phi_h Phi_j``, ``Gamma_(j+1) = Phi_h Gamma_j + Gamma_h``."""
    phi_h, gamma_h = plant
    steps = [(np.eye(2), np.zeros(2))]
    for _ in range(count - 1):
        phi, gamma = steps[-1]
        steps.append((phi_h @ phi, phi_h @ gamma + gamma_h))
    return steps


def _powers(m: np.ndarray, s0: np.ndarray, samples: int) -> np.ndarray:
    """``[s0, M s0, ..., M^samples s0]`` through the eigen-decomposition of ``M`` (one vectorized power
    per eigenvalue), or sample by sample when ``M`` is close to defective."""
    with np.errstate(over="ignore", invalid="ignore"):
        lam, vec = np.linalg.eig(m)
        if np.linalg.cond(vec) < 1e8:
            coef = np.linalg.solve(vec, s0.astype(complex))
            powers = np.empty((samples + 1, len(lam)), dtype=complex)
            powers[0] = 1.0
            powers[1:] = lam
            np.cumprod(powers, axis=0, out=powers)
            return ((powers * coef[None, :]) @ vec.T).real
        states = np.empty((samples + 1, len(s0)))
        states[0] = s0
        for k in range(samples):
            states[k + 1] = m @ states[k]
        return states


@dataclass
class AnalyticProblem(WallProblem):
    """The analytic counterpart of :class:`~hapticdesign.simulation.impedance.ImpedanceProblem`:
    the same ``verdict(K)`` and ``estimate()``, so the searches (fast, linear, grid) use it as is."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.wall = linearize(self.device, self.sim_type, self.wall_joint, self.config)
        self.held = self._held()
        self.rest = self.equilibrium / self.wall.scale  # the spring's rest in joint units
        self.sub = self.config.steps_per_sample()
        self.samples = int(round(self.config.duration / self.config.loop.period))
        self.driven = None
        with one_blas_thread():
            self.loops = wall_loops([self.wall, self.held], self.config)
            inertia, damping, stiffness = (np.full((1, 1, 1), v) for v in self.wall.plant(self.config.loop.hand))
            phi, gamma = held_plant(inertia, damping, stiffness, self.config.step)
            self._steps = _sub_steps((phi[0], gamma[0, :, 0]), self.sub)
            if self._time_varying():
                self.driven = self._driven_loop()

    def _held(self) -> WallJoint:
        """The loop linearized where the wall's spring rests (:func:`equilibrium_pose`): its growth decides
        stability, the start pose's need not (the free joint travels to the rest before it oscillates there)."""
        self.held_pose = equilibrium_pose(self.device, self.sim_type, self.wall_joint, self.config, self.equilibrium)
        return linearize(self.device, self.sim_type, self.wall_joint, self.config, self.held_pose)

    def _resting(self, stiffness: float) -> WallJoint | None:
        """The wall joint linearized where the wall holds it under the spring ``stiffness``
        (:func:`~.config.spring_rest` on the wall joint alone: the residual gravity torque ``-(G_w - s_G G_m,w)`` and
        a hand's spring, resting at the start pose, move the pose by about their torque over ``K``); the loop at the
        spring's rest when nothing pushes there, None when the wall cannot hold the joint (it falls)."""
        w, held = self.wall_joint, self.held
        hand = self.config.loop.hand or Hand()
        row = np.zeros(self.device.n_dof)
        row[w] = held.scale
        hand_spring = np.zeros((self.device.n_dof, self.device.n_dof))
        hand_spring[w, w] = hand.stiffness * float(held.reach @ held.reach)
        start = start_pose(self.device, self.sim_type, w)[1]
        model = compensator_device(self.device, self.config) if self.config.switches[2] else None
        pose = spring_rest(self.device, model, self.held_pose, row, stiffness, [w], (hand_spring, start))
        if pose is None:
            return None
        return held if pose is self.held_pose else linearize(self.device, self.sim_type, w, self.config, pose)

    def _time_varying(self) -> bool:
        """Type 2 with the wall joint coupled to the motion, on a joint wall of an open chain without a hand."""
        cfg = self.config
        return (self.sim_type == 2 and not self.wall.exact and not cfg.wall.cartesian and cfg.loop.hand is None
                and has_trigonometric_basis(self.device.mechanism))

    def _driven_loop(self) -> DrivenLoop:
        device, cfg, w = self.device, self.config, self.wall_joint
        rest = rest_pose(device)
        damping = np.asarray(cfg.damping if cfg.damping is not None else device.damping, dtype=float)
        switches = tuple(float(on) for on in cfg.switches)
        return DrivenLoop.build(device, compensator_device(device, cfg), w, type_paths(2, device.n_dof, w, rest), rest,
                                float(damping[w]), switches, cfg.loop.period, self.sub, self.samples,
                                cfg.loop.delay, cfg.loop.wall_damping, self.rest)

    @property
    def exact(self) -> bool:
        if self.driven is not None:
            return bool(dynamics_of(self.device).cyclic[self.wall_joint] and
                        dynamics_of(compensator_device(self.device, self.config)).cyclic[self.wall_joint])
        return self.wall.exact

    @property
    def growth_is_exact(self) -> bool:
        """Whether :meth:`grows` decides the wall's stability: type 1 (the held joints leave the wall joint one
        time-invariant loop about the start pose, exact to first order there), or a driven motion that does not
        reach the wall joint's row of H, C, G (:attr:`exact`)."""
        return self.sim_type == 1 or self.exact

    def estimate(self) -> float:
        inertia, damping, _ = self.wall.plant(self.config.loop.hand)
        joint = damping ** 2 / inertia if self.wall.model_inertia > 0 else 2.0 * damping / self.config.loop.period
        return joint / self.wall.scale ** 2

    def response(self, stiffness: float) -> np.ndarray:
        """The wall coordinate from its start (``q - q0``, or ``J_n,w (q - q0)`` along a Cartesian wall) at every
        plant step (rows: samples, columns: plant steps within the period).

        The loop about the start pose is affine: the constant torque and the springs' rests (the wall's at
        ``equilibrium``, the hand's at the start) move its fixed point to ``x*`` (the spring, the hand's and
        gravity's stiffness and the compensator's balance there, at rest, torque ``u*``), and the deviation from it
        follows the linear map of :func:`wall_loops`: ``e_k = m(K)^k e_0``. The run starts at rest at the start
        pose with the delay line holding the first sample and the compensator's torque memory such that it reads no
        acceleration (the seed's initial conditions); between samples the plant moves exactly under the held torque.
        """
        wall = self.wall
        _, _, k = wall.plant(self.config.loop.hand)
        s2 = wall.scale ** 2
        push = wall.torque - k * self.rest  # the constant torque in the spring's coordinate p = x - rest
        with np.errstate(divide="ignore", invalid="ignore"):
            p_eq = (push + wall.model_gravity * self.rest) / (k - wall.model_gravity + stiffness * s2)
        u_eq = -stiffness * s2 * p_eq + wall.model_gravity * (p_eq + self.rest)
        size, lines = self.loops.base.shape[-1], 2 * (self.config.loop.delay + 1)
        start, fixed = np.zeros(size), np.zeros(size)
        start[:lines:2], fixed[:lines:2] = -self.rest, p_eq
        start[lines:], fixed[lines:] = -k * self.rest - push, u_eq
        m = self.loops.matrices(np.array([stiffness]), [0])[0]
        states = _powers(m, start - fixed, self.samples)
        du = self.loops.torques(stiffness, states, 0)[:, 0]
        cols = [phi[0, 0] * states[:, 0] + phi[0, 1] * states[:, 1] + gamma[0] * du for phi, gamma in self._steps]
        return (np.stack(cols, axis=1) + p_eq + self.rest) * wall.scale

    def grows(self, stiffness: float) -> bool:
        """Whether the linearized sampled loop is unstable at ``stiffness``: the spectral radius of its
        one-sample map (the constant state of the affine part left out) exceeds 1, or along a driven motion
        (:mod:`.analytic_driven`) its largest Floquet multiplier over the motion's period (not decided, so
        False, when the run is shorter than a period). For type 1 this is the exact local growth boundary
        of the wall (Lyapunov's indirect method for the sampled system), linearized where the wall holds the
        joint under the spring (:meth:`_resting`; a spring that cannot hold it grows)."""
        if self.driven is not None:
            with one_blas_thread():
                return bool(self.driven.floquet_radius(stiffness) > 1.0)
        wall = self._resting(stiffness)
        if wall is None:
            return True
        with one_blas_thread():
            loops, index = (self.loops, 1) if wall is self.held else (wall_loops([wall], self.config), 0)
            radius = float(loops.radii(np.array([stiffness]), [index])[0])
        return not radius < 1.0

    def verdict(self, stiffness: float) -> Verdict:
        """The seed's criteria on the exact linear response (overshoot checked at every plant step); where
        the growth of the linearized loop is the wall's (:attr:`growth_is_exact`), a stiffness at which it
        grows is not stable whatever the criteria saw in the run's duration (:meth:`grows`)."""
        with one_blas_thread():
            q = self.response(stiffness) if self.driven is None else self.driven.response(stiffness)
        flat = q.reshape(-1)[: self.samples * self.sub + 1]
        finite = np.isfinite(flat)
        excursion = np.abs(flat)
        limit = min(self.criteria.overshoot_limit, self.criteria.safety_limit)
        crossing = np.nonzero(~finite | (excursion >= limit))[0]
        if crossing.size:
            i = int(crossing[0])
            peak = float(excursion[i]) if finite[i] else math.inf
            cause = "diverged" if not finite[i] else (
                "overshoot" if excursion[i] >= self.criteria.overshoot_limit else "safety switch")
            return Verdict(stiffness, False, cause, peak, math.nan, i * self.config.step)
        peak = float(excursion.max())
        samples = q[:, 0]
        t = np.arange(len(samples)) * self.config.loop.period
        tail = samples[t >= t[-1] - self.criteria.settle_window]
        final = float(np.max(np.abs(tail - self.equilibrium)))
        if final > self.criteria.settle_tolerance:
            return Verdict(stiffness, False, "not settled", peak, final)
        if self.growth_is_exact and self.grows(stiffness):
            return Verdict(stiffness, False, GROWS, peak, final)
        return Verdict(stiffness, True, "stable", peak, final)
