"""The fixed-step sampled-data loop in numba (seed 000 §4.1.1, Figures 4.1-4.8, 4.12-4.16).

Continuous side: the device's nonlinear dynamics ``(H + M_hand) qdd + C qd^2 + G + D qd +
F_c tanh(qd / v_f) + K_hand (q - q_hand) = u + tau_c`` (Coulomb friction ``F_c`` per joint) integrated by classical RK4 at step ``h``. Joints are either
free (``tau_c = 0``) or prescribed: their position, velocity and acceleration follow a path and
``tau_c`` is the torque that imposes it (only the free joints are integrated; our choice, exact
for an ideal motion actuator such as Simscape's motion-actuated joint).

Digital side, every ``sub`` steps (period ``T = sub h``): sensors read position, velocity and
acceleration (the acceleration just before the instant, i.e. under the previous held torque,
which avoids an algebraic loop; zero at t = 0 as the seed's initial conditions), optionally quantized (positions) and delayed; the compensator
computes the model's inverse dynamics ``tau_f`` with its inertial, Coriolis and gravity terms
switchable; the virtual wall computes ``tau_imp = K (q_w - q_eq) + B qd_w``; the actuators hold
``u = tau_f - tau_imp`` (zero-order hold). The safety switch of Figure 4.7 cuts both torques off
once the wall joint leaves its reference by ``safety_limit``.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from hapticdesign.analysis.dynamics.model import velocity_products_into as velocity_products
from hapticdesign.simulation.config import FRICTION_VELOCITY, STATUS_COMPLETED, STATUS_DIVERGED, STATUS_EXCURSION
from hapticdesign.simulation.tables import evaluate_entries, unpack_entries


@nb.njit(cache=True, error_model="numpy", inline="always")
def _solve_in_place(a, b, n):
    """Gaussian elimination with partial pivoting on the leading n x n block; b becomes x."""
    for col in range(n):
        piv = col
        for r in range(col + 1, n):
            if abs(a[r, col]) > abs(a[piv, col]):
                piv = r
        if piv != col:
            for k in range(n):
                a[col, k], a[piv, k] = a[piv, k], a[col, k]
            b[col], b[piv] = b[piv], b[col]
        for r in range(col + 1, n):
            f = a[r, col] / a[col, col]
            for k in range(col, n):
                a[r, k] -= f * a[col, k]
            b[r] -= f * b[col]
    for col in range(n - 1, -1, -1):
        s = b[col]
        for k in range(col + 1, n):
            s -= a[col, k] * b[k]
        b[col] = s / a[col, col]


@nb.njit(cache=True, error_model="numpy", inline="always")
def _plant_terms(q, table, hand_mass, ws_values, ws_phi, ws_entries, cache_q, cache_valid, h, c, g):
    """H + M_hand, C, G of the plant at q, reusing the last evaluation when the non-cyclic q is unchanged."""
    rows, cols, vals, index, kinds, degrees = table
    n = q.shape[0]
    same = cache_valid[0] == 1
    if same:
        for k in range(n):
            if kinds[k] != 0 and q[k] != cache_q[k]:
                same = False
                break
    if not same:
        evaluate_entries(q, rows, cols, vals, index, kinds, degrees, ws_values, ws_phi, ws_entries)
        unpack_entries(ws_entries, n, h, c, g)
        for i in range(n):
            for j in range(n):
                h[i, j] += hand_mass[i, j]
        for k in range(n):
            cache_q[k] = q[k]
        cache_valid[0] = 1


@nb.njit(cache=True, error_model="numpy", inline="always")
def accelerations(q, qd, qdd_path, u, prescribed, table, damping, coulomb, hand_mass, hand_stiffness, hand_rest, ws,
                  qdd, tau_c, want_tau_c=True):
    """Joint accelerations (free joints solved, prescribed taken from the path) and, when
    ``want_tau_c``, the constraint torques (``tau_c`` is scratch otherwise)."""
    ws_values, ws_phi, ws_entries, cache_q, cache_valid, h, c, g, qd2, a, rhs, free = ws
    n = q.shape[0]
    _plant_terms(q, table, hand_mass, ws_values, ws_phi, ws_entries, cache_q, cache_valid, h, c, g)
    velocity_products(qd, qd2)
    bias = tau_c
    for i in range(n):
        if prescribed[i] and not want_tau_c:
            continue
        s = g[i] - u[i]
        for col in range(qd2.shape[0]):
            s += c[i, col] * qd2[col]
        if coulomb[i] != 0.0:
            s += coulomb[i] * np.tanh(qd[i] / FRICTION_VELOCITY)
        for j in range(n):
            s += damping[i, j] * qd[j]
            if hand_stiffness[i, j] != 0.0:
                s += hand_stiffness[i, j] * (q[j] - hand_rest[j])
        bias[i] = s
    nf = 0
    for i in range(n):
        if not prescribed[i]:
            free[nf] = i
            nf += 1
        else:
            qdd[i] = qdd_path[i]
    for r in range(nf):
        i = free[r]
        s = -bias[i]
        for j in range(n):
            if prescribed[j]:
                s -= h[i, j] * qdd[j]
        rhs[r] = s
        for cc in range(nf):
            a[r, cc] = h[i, free[cc]]
    if nf > 0:
        _solve_in_place(a, rhs, nf)
    for r in range(nf):
        qdd[free[r]] = rhs[r]
    if not want_tau_c:
        return
    for i in range(n):
        s = bias[i]
        for j in range(n):
            s += h[i, j] * qdd[j]
        tau_c[i] = 0.0 if not prescribed[i] else s


@nb.njit(cache=True, error_model="numpy", inline="always")
def _stage_state(q, qd, kq, a, h, prescribed, path_q_row, path_qd_row, qs, qds):
    """RK4 stage state ``(q + h kq, qd + h a)``; prescribed joints take the path's value instead."""
    for i in range(q.shape[0]):
        if prescribed[i]:
            qs[i] = path_q_row[i]
            qds[i] = path_qd_row[i]
        else:
            qs[i] = q[i] + h * kq[i]
            qds[i] = qd[i] + h * a[i]


