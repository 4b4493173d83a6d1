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
switchable; the virtual wall computes ``tau_imp = K (q_w - q_eq) + B qd_w`` on a joint, or for a
Cartesian wall along the unit direction n at the handle ``tau_imp = J_n^T (K (n.p - x_eq) + B J_n qd)``
(``tau = J^T F``, ``J_n = n^T J_v`` from the compiled frame tree at the sensed pose; for a closed-loop
device ``n^T J_v T`` in actuated coordinates at the compensator's closed pose); the actuators
hold ``u = tau_f - tau_imp`` (zero-order hold). The safety switch of Figure 4.7 cuts both torques
off once the wall coordinate (the wall joint, or the handle along n) leaves its reference by
``safety_limit``.

H, C and G come from a tree's exact basis tables (:mod:`.tables`) or, for a closed-loop device, in its
actuated coordinates from the compiled closed-loop plant (seed 000 eq. 2.44-2.50 on the loop-opened
tree, :mod:`hapticdesign.analysis.dynamics.closed_loop_plant`), the plant and the compensator's model
each with its own warm start; which one is inlined follows the record's type (:mod:`.records`). A
closed-loop run whose loops stop closing on the assembly branch ends with ``STATUS_LOOP_LOST``.
"""

from __future__ import annotations

import warnings

import numba as nb
import numpy as np
from numba.core import types
from numba.core.errors import NumbaIRAssumptionWarning
from numba.extending import overload

from hapticdesign.analysis.dynamics.closed_loop_plant import closed_loop_terms, handle_along
from hapticdesign.analysis.dynamics.model import velocity_products_into as velocity_products
from hapticdesign.model.dense import solve_leading
from hapticdesign.model.walk import frame_jacobian, node_poses
from hapticdesign.simulation import records
from hapticdesign.simulation.config import (
    FRICTION_VELOCITY, STATUS_COMPLETED, STATUS_DIVERGED, STATUS_EXCURSION, STATUS_LOOP_LOST,
)
from hapticdesign.simulation.tables import evaluate_entries, unpack_entries


CALLED = {"cache": True, "error_model": "numpy", "_nrt": False, "forceinline": True}
"""Options of the record-typed helpers (:func:`_terms`, :func:`_handle`, :func:`_status`): numba compiles each
once per record type as its own function and LLVM inlines it at every call (``alwaysinline``), as fast as numba's
own inlining of an overload (``inline="always"``), which copied and typed the helper's code again at every call
site and took half the loop's compile time (Phantom, type 1: 58 -> 30 CPU-s; ``benchmarks/bench_cold.py``)."""


@nb.njit(cache=True, error_model="numpy", inline="always")
def _tree_plant_terms(q, qd, record):
    """H + M_hand, C, G of a tree's tables at q into the record's workspace, reusing the last evaluation
    when the non-cyclic q is unchanged; the velocity products of qd."""
    t, ws = record.table, record.ws
    kinds, cache_q, cache_valid, h, hand_mass = t.kinds, ws.cache_q, ws.cache_valid, ws.h, record.hand_mass
    n = q.shape[0]
    same = cache_valid[0] == 1
    if same:
        for k in range(n):
            if kinds[k] != 0 and q[k] != cache_q[k]:
                same = False
                break
    if not same:
        evaluate_entries(q, t.rows, t.cols, t.vals, t.index, kinds, t.degrees, ws.values, ws.phi, ws.entries)
        unpack_entries(ws.entries, n, h, ws.c, ws.g)
        for i in range(n):
            for j in range(n):
                h[i, j] += hand_mass[i, j]
        for k in range(n):
            cache_q[k] = q[k]
        cache_valid[0] = 1
    velocity_products(qd, ws.qd2)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _loop_cached(q, qd, ws):
    """Whether a closed-loop workspace already holds the terms at exactly (q, qd)."""
    if ws.cache_valid[0] != 1:
        return False
    for k in range(q.shape[0]):
        if q[k] != ws.cache_q[k] or qd[k] != ws.cache_qd[k]:
            return False
    return True


@nb.njit(cache=True, error_model="numpy", inline="always")
def _loop_terms(q, qd, record):
    """H, C(q, qd) qd^2 and G of a closed-loop record (plant or compensator) at (q, qd) into its
    workspace, ``C qd^2`` as the one column of ``ws.c`` (its velocity product ``ws.qd2`` is 1); a failed
    closure leaves them as they were and keeps the first failure's status."""
    ws = record.ws
    status = closed_loop_terms(q, qd, record.structure, record.loop_ws, ws.h, record.cqd, ws.g)
    if status != 0:
        ws.cache_valid[0] = 0
        if record.status[0] == 0:
            record.status[0] = status
        return status
    for i in range(q.shape[0]):
        ws.c[i, 0] = record.cqd[i]
        ws.cache_q[i] = q[i]
        ws.cache_qd[i] = qd[i]
    ws.cache_valid[0] = 1
    return status


@nb.njit(cache=True, error_model="numpy", inline="always")
def _loop_plant_terms(q, qd, record):
    """:func:`_loop_terms` of the record, plus the hand's mass; nothing to do at the state last evaluated
    (a sample instant's sensor call or the handle's position after a step, then stage 1 at that state)."""
    if _loop_cached(q, qd, record.ws):
        return
    if _loop_terms(q, qd, record) == 0:
        h, hand_mass = record.ws.h, record.hand_mass
        for i in range(q.shape[0]):
            for j in range(q.shape[0]):
                h[i, j] += hand_mass[i, j]


@nb.njit(cache=True, error_model="numpy", inline="always")
def _loop_model_terms(q, qd, record):
    """:func:`_loop_terms` of the compensator's model (nothing to do at the state last evaluated)."""
    if not _loop_cached(q, qd, record.ws):
        _loop_terms(q, qd, record)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _tree_model_terms(q, qd, record):
    """H, C, G of the compensator's tables at q and the velocity products of qd."""
    t, ws = record.table, record.ws
    evaluate_entries(q, t.rows, t.cols, t.vals, t.index, t.kinds, t.degrees, ws.values, ws.phi, ws.entries)
    unpack_entries(ws.entries, q.shape[0], ws.h, ws.c, ws.g)
    velocity_products(qd, ws.qd2)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _handle_normal(q, handle):
    """The handle's position along the wall direction, ``n . p(q)``, by a walk of a tree (its node poses stay
    in ``handle``)."""
    pos, n, node, tree = handle.pos, handle.direction, handle.node, handle.tree
    node_poses(q, tree.parent, tree.axis, tree.coef, tree.offset, tree.const_rot, tree.const_pos, node, handle.rot, pos)
    return n[0] * pos[node, 0] + n[1] * pos[node, 1] + n[2] * pos[node, 2]


@nb.njit(**CALLED)
def _tree_handle(q, handle, jn, want_jn):
    """``n . p`` of a tree's handle at q and, when ``want_jn``, ``J_n = n^T J_v`` into ``jn``: compiled once for the
    plant's and the compensator's records alike (it reads neither), inlined by LLVM (:data:`CALLED`)."""
    x = _handle_normal(q, handle)
    if want_jn:
        jac, n = handle.jac, handle.direction
        tree = handle.tree
        frame_jacobian(handle.node, tree.parent, tree.axis, tree.coef, handle.rot, handle.pos, np.bool_(False), jac)
        for k in range(q.shape[0]):
            jn[k] = n[0] * jac[0, k] + n[1] * jac[1, k] + n[2] * jac[2, k]
    return x


@nb.njit(cache=True, error_model="numpy", inline="always")
def _loop_handle(q, qd, handle, record, jn, want_jn):
    """``n . p`` and ``J_n = n^T J_v T`` of a closed-loop device's handle at the record's closed pose at
    (q, qd), evaluated there unless it already is (:func:`_terms`)."""
    _terms(q, qd, record)
    return handle_along(record.loop_ws, handle.tree.parent, handle.tree.axis, handle.node, handle.direction, jn, want_jn)


# The plant and the compensator are chosen by their record type (a tree's tables or a closed-loop plant) and
# inlined by LLVM (CALLED), which keeps the tree path as fast as a direct call; numba's SSA pass reports an
# internal, pedantic scope check on the helpers it inlines itself (its message says so), once per compile.
warnings.filterwarnings("ignore", category=NumbaIRAssumptionWarning)


def _is_loop(record) -> bool:
    """Whether a numba record type is a closed-loop plant or compensator (:mod:`.records`)."""
    return isinstance(record, types.NamedTuple) and record.instance_class in (records.LoopPlant,
                                                                              records.LoopController)


def _terms(q, qd, record):
    """H (+ M_hand for the plant), C with its velocity products (``C qd^2 = ws.c @ ws.qd2``) and G of a
    plant or compensator record at (q, qd) into its workspace (numba only: a tree's tables or a
    closed-loop plant, by the record's type)."""


def _handle(q, qd, handle, record, jn, want_jn):
    """The handle's position along the wall direction and, when ``want_jn``, ``J_n`` into ``jn`` (numba
    only: a tree's walk, or a closed-loop record's closed pose)."""


def _status(record):
    """0 while a closed-loop record's loops close on the assembly branch; always 0 for a tree (numba only)."""


@overload(_terms, jit_options=CALLED)
def _terms_impl(q, qd, record):
    kind = record.instance_class
    return {records.Plant: _tree_plant_terms, records.Controller: _tree_model_terms,
            records.LoopPlant: _loop_plant_terms, records.LoopController: _loop_model_terms}[kind].py_func


@overload(_handle, jit_options=CALLED)
def _handle_impl(q, qd, handle, record, jn, want_jn):
    if _is_loop(record):
        return _loop_handle.py_func
    return lambda q, qd, handle, record, jn, want_jn: _tree_handle(q, handle, jn, want_jn)


@overload(_status, jit_options=CALLED)
def _status_impl(record):
    if _is_loop(record):
        return lambda record: record.status[0]
    return lambda record: 0


@nb.njit(cache=True, error_model="numpy", inline="always")
def accelerations(q, qd, qdd_path, u, prescribed, plant, qdd, tau_c, want_tau_c=True):
    """Joint accelerations (free joints solved, prescribed taken from the path) and, when
    ``want_tau_c``, the constraint torques (``tau_c`` is scratch otherwise)."""
    ws = plant.ws
    h, c, g, qd2, a, rhs, free = ws.h, ws.c, ws.g, ws.qd2, ws.a, ws.rhs, ws.free
    damping, hand_stiffness, hand_rest = plant.damping, plant.hand_stiffness, plant.hand_rest
    coulomb, friction_map = plant.coulomb, plant.friction_map
    n = q.shape[0]
    _terms(q, qd, plant)
    bias = tau_c
    for i in range(n):
        if prescribed[i] and not want_tau_c:
            continue
        s = g[i] - u[i]
        for col in range(qd2.shape[0]):
            s += c[i, col] * qd2[col]
        for k in range(coulomb.shape[0]):
            if coulomb[k] != 0.0 and friction_map[k, i] != 0.0:
                rate = 0.0
                for j in range(n):
                    rate += friction_map[k, j] * qd[j]
                s += friction_map[k, i] * coulomb[k] * np.tanh(rate / FRICTION_VELOCITY)
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
        solve_leading(a, rhs, nf)
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


@nb.njit(cache=True, error_model="numpy", inline="always")
def _compensator_torque(q, qd, qdd, ctrl, out):
    """Model-based feedforward ``tau_f = s_H H qdd + s_C C qd^2 + s_G G`` (seed §4.1.1.2); for a
    closed-loop device the model's loops must close at the sensed pose (:func:`_status`)."""
    ws, switches = ctrl.ws, ctrl.switches
    h, c, g, qd2 = ws.h, ws.c, ws.g, ws.qd2
    n = q.shape[0]
    _terms(q, qd, ctrl)
    for i in range(n):
        s_h = 0.0
        for j in range(n):
            s_h += h[i, j] * qdd[j]
        s_c = 0.0
        for col in range(qd2.shape[0]):
            s_c += c[i, col] * qd2[col]
        out[i] = switches[0] * s_h + switches[1] * s_c + switches[2] * g[i]


@nb.njit(cache=True, error_model="numpy")
def handle_coordinate(q, qd, handle, record):
    """The handle's position along the wall direction at (q, qd), callable from Python (the wall's
    reference at the start pose); a closed-loop record is evaluated there, as the loop's first step will be."""
    return _handle(q, qd, handle, record, handle.jac[0], False)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _wall_coordinate(q, qd, wall, handle, plant):
    """The wall coordinate: the wall joint's position, or the handle's along a Cartesian wall's direction."""
    if wall.cartesian:
        return _handle(q, qd, handle, plant, handle.jac[0], False)
    return q[wall.joint]


@nb.njit(cache=True, error_model="numpy", inline="always")
def _wall_state(q, qd, wall, handle, plant, jn):
    """The wall coordinate and its rate: ``q_j, qd_j`` on a joint, ``n.p, J_n qd`` along a Cartesian
    wall's direction (``J_n`` into the scratch ``jn``)."""
    if not wall.cartesian:
        return q[wall.joint], qd[wall.joint]
    x = _handle(q, qd, handle, plant, jn, True)
    rate = 0.0
    for k in range(q.shape[0]):
        rate += jn[k] * qd[k]
    return x, rate


@nb.njit(cache=True, error_model="numpy", inline="always")
def _inside_step(c0, r0, c1, r1, m, h, wall, tripped):
    """The wall coordinate at the plant steps inside a step of ``m`` plant steps (length ``h``), from the
    cubic Hermite interpolant of its values ``c0, c1`` and rates ``r0, r1`` at the step's ends (fourth
    order in ``h``): (the first inside plant step whose excursion from ``wall.reference`` reaches the
    excursion stop or, unless ``tripped``, the safety limit, 0 if none; the largest excursion inside)."""
    peak = 0.0
    for k in range(1, m):
        x = k / m
        x2 = x * x
        x3 = x2 * x
        c = (2.0 * x3 - 3.0 * x2 + 1.0) * c0 + (x3 - 2.0 * x2 + x) * h * r0 + (3.0 * x2 - 2.0 * x3) * c1 + (x3 - x2) * h * r1
        excursion = abs(c - wall.reference)
        if excursion >= wall.stop_excursion or (not tripped and excursion >= wall.safety_limit):
            return k, peak
        peak = max(peak, excursion)
    return 0, peak


@nb.njit(cache=True, error_model="numpy", inline="always")
def _span_at_most(spans, k):
    """Index in ``spans`` (largest first, ending in 1) of the largest span no larger than ``k`` (>= 1)."""
    s = 0
    while spans[s] > k:
        s += 1
    return s


@nb.njit(cache=True, error_model="numpy", inline="always")
def _wall_torque(q, qd, wall, handle, ctrl, out):
    """``tau_imp`` of the wall at the sensed state: ``K (q_j - q_eq) + B qd_j`` on the wall joint, or
    ``J_n^T (K (n.p - x_eq) + B J_n qd)`` with ``J_n = n^T J_v`` the handle's Jacobian along n (for a
    closed-loop device in actuated coordinates, ``n^T J_v T`` at the compensator's closed pose)."""
    if not wall.cartesian:
        for i in range(q.shape[0]):
            out[i] = 0.0
        out[wall.joint] = wall.stiffness * (q[wall.joint] - wall.rest) + wall.damping * qd[wall.joint]
        return
    x = _handle(q, qd, handle, ctrl, out, True)
    v = 0.0
    for k in range(q.shape[0]):
        v += out[k] * qd[k]
    force = wall.stiffness * (x - wall.rest) + wall.damping * v
    for k in range(q.shape[0]):
        out[k] *= force


@nb.njit(cache=True, error_model="numpy", inline="always")
def _first_span(spans, wanted, it, n_steps):
    """Index in ``spans`` (largest first, ending in 1) of the largest span no larger than ``spans[wanted]``
    that starts on its own multiple at plant step ``it`` and ends by ``n_steps``."""
    s = wanted
    while s < spans.shape[0] - 1 and (it % spans[s] != 0 or it + spans[s] > n_steps):
        s += 1
    return s


@nb.njit(cache=True, error_model="numpy", inline="always")
def _step_error(q_new, qd_new, k4q, a4, a5, h, prescribed, tolerance):
    """Local error of the embedded third-order solution, ``h/6 |k4 - k5|`` per state entry, over
    ``tolerance (1 + |y|)``: the largest ratio over the free joints (at most 1: accept)."""
    err = 0.0
    for i in range(q_new.shape[0]):
        if prescribed[i]:
            continue
        eq = h / 6.0 * abs(k4q[i] - qd_new[i]) / (tolerance * (1.0 + abs(q_new[i])))
        ev = h / 6.0 * abs(a4[i] - a5[i]) / (tolerance * (1.0 + abs(qd_new[i])))
        if not (eq < np.inf and ev < np.inf):
            return np.inf
        err = max(err, eq, ev)
    return err


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def run_loop(plant, ctrl, motion, timing, wall, handle, rec, scratch):
    """Run the loop (records of :mod:`.records`, its state and stage arrays in ``scratch``); returns (records written, status, time the safety
    switch tripped or -1, peak excursion of the wall coordinate from ``wall.reference`` over every
    plant step, time the run ended, steps taken).

    Steps: with ``timing.tolerance == 0`` every step is one plant step ``h`` (the seed's fixed-step
    RK4). Otherwise a step spans ``m`` plant steps, ``m`` from ``timing.spans`` (the divisors of the
    sample period and of the record stride in plant steps, so that steps end on every sample instant
    and recorded row), chosen by error control: the slope at the step's end, ``k5 = f(t + m h, y_1)``,
    which the next step needs anyway (its first stage, or the sensors' acceleration at a sample
    instant: the same state and held torque), gives the embedded third-order solution
    ``y + m h (k1/6 + k2/3 + k3/3 + k5/6)``, whose distance ``m h |k4 - k5| / 6`` from RK4's
    ``y_1`` estimates the local error (it is O((m h)^4)). A step whose estimate exceeds
    ``tolerance (1 + |y|)`` is retried with a smaller span, the next one's span grows while the
    estimate scaled by ``(m' / m)^4`` stays below half the tolerance, and a step of one plant step is
    always accepted. Between two sample instants the held torque is constant, so the right-hand
    side is smooth there and a step of the whole period usually passes: four evaluations of the
    dynamics per sample instead of forty at ``h`` = 0.1 ms. Checks (excursion, safety switch) run at
    the end of every step and, inside a longer one, at each plant step from the cubic Hermite
    interpolant of the wall coordinate (:func:`_inside_step`): a step that would pass the safety limit
    or the excursion stop there is retried to end on that plant step, so the switch trips and the run
    stops on the plant step where the fixed step would.

    The excursion is checked at every plant step, so a run stopped at ``wall.stop_excursion`` reports a
    peak at or above it even when no recorded row (every ``timing.stride`` plant steps) shows it.

    Compiled without numba's reference counting (``_nrt=False``): the loop allocates nothing (its
    arrays come in ``scratch``), and each array a helper reads from a record would otherwise cost an
    atomic increment and decrement of its reference count in the innermost loop, which took about a
    third of a tree run's time (Phantom, type 1: 56 -> 17 ms for 5 s).

    The evaluation of the plant (:func:`accelerations` with the record's terms) is inlined at two places
    only, one for a sample instant and stage 1, one for stages 2-4 and the error estimate's slope (loops
    over the stages pick their arrays): numba's compile time grows faster than the code it inlines, and
    the six inlined copies this loop had took most of the 127 CPU-s a fresh install spent on its first
    ``impedance-range`` (``benchmarks/bench_cold.py``); the arithmetic, and so every trace, is the same."""
    prescribed, path_q, path_qd, path_qdd = motion.prescribed, motion.path_q, motion.path_qd, motion.path_qdd
    step, sub, n_steps, stride, spans, tolerance = (timing.step, timing.sub, timing.n_steps, timing.stride, timing.spans,
                                                    timing.tolerance)
    delay, quant = ctrl.delay, ctrl.quant
    rec_q, rec_qd, rec_u, rec_f, rec_imp, rec_c, rec_w = rec.q, rec.qd, rec.u, rec.tau_f, rec.tau_imp, rec.tau_c, rec.wall
    q, qd, u, tau_f, tau_imp, qdd, tau_c = scratch.q, scratch.qd, scratch.u, scratch.tau_f, scratch.tau_imp, scratch.qdd, scratch.tau_c
    k1q, k2q, k3q, k4q, a1, a2, a3, a4 = scratch.k1q, scratch.k2q, scratch.k3q, scratch.k4q, scratch.a1, scratch.a2, scratch.a3, scratch.a4
    c1, qs, qds, buf, sensed = scratch.c1, scratch.qs, scratch.qds, scratch.buf, scratch.sensed
    q_new, qd_new, a5, jn = scratch.q_new, scratch.qd_new, scratch.a5, scratch.jn
    n = q.shape[0]
    n_span = spans.shape[0]
    for i in range(n):
        q[i] = path_q[0, i] if prescribed[i] else motion.q0[i]
        qd[i] = path_qd[0, i] if prescribed[i] else motion.qd0[i]
        u[i] = tau_f[i] = tau_imp[i] = qdd[i] = tau_c[i] = 0.0
    for slot in range(buf.shape[0]):
        for row in range(3):
            for i in range(n):
                buf[slot, row, i] = 0.0
    n_free = 0
    for i in range(n):
        if not prescribed[i]:
            n_free += 1
    tripped = False
    trip_time = -1.0
    written = 0
    status = STATUS_COMPLETED
    peak = 0.0
    if tolerance > 0.0:
        coord, rate = _wall_state(q, qd, wall, handle, plant, jn)
    else:
        coord, rate = _wall_coordinate(q, qd, wall, handle, plant), 0.0
    end_time = 0.0
    it = 0
    wanted = 0
    taken = 0
    while True:
        t = it * step
        # one evaluation of the plant, inlined once for both uses: at a sample instant the sensors'
        # acceleration under the torque held so far (phase 0), then stage 1 under the new torque (phase 1,
        # which also gives the recorded constraint torque)
        phase = 0 if it % sub == 0 else 1
        while True:
            accelerations(q, qd, path_qdd[2 * it], u, prescribed, plant, qdd if phase == 0 else a1, c1, True)
            if phase == 1:
                break
            phase = 1
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
            _compensator_torque(sensed[0], sensed[1], sensed[2], ctrl, tau_f)
            _wall_torque(sensed[0], sensed[1], wall, handle, ctrl, tau_imp)
            if tripped:
                for i in range(n):
                    tau_f[i] = 0.0
                    tau_imp[i] = 0.0
            for i in range(n):
                u[i] = tau_f[i] - tau_imp[i]
        if _status(plant) != 0 or _status(ctrl) != 0:
            # a closed-loop plant or model left its assembly branch here or in the last step's stages
            status = STATUS_LOOP_LOST
            end_time = t
            break
        if it % stride == 0:
            r = it // stride
            for i in range(n):
                rec_q[r, i] = q[i]
                rec_qd[r, i] = qd[i]
                rec_u[r, i] = u[i]
                rec_f[r, i] = tau_f[i]
                rec_imp[r, i] = tau_imp[i]
                rec_c[r, i] = c1[i]
            rec_w[r] = coord
            written = r + 1
        finite = True
        for i in range(n):
            if not (np.isfinite(q[i]) and np.isfinite(qd[i])) or abs(qd[i]) > 1e8:
                finite = False
        end_time = t
        if not finite:
            status = STATUS_DIVERGED
            break
        excursion = abs(coord - wall.reference)
        if excursion > peak:
            peak = excursion
        if excursion >= wall.stop_excursion:
            status = STATUS_EXCURSION
            break
        if it == n_steps:
            break
        inside_peak = coord_new = rate_new = 0.0
        if n_free == 0:
            m = 1
            h = step
            end = 2 * (it + m)
            for i in range(n):
                q_new[i] = path_q[end, i]
                qd_new[i] = path_qd[end, i]
        else:
            for i in range(n):
                k1q[i] = qd[i]
            s = _first_span(spans, wanted, it, n_steps)
            while True:
                # RK4 over m plant steps; prescribed joints follow the path at each stage time
                m = spans[s]
                h = m * step
                mid, end = 2 * it + m, 2 * (it + m)
                # stages 2-4, then (error control only) the slope at the step's end: one inlined evaluation
                for stage in range(4):
                    if stage == 3:
                        for i in range(n):
                            if prescribed[i]:
                                q_new[i] = path_q[end, i]
                                qd_new[i] = path_qd[end, i]
                            else:
                                q_new[i] = q[i] + h / 6.0 * (k1q[i] + 2.0 * k2q[i] + 2.0 * k3q[i] + k4q[i])
                                qd_new[i] = qd[i] + h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i])
                        if tolerance == 0.0:
                            break
                        at_q, at_qd, row, slope = q_new, qd_new, end, a5
                    else:
                        k_in, a_in, k_out, slope = ((k1q, a1, k2q, a2) if stage == 0 else
                                                    (k2q, a2, k3q, a3) if stage == 1 else (k3q, a3, k4q, a4))
                        row = mid if stage < 2 else end
                        _stage_state(q, qd, k_in, a_in, 0.5 * h if stage < 2 else h, prescribed, path_q[row],
                                     path_qd[row], qs, qds)
                        for i in range(n):
                            k_out[i] = qds[i]
                        at_q, at_qd = qs, qds
                    accelerations(at_q, at_qd, path_qdd[row], u, prescribed, plant, slope, tau_c, False)
                if tolerance == 0.0:
                    break
                err = _step_error(q_new, qd_new, k4q, a4, a5, h, prescribed, tolerance)
                if not (err <= 1.0) and s < n_span - 1:
                    s = _first_span(spans, s + 1, it, n_steps)
                    continue
                # checks at the plant steps inside: a step over the safety limit or the excursion stop is
                # retried so that it ends on the first plant step that reaches it, as the fixed step does
                coord_new, rate_new = _wall_state(q_new, qd_new, wall, handle, plant, jn)
                k_event, inside_peak = _inside_step(coord, rate, coord_new, rate_new, m, h, wall, tripped)
                if k_event > 0:
                    s = _first_span(spans, _span_at_most(spans, k_event), it, n_steps)
                    continue
                # the next step: the largest span whose scaled estimate stays below half the tolerance
                wanted = s
                while wanted > 0 and err * (spans[wanted - 1] / m) ** 4 <= 0.5:
                    wanted -= 1
                break
        for i in range(n):
            q[i] = q_new[i]
            qd[i] = qd_new[i]
        it += m
        taken += 1
        peak = max(peak, inside_peak)
        if tolerance > 0.0 and n_free > 0:
            coord, rate = coord_new, rate_new  # the accepted step's end, evaluated for its checks
        elif tolerance > 0.0:
            coord, rate = _wall_state(q, qd, wall, handle, plant, jn)
        else:
            coord = _wall_coordinate(q, qd, wall, handle, plant)
        if not tripped and abs(coord - wall.reference) >= wall.safety_limit:
            tripped = True
            trip_time = t + h
            for i in range(n):
                tau_f[i] = 0.0
                tau_imp[i] = 0.0
                u[i] = 0.0
    return written, status, trip_time, peak, end_time, taken
