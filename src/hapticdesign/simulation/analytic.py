"""The stable impedance range without integrating an ODE: the sampled loop linearized about the pose.

With the other joints held (type 1) the wall joint of any device is a 1-DOF system about the start
pose ``q0``: inertia ``J = H_ww(q0)`` (plus a hand's mass ``m_h J_v^T J_v``), damping ``b_w`` (plus
the hand's), a physical spring from a hand's stiffness, and a constant torque, the gravity the
compensator leaves (``G_w - s_G G_model,w``). Coriolis terms vanish at rest. The compensator feeds
``c J a`` forward with ``c = H_model,ww / J`` (its model has no hand; a modelling error lowers it).
For joint 1 of the Phantom (vertical axis, cyclic) this is exact for every design. In type 2 the
other joints move: when the wall joint's row of H, C, G does not depend on them (LN = 0 designs)
the same 1-DOF loop is exact; otherwise the loop is linear time-varying along the motion and
:mod:`.analytic_driven` answers with the product of its one-sample transition matrices (exact for a
cyclic wall joint such as the Phantom's joint 1, linearized in the wall joint otherwise). A Cartesian
wall, a hand or a closed-loop device in type 2 keeps the start-pose loop (``exact`` false). The growth check
(:meth:`AnalyticProblem.grows`) takes the loop where the wall holds the joint (:func:`equilibrium_pose`): the free
joint travels to the spring's rest and oscillates there, so stability is decided there, not at the start.

The seed's criteria are then evaluated on the exact linear response: the closed loop (plant discretized exactly,
:func:`_plant`; the digital side a discrete state-space system, :func:`_controller`) gives the state at every
sample, and the exact sub-sample transition of the plant under the held torque gives the excursion at every plant
step (as the simulation checks it). No ODE is integrated.
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
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.linalg import expm
from threadpoolctl import ThreadpoolController

from hapticdesign.analysis.dynamics.device import coriolis_centrifugal, dynamics_of, gravity, mass_matrix
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.analytic_driven import DrivenLoop
from hapticdesign.simulation.config import (
    LoopConfig, compensator_device, handle_jacobian, normal_jacobian, plant_friction, rest_pose,
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
    """The wall joint linearized at the start pose: its inertia ``J``, damping ``b`` and physical spring ``k_p`` (a
    hand's), the compensator's share ``c`` of ``J a``, the constant torque on it, and ``scale``, the wall coordinate
    per unit of the joint (1 for a joint wall, ``J_n,w`` for a Cartesian wall: its spring and damper act on the joint
    as ``K J_n,w^2`` and ``B J_n,w^2``)."""

    inertia: float
    damping: float
    stiffness: float
    fraction: float
    torque: float
    exact: bool
    scale: float = 1.0


def _plant(wall: WallJoint, step: float) -> tuple[np.ndarray, np.ndarray]:
    """``J qdd + b qd + k_p q = u`` over ``step`` under a held ``u``, exactly (``scipy.linalg.expm`` of the augmented
    matrix): ``Phi`` (2, 2) and ``Gamma`` (2,) of ``(q, qd)``."""
    a = np.zeros((3, 3))
    a[0, 1] = 1.0
    a[1, 0] = -wall.stiffness / wall.inertia
    a[1, 1] = -wall.damping / wall.inertia
    a[1, 2] = 1.0 / wall.inertia
    e = expm(a * step)
    return e[:2, :2], e[:2, 2]


def _controller(wall: WallJoint, delay: int, stiffness: float,
                virtual_damping: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The digital side ``(A, B, C, D)`` from ``(q_k, v_k)`` to ``u_k = -K q_(k-N) - B v_(k-N) + c (u_(k-N-1) -
    b v_(k-N) - k_p q_(k-N))`` (the sampled velocity, the seed's), state ``q_(k-1..k-N-1)``, ``v_(k-1..k-N)``,
    ``u_(k-1..k-N-1)``."""
    n = delay
    nq, nv, nu = n + 1, n, n + 1
    size = nq + nv + nu
    c, d = np.zeros(size), np.zeros(2)

    def add(signal: str, lag: int, gain: float) -> None:
        """Add ``gain * signal_(k - lag)`` to the output."""
        if lag == 0:
            d["qv".index(signal)] += gain
        else:
            c[{"q": 0, "v": nq, "u": nq + nv}[signal] + lag - 1] += gain

    add("q", n, -stiffness - wall.fraction * wall.stiffness)
    add("v", n, -virtual_damping - wall.fraction * wall.damping)
    add("u", n + 1, wall.fraction)
    a, b = np.zeros((size, size)), np.zeros((size, 2))
    b[0, 0] = 1.0  # q_k enters the position line
    a[1:nq, 0:nq - 1] = np.eye(nq - 1)
    if nv:
        b[nq, 1] = 1.0
        a[nq + 1:nq + nv, nq:nq + nv - 1] = np.eye(nv - 1)
    a[nq + nv] = c  # u_k enters the torque line
    b[nq + nv] = d
    a[nq + nv + 1:, nq + nv:size - 1] = np.eye(nu - 1)
    return a, b, c[None, :], d[None, :]


def linear_loop(device: Device, config: LoopConfig) -> bool:
    """Whether the sampled loop is linear about a pose: no encoder quantization, no Coulomb friction."""
    return config.sensors.counts_per_revolution is None and not np.any(plant_friction(device, config)[1] > 0)


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
    if config.sensors.counts_per_revolution is not None:
        raise UserError("the analytic method has no encoder quantization (not linear): use the simulation")
    if np.any(plant_friction(device, config)[1] > 0):
        raise UserError("the analytic method has no Coulomb friction (not linear): use the simulation")
    rest, q0, paths = start_pose(device, sim_type, wall_joint)
    if pose is not None:
        q0 = np.asarray(pose, dtype=float)
    w = wall_joint
    damping = np.asarray(config.damping if config.damping is not None else device.damping, dtype=float)
    h, g = mass_matrix(device, q0), gravity(device, q0)
    model = compensator_device(device, config.compensator)
    j_device = float(h[w, w])
    j, b, spring = j_device, float(damping[w]), 0.0
    if config.hand is not None:
        jv = handle_jacobian(device, q0)[:3, w]
        reach = float(jv @ jv)
        j += config.hand.mass * reach
        b += config.hand.damping * reach
        spring = config.hand.stiffness * reach
    comp = config.compensator
    fraction = float(mass_matrix(model, q0)[w, w]) / j_device if comp.inertial else 0.0
    torque = -(float(g[w]) - comp.gravity * float(gravity(model, q0)[w]))
    exact = sim_type == 1 or _decoupled(device, w, paths, rest)
    if not config.wall.cartesian:
        return WallJoint(j, b, spring, fraction, torque, exact)
    scale = float(normal_jacobian(device, config.wall, q0)[w])
    if abs(scale) < 1e-12:
        raise UserError(f"joint {w + 1} does not move the handle along the wall direction at the start pose")
    return WallJoint(j, b, spring, fraction, torque, exact and _linear_along_wall(device, config, w, q0, paths), scale)


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


def _sub_steps(wall: WallJoint, step: float, count: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Exact transitions of ``(q, qd)`` over ``0, h, ..., (count - 1) h`` under a held torque:
    ``(Phi_j, Gamma_j)`` from one matrix exponential, ``Phi_(j+1) = Phi_h Phi_j``,
    ``Gamma_(j+1) = Phi_h Gamma_j + Gamma_h``."""
    phi_h, gamma_h = _plant(wall, step)
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
        self.samples = int(round(self.config.duration / self.config.sensors.period))
        self.driven = None
        with one_blas_thread():
            self._plant = _plant(self.wall, self.config.sensors.period)
            self._held_plant = _plant(self.held, self.config.sensors.period)
            self._steps = _sub_steps(self.wall, self.config.step, self.sub)
            if self._time_varying():
                self.driven = self._driven_loop()

    def _held(self) -> WallJoint:
        """The loop linearized where the wall holds the joint (:func:`equilibrium_pose`): its growth decides
        stability, the start pose's need not (the free joint travels to the rest before it oscillates there)."""
        pose = equilibrium_pose(self.device, self.sim_type, self.wall_joint, self.config, self.equilibrium)
        return linearize(self.device, self.sim_type, self.wall_joint, self.config, pose)

    def _time_varying(self) -> bool:
        """Type 2 with the wall joint coupled to the motion, on a joint wall of an open chain without a hand."""
        cfg = self.config
        return (self.sim_type == 2 and not self.wall.exact and not cfg.wall.cartesian and cfg.hand is None
                and self.device.mechanism.loops is None)

    def _driven_loop(self) -> DrivenLoop:
        device, cfg, w = self.device, self.config, self.wall_joint
        rest = rest_pose(device)
        damping = np.asarray(cfg.damping if cfg.damping is not None else device.damping, dtype=float)
        comp = cfg.compensator
        switches = (float(comp.inertial), float(comp.coriolis), float(comp.gravity))
        return DrivenLoop.build(device, compensator_device(device, comp), w, type_paths(2, device.n_dof, w, rest), rest,
                                float(damping[w]), switches, cfg.sensors.period, self.sub, self.samples,
                                cfg.sensors.delay_samples, cfg.wall.damping, self.rest)

    @property
    def exact(self) -> bool:
        if self.driven is not None:
            return bool(dynamics_of(self.device).cyclic[self.wall_joint] and
                        dynamics_of(compensator_device(self.device, self.config.compensator)).cyclic[self.wall_joint])
        return self.wall.exact

    @property
    def growth_is_exact(self) -> bool:
        """Whether :meth:`grows` decides the wall's stability: type 1 (the held joints leave the wall joint one
        time-invariant loop about the start pose, exact to first order there), or a driven motion that does not
        reach the wall joint's row of H, C, G (:attr:`exact`)."""
        return self.sim_type == 1 or self.exact

    def estimate(self) -> float:
        wall, period = self.wall, self.config.sensors.period
        joint = wall.damping ** 2 / wall.inertia if wall.fraction > 0 else 2.0 * wall.damping / period
        return joint / self.wall.scale ** 2

    def _augmented(self, stiffness: float, wall: WallJoint | None = None) -> tuple[np.ndarray, np.ndarray, int]:
        """One-sample map of ``s = [q - q_eq, qd, controller state, 1]`` and the row giving ``u`` (of the loop
        ``wall``, default the start pose's)."""
        wall = wall or self.wall
        d = wall.torque
        s2 = wall.scale ** 2
        n = self.config.sensors.delay_samples
        ac, bc, cc, dc = _controller(wall, n, stiffness * s2, self.config.wall.damping * s2)
        phi, gamma = self._plant if wall is self.wall else self._held_plant
        nc = ac.shape[0]
        u_line = (n + 1) + n
        # the spring acts on q - q_eq; the rest of the hand's spring and the constant torque act on the plant
        const = d - wall.stiffness * self.rest
        comp = wall.fraction * const
        size = 2 + nc + 1
        m = np.zeros((size, size))
        u_row = np.concatenate([dc[0], cc[0], [comp]])
        m[:2] = np.outer(gamma, u_row)
        m[:2, :2] += phi
        m[:2, -1] += gamma * const
        m[2:2 + nc, :2] = bc
        m[2:2 + nc, 2:2 + nc] = ac
        m[2 + u_line, -1] += comp
        m[-1, -1] = 1.0
        return m, u_row, u_line

    def _initial(self, u_line: int) -> np.ndarray:
        """The kernel's start: q = 0, qd = 0, the delay line holding the first sample, no acceleration."""
        n = self.config.sensors.delay_samples
        nc = (n + 1) + n + (n + 1)
        s = np.zeros(2 + nc + 1)
        e0 = -self.rest
        s[0] = e0
        s[2:2 + n + 1] = e0
        const = self.wall.torque - self.wall.stiffness * self.rest
        s[2 + u_line:2 + nc] = self.wall.stiffness * e0 - const  # the compensator sees a = 0 until samples arrive
        s[-1] = 1.0
        return s

    def response(self, stiffness: float) -> np.ndarray:
        """The wall coordinate from its start (``q - q0``, or ``J_n,w (q - q0)`` along a Cartesian wall) at
        every plant step (rows: samples, columns: plant steps within the period)."""
        m, u_row, u_line = self._augmented(stiffness)
        states = _powers(m, self._initial(u_line), self.samples)
        u = states @ u_row
        const = self.wall.torque - self.wall.stiffness * self.rest
        cols = [phi[0, 0] * states[:, 0] + phi[0, 1] * states[:, 1] + gamma[0] * (u + const)
                for phi, gamma in self._steps]
        return (np.stack(cols, axis=1) + self.rest) * self.wall.scale

    def grows(self, stiffness: float) -> bool:
        """Whether the linearized sampled loop is unstable at ``stiffness``: the spectral radius of its
        one-sample map (the constant state of the affine part left out) exceeds 1, or along a driven motion
        (:mod:`.analytic_driven`) its largest Floquet multiplier over the motion's period (not decided, so
        False, when the run is shorter than a period). For type 1 this is the exact local growth boundary
        of the wall (Lyapunov's indirect method for the sampled system), linearized where the wall holds the
        joint (:func:`equilibrium_pose`)."""
        if self.driven is not None:
            with one_blas_thread():
                return bool(self.driven.floquet_radius(stiffness) > 1.0)
        m, _, _ = self._augmented(stiffness, self.held)
        with one_blas_thread():
            radius = float(np.max(np.abs(np.linalg.eigvals(m[:-1, :-1]))))
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
        t = np.arange(len(samples)) * self.config.sensors.period
        tail = samples[t >= t[-1] - self.criteria.settle_window]
        final = float(np.max(np.abs(tail - self.equilibrium)))
        if final > self.criteria.settle_tolerance:
            return Verdict(stiffness, False, "not settled", peak, final)
        if self.growth_is_exact and self.grows(stiffness):
            return Verdict(stiffness, False, GROWS, peak, final)
        return Verdict(stiffness, True, "stable", peak, final)