@nb.njit(cache=True, error_model="numpy")
def compensator_torque(q, qd, qdd, table, switches, ws_values, ws_phi, ws_entries, h, c, g, qd2, out):
    """Model-based feedforward ``tau_f = s_H H qdd + s_C C qd^2 + s_G G`` (seed §4.1.1.2)."""
    rows, cols, vals, index, kinds, degrees = table
    n = q.shape[0]
    evaluate_entries(q, rows, cols, vals, index, kinds, degrees, ws_values, ws_phi, ws_entries)
    unpack_entries(ws_entries, n, h, c, g)
    velocity_products(qd, qd2)
    for i in range(n):
        s_h = 0.0
        for j in range(n):
            s_h += h[i, j] * qdd[j]
        s_c = 0.0
        for col in range(qd2.shape[0]):
            s_c += c[i, col] * qd2[col]
        out[i] = switches[0] * s_h + switches[1] * s_c + switches[2] * g[i]


def make_workspace(n: int, n_values: int, n_basis: int, n_entries: int):
    """Scratch arrays for :func:`accelerations` (one set per plant)."""
    m = n * (n + 1) // 2
    return (
        np.zeros((n, n_values)), np.zeros(n_basis), np.zeros(n_entries), np.zeros(n), np.zeros(1, dtype=np.int64),
        np.zeros((n, n)), np.zeros((n, m)), np.zeros(n), np.zeros(m), np.zeros((n, n)), np.zeros(n),
        np.zeros(n, dtype=np.int64),
    )


