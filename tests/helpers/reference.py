"""The same sampled-data loop written plainly with ``scipy.integrate.solve_ivp`` (adaptive RK45).

Between samples the held torques are constant, so each sample period is one ``solve_ivp`` call on the free joints,
with the prescribed joints following their paths and the dynamics from
:class:`~hapticdesign.analysis.dynamics.model.DynamicsModel` in NumPy. It is the tests' cross-check of the numba
kernel and the benchmarks' speed baseline, kept beside them (outside the package). It shares only the configuration
types with the fast loop (:mod:`hapticdesign.simulation.config`), none of its code. Records are taken at the sample
instants; the excursion stop and the safety switch are checked at every plant-step instant (``config.step``) from the
dense output of each period, as the fast loop checks them, and a tripped switch removes the torques from that instant
on. A Cartesian wall takes the handle's position and Jacobian from :mod:`hapticdesign.analysis.kinematics` (for a
closed-loop device at the pose the loop solver closes, with ``J T``).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.config import (
    FRICTION_VELOCITY, STATUS_COMPLETED, STATUS_DIVERGED, STATUS_EXCURSION, LoopConfig, Trace, compensator_device,
    hand_matrices, plant_damping, plant_friction, unit_direction,
)
from hapticdesign.simulation.paths import Path


def _terms(device: Device, pi: np.ndarray, q: np.ndarray):
    model = dynamics_of(device)
    return model.H(q, pi), model.C(q, pi), model.G(q, pi)


def simulate_adaptive(
    device: Device,
    config: LoopConfig,
    paths: dict[int, Path] | None = None,
    q0: np.ndarray | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
) -> Trace:
    """Run the loop of :func:`~hapticdesign.simulation.loop.simulate` with SciPy's RK45."""
    n = device.n_dof
    sub = config.steps_per_sample()
    loop = config.loop
    period = loop.period
    paths = dict(paths or {})
    wall = config.wall
    if not 0 <= wall.joint < n:
        raise UserError(f"unknown joint {wall.joint + 1}; the device has joints 1..{n}")
    comp, full = config.compensator, loop.compensation == "full"
    inertial, coriolis = comp.inertial and full, comp.coriolis and full
    gravity_on = comp.gravity and loop.compensation != "none"
    pi_plant = device.standard_parameters()
    pi_model = compensator_device(device, config).standard_parameters()
    damping = plant_damping(device, config)
    quant = 0.0 if config.counts is None else 2 * np.pi / config.counts
    delay = loop.delay
    safety = math.inf if config.safety_limit is None else config.safety_limit
    stop = math.inf if config.stop_excursion is None else config.stop_excursion
    free = [j for j in range(n) if j not in paths]
    fixed = sorted(paths)

    def path_at(t: float):
        q, qd, qdd = np.zeros(n), np.zeros(n), np.zeros(n)
        for j in fixed:
            a, b, c = paths[j].sample(np.array([t]))
            q[j], qd[j], qdd[j] = a[0], b[0], c[0]
        return q, qd, qdd

    q_start = np.zeros(n) if q0 is None else np.asarray(q0, dtype=float).copy()
    q_start[fixed] = path_at(0.0)[0][fixed]
    hand_mass, hand_damping, hand_stiffness = hand_matrices(device, loop.hand, q_start)
    damping = damping + hand_damping
    friction_map, friction = plant_friction(device, config)

    def accel(t: float, q: np.ndarray, qd: np.ndarray, u: np.ndarray):
        qp, qdp, qddp = path_at(t)
        q, qd = q.copy(), qd.copy()
        q[fixed], qd[fixed] = qp[fixed], qdp[fixed]
        h, c, g = _terms(device, pi_plant, q)
        h = h + hand_mass
        j, k = np.triu_indices(n)
        bias = (c @ (qd[j] * qd[k]) + g + damping @ qd
                + friction_map.T @ (friction * np.tanh(friction_map @ qd / FRICTION_VELOCITY))
                + hand_stiffness @ (q - q_start) - u)
        qdd = qddp.copy()
        if free:
            rhs = -bias[free] - h[np.ix_(free, fixed)] @ qddp[fixed]
            qdd[free] = np.linalg.solve(h[np.ix_(free, free)], rhs)
        tau_c = h @ qdd + bias
        tau_c[free] = 0.0
        return qdd, tau_c

    def rhs(t: float, y: np.ndarray, u: np.ndarray) -> np.ndarray:
        q, qd = np.zeros(n), np.zeros(n)
        q[free], qd[free] = y[: len(free)], y[len(free):]
        qdd, _ = accel(t, q, qd, u)
        return np.concatenate([qd[free], qdd[free]])

    n_samples = int(round(config.duration / period))
    q, qd = q_start.copy(), np.zeros(n)
    u = np.zeros(n)
    history: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    rec = {k: [] for k in ("q", "qd", "u", "f", "imp", "c")}
    tripped_at = None
    status = STATUS_COMPLETED
    direction = unit_direction(wall.direction) if wall.cartesian else None
    space = configuration_of(device)

    def coordinate(q_t: np.ndarray) -> float:
        """The wall coordinate: the wall joint, or the handle along the Cartesian wall's direction."""
        if direction is None:
            return float(q_t[wall.joint])
        return float(direction @ space.pose(q_t)[:3, 3])

    def wall_torque(qs: np.ndarray, qds: np.ndarray) -> np.ndarray:
        tau = np.zeros(n)
        if direction is None:
            tau[wall.joint] = wall.stiffness * (qs[wall.joint] - wall.equilibrium) + loop.wall_damping * qds[wall.joint]
            return tau
        j_n = direction @ space.jacobian(qs)[:3]
        return j_n * (wall.stiffness * (coordinate(qs) - rest) + loop.wall_damping * (j_n @ qds))

    reference = coordinate(q_start)
    rest = reference + wall.equilibrium
    peak, end_time = 0.0, 0.0
    j_, k_ = np.triu_indices(n)

    def state_at(t: float, y: np.ndarray):
        qp, qdp, _ = path_at(t)
        q_t, qd_t = qp.copy(), qdp.copy()
        q_t[free], qd_t[free] = y[: len(free)], y[len(free):]
        return q_t, qd_t

    def plant_step_check(t: float, q_t: np.ndarray, qd_t: np.ndarray) -> int | None:
        """The checks the loop makes at one plant-step instant: finite state, peak, excursion stop."""
        nonlocal peak, end_time
        end_time = t
        if not (np.all(np.isfinite(q_t)) and np.all(np.isfinite(qd_t))) or np.max(np.abs(qd_t)) > 1e8:
            return STATUS_DIVERGED
        excursion = abs(coordinate(q_t) - reference)
        peak = max(peak, excursion)
        return STATUS_EXCURSION if excursion >= stop else None

    for k in range(n_samples + 1):
        t = k * period
        qp, qdp, _ = path_at(t)
        q[fixed], qd[fixed] = qp[fixed], qdp[fixed]
        if k == 0 and (ended := plant_step_check(t, q, qd)) is not None:
            status = ended
            break
        qdd_minus, _ = accel(t, q, qd, u)
        if k == 0:
            qdd_minus[free] = 0.0
        history.append((q.copy(), qd.copy(), qdd_minus))
        qs, qds, qdds = history[max(0, len(history) - 1 - delay)]
        if quant > 0:
            qs = np.round(qs / quant) * quant
        h_m, c_m, g_m = _terms(device, pi_model, qs)
        tau_f = inertial * (h_m @ qdds) + coriolis * (c_m @ (qds[j_] * qds[k_])) + gravity_on * g_m
        tau_imp = wall_torque(qs, qds)
        if tripped_at is not None:
            tau_f, tau_imp = np.zeros(n), np.zeros(n)
        u = tau_f - tau_imp
        _, tau_c = accel(t, q, qd, u)
        for key, val in zip(rec, (q, qd, u, tau_f, tau_imp, tau_c)):
            rec[key].append(val.copy())
        if k == n_samples:
            break
        ended, start, y = None, t, np.concatenate([q[free], qd[free]])
        instants = t + config.step * np.arange(1, sub + 1)
        while start < instants[-1] - 0.5 * config.step and ended is None:
            todo = instants[instants > start + 0.5 * config.step]
            if free:
                sol = solve_ivp(rhs, (start, todo[-1]), y, method="RK45", rtol=rtol, atol=atol, args=(u,),
                                dense_output=True)
                states = sol.sol(todo).T
            else:
                states = np.zeros((len(todo), 0))
            for t_j, y_j in zip(todo, states):
                q_j, qd_j = state_at(t_j, y_j)
                ended = plant_step_check(t_j, q_j, qd_j)
                if ended is not None:
                    break
                if tripped_at is None and abs(coordinate(q_j) - reference) >= safety:
                    tripped_at = t_j
                    u = np.zeros(n)
                    start, y = t_j, y_j
                    break
            else:
                start, y = todo[-1], states[-1] if free else y
        q, qd = state_at(instants[-1], y)
        if ended is not None:
            status = ended
            break
    arrays = {k: np.array(v).reshape(-1, n) for k, v in rec.items()}
    times = np.arange(len(arrays["q"])) * period
    return Trace(times, arrays["q"], arrays["qd"], arrays["u"], arrays["f"], arrays["imp"], arrays["c"],
                 status, tripped_at, peak, end_time, np.array([coordinate(q_k) for q_k in arrays["q"]]))
