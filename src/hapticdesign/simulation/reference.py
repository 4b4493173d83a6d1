"""The same sampled-data loop written plainly with ``scipy.integrate.solve_ivp`` (adaptive RK45).

Between samples the held torques are constant, so each sample period is one ``solve_ivp`` call
on the free joints, with the prescribed joints following their paths and the dynamics from
:class:`~hapticdesign.analysis.dynamics.model.DynamicsModel` in NumPy. This is the optional
adaptive integrator, the cross-check of the numba kernel, and the speed baseline of the
benchmark. Records are taken at the sample instants; the safety switch is checked there too.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.kernel import STATUS_COMPLETED, STATUS_DIVERGED, STATUS_EXCURSION
from hapticdesign.simulation.loop import LoopConfig, Trace, _hand_matrices, model_device
from hapticdesign.simulation.paths import Path


def _terms(device: Device, pi: np.ndarray, q: np.ndarray):
    model = device.model
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
    config.steps_per_sample()
    period = config.sensors.period
    paths = dict(paths or {})
    wall = config.wall
    if not 0 <= wall.joint < n:
        raise UserError(f"unknown joint {wall.joint + 1}; the device has joints 1..{n}")
    comp = config.compensator
    pi_plant = device.standard_parameters()
    pi_model = model_device(device, comp.error_percent).standard_parameters()
    damping = np.diag(np.asarray(config.damping if config.damping is not None else device.damping, dtype=float))
    quant = 0.0 if config.sensors.counts_per_revolution is None else 2 * np.pi / config.sensors.counts_per_revolution
    delay = config.sensors.delay_samples
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
    hand_mass, hand_damping, hand_stiffness = _hand_matrices(device, config.hand, q_start)
    damping = damping + hand_damping

    def accel(t: float, q: np.ndarray, qd: np.ndarray, u: np.ndarray):
        qp, qdp, qddp = path_at(t)
        q, qd = q.copy(), qd.copy()
        q[fixed], qd[fixed] = qp[fixed], qdp[fixed]
        h, c, g = _terms(device, pi_plant, q)
        h = h + hand_mass
        j, k = np.triu_indices(n)
        bias = c @ (qd[j] * qd[k]) + g + damping @ qd + hand_stiffness @ (q - q_start) - u
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
    tau_f, tau_imp = np.zeros(n), np.zeros(n)
    for k in range(n_samples + 1):
        t = k * period
        qp, qdp, _ = path_at(t)
        q[fixed], qd[fixed] = qp[fixed], qdp[fixed]
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
            status = STATUS_DIVERGED
            break
        qdd_minus, _ = accel(t, q, qd, u)
        if k == 0:
            qdd_minus[free] = 0.0
        history.append((q.copy(), qd.copy(), qdd_minus))
        qs, qds, qdds = history[max(0, len(history) - 1 - delay)]
        if quant > 0:
            qs = np.round(qs / quant) * quant
        h_m, c_m, g_m = _terms(device, pi_model, qs)
        j_, k_ = np.triu_indices(n)
        tau_f = comp.inertial * (h_m @ qdds) + comp.coriolis * (c_m @ (qds[j_] * qds[k_])) + comp.gravity * g_m
        tau_imp = np.zeros(n)
        tau_imp[wall.joint] = wall.stiffness * (qs[wall.joint] - wall.equilibrium) + wall.damping * qds[wall.joint]
        if tripped_at is not None:
            tau_f, tau_imp = np.zeros(n), np.zeros(n)
        u = tau_f - tau_imp
        _, tau_c = accel(t, q, qd, u)
        for key, val in zip(rec, (q, qd, u, tau_f, tau_imp, tau_c)):
            rec[key].append(val.copy())
        if abs(q[wall.joint] - q_start[wall.joint]) >= stop:
            status = STATUS_EXCURSION
            break
        if k == n_samples:
            break
        if free:
            sol = solve_ivp(rhs, (t, t + period), np.concatenate([q[free], qd[free]]), method="RK45",
                            rtol=rtol, atol=atol, args=(u,))
            y = sol.y[:, -1]
            q[free], qd[free] = y[: len(free)], y[len(free):]
        if tripped_at is None and abs(q[wall.joint] - q_start[wall.joint]) >= safety:
            tripped_at = t + period
    arrays = {k: np.array(v).reshape(-1, n) for k, v in rec.items()}
    times = np.arange(len(arrays["q"])) * period
    return Trace(times, arrays["q"], arrays["qd"], arrays["u"], arrays["f"], arrays["imp"], arrays["c"],
                 status, tripped_at)