@nb.njit(cache=True, error_model="numpy")
def run_loop(plant, model, ws_plant, ws_model, damping, coulomb, hand_mass, hand_stiffness, hand_rest, prescribed,
             path_q, path_qd, path_qdd, q0, qd0, step, sub, n_steps, wall_joint, wall_k, wall_b, wall_eq,
             switches, quant, delay, safety_limit, reference, stop_excursion, stride,
             rec_q, rec_qd, rec_u, rec_f, rec_imp, rec_c):
    """Run the loop; returns (records written, status, time the safety switch tripped or -1, peak
    excursion of the wall joint from ``reference`` over every plant step, time the run ended).

    The excursion is checked at every plant step, so a run stopped at ``stop_excursion`` reports a
    peak at or above it even when no recorded row (every ``stride`` steps) shows it."""
    n = q0.shape[0]
    q = q0.copy()
    qd = qd0.copy()
    for i in range(n):
        if prescribed[i]:
            q[i] = path_q[0, i]
            qd[i] = path_qd[0, i]
    u = np.zeros(n)
    tau_f = np.zeros(n)
    tau_imp = np.zeros(n)
    qdd = np.zeros(n)
    tau_c = np.zeros(n)
    k1q = np.zeros(n); k2q = np.zeros(n); k3q = np.zeros(n); k4q = np.zeros(n)
    a1 = np.zeros(n); a2 = np.zeros(n); a3 = np.zeros(n); a4 = np.zeros(n)
    c1 = np.zeros(n)
    qs = np.zeros(n); qds = np.zeros(n)
    buf = np.zeros((delay + 1, 3, n))
    sensed = np.zeros((3, n))
    m_values, m_phi, m_entries, _, _, m_h, m_c, m_g, m_qd2, _, _, _ = ws_model
    n_free = 0
    for i in range(n):
        if not prescribed[i]:
            n_free += 1
    tripped = False
    trip_time = -1.0
    written = 0
    status = STATUS_COMPLETED
    peak = 0.0
    end_time = 0.0
    for it in range(n_steps + 1):
        t = it * step
        if it % sub == 0:
            accelerations(q, qd, path_qdd[2 * it], u, prescribed, plant, damping, coulomb,
                          hand_mass, hand_stiffness, hand_rest, ws_plant, qdd, c1)
            if it == 0:
                for i in range(n):
                    if not prescribed[i]:
                        qdd[i] = 0.0
            k = it // sub
            slot = k % (delay + 1)
            for i in range(n):
                buf[slot, 0, i] = q[i]
                buf[slot, 1, i] = qd[i]
                buf[slot, 2, i] = qdd[i]
            old = (k - delay) % (delay + 1) if k >= delay else 0
            for i in range(n):
                pos = buf[old, 0, i]
                if quant > 0.0:
                    pos = np.round(pos / quant) * quant
                sensed[0, i] = pos
                sensed[1, i] = buf[old, 1, i]
                sensed[2, i] = buf[old, 2, i]
            compensator_torque(sensed[0], sensed[1], sensed[2], model, switches,
                               m_values, m_phi, m_entries, m_h, m_c, m_g, m_qd2, tau_f)
            for i in range(n):
                tau_imp[i] = 0.0
            tau_imp[wall_joint] = wall_k * (sensed[0, wall_joint] - wall_eq) + wall_b * sensed[1, wall_joint]
            if tripped:
                for i in range(n):
                    tau_f[i] = 0.0
                    tau_imp[i] = 0.0
            for i in range(n):
                u[i] = tau_f[i] - tau_imp[i]
        # stage 1 (also gives the recorded constraint torque)
        accelerations(q, qd, path_qdd[2 * it], u, prescribed, plant, damping, coulomb,
                      hand_mass, hand_stiffness, hand_rest, ws_plant, a1, c1)
        if it % stride == 0:
            r = it // stride
            for i in range(n):
                rec_q[r, i] = q[i]
                rec_qd[r, i] = qd[i]
                rec_u[r, i] = u[i]
                rec_f[r, i] = tau_f[i]
                rec_imp[r, i] = tau_imp[i]
                rec_c[r, i] = c1[i]
            written = r + 1
        finite = True
        for i in range(n):
            if not (np.isfinite(q[i]) and np.isfinite(qd[i])) or abs(qd[i]) > 1e8:
                finite = False
        end_time = t
        if not finite:
            status = STATUS_DIVERGED
            break
        excursion = abs(q[wall_joint] - reference)
        if excursion > peak:
            peak = excursion
        if excursion >= stop_excursion:
            status = STATUS_EXCURSION
            break
        if it == n_steps:
            break
        if n_free == 0:
            for i in range(n):
                q[i] = path_q[2 * it + 2, i]
                qd[i] = path_qd[2 * it + 2, i]
        else:
            # RK4 stages 2-4; prescribed joints follow the path at each stage time
            k1q[:] = qd
            _stage_state(q, qd, k1q, a1, 0.5 * step, prescribed, path_q[2 * it + 1], path_qd[2 * it + 1], qs, qds)
            k2q[:] = qds
            accelerations(qs, qds, path_qdd[2 * it + 1], u, prescribed, plant, damping, coulomb,
                          hand_mass, hand_stiffness, hand_rest, ws_plant, a2, tau_c, False)
            _stage_state(q, qd, k2q, a2, 0.5 * step, prescribed, path_q[2 * it + 1], path_qd[2 * it + 1], qs, qds)
            k3q[:] = qds
            accelerations(qs, qds, path_qdd[2 * it + 1], u, prescribed, plant, damping, coulomb,
                          hand_mass, hand_stiffness, hand_rest, ws_plant, a3, tau_c, False)
            _stage_state(q, qd, k3q, a3, step, prescribed, path_q[2 * it + 2], path_qd[2 * it + 2], qs, qds)
            k4q[:] = qds
            accelerations(qs, qds, path_qdd[2 * it + 2], u, prescribed, plant, damping, coulomb,
                          hand_mass, hand_stiffness, hand_rest, ws_plant, a4, tau_c, False)
            for i in range(n):
                if prescribed[i]:
                    q[i] = path_q[2 * it + 2, i]
                    qd[i] = path_qd[2 * it + 2, i]
                else:
                    q[i] += step / 6.0 * (k1q[i] + 2.0 * k2q[i] + 2.0 * k3q[i] + k4q[i])
                    qd[i] += step / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i])
        if not tripped and abs(q[wall_joint] - reference) >= safety_limit:
            tripped = True
            trip_time = t + step
            for i in range(n):
                tau_f[i] = 0.0
                tau_imp[i] = 0.0
                u[i] = 0.0
    return written, status, trip_time, peak, end_time
