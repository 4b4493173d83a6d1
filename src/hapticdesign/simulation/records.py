"""The typed records the numba loop (:mod:`.kernel`) takes, built in one place (:mod:`.loop`).

Each is a ``typing.NamedTuple`` of arrays and scalars, which numba compiles to a struct whose
fields the kernel reads by name: a stiffness cannot pass for a damping by its position.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from hapticdesign.model.walk import Tree


class Table(NamedTuple):
    """Sparse basis coefficients of H, C, G (:class:`~.tables.DynamicsTables`) for :func:`~.tables.evaluate_entries`."""

    rows: np.ndarray
    cols: np.ndarray
    vals: np.ndarray
    index: np.ndarray
    kinds: np.ndarray
    degrees: np.ndarray


class DynamicsScratch(NamedTuple):
    """Scratch arrays of one set of dynamics tables (basis values, entries, H, C, G, linear solve)."""

    values: np.ndarray
    phi: np.ndarray
    entries: np.ndarray
    cache_q: np.ndarray
    cache_qd: np.ndarray
    cache_valid: np.ndarray
    h: np.ndarray
    c: np.ndarray
    g: np.ndarray
    qd2: np.ndarray
    a: np.ndarray
    rhs: np.ndarray
    """The right-hand side, then the solution, of :func:`~hapticdesign.model.dense.solve_leading`."""
    free: np.ndarray


class Plant(NamedTuple):
    """The continuous side: dynamics tables, joint damping (with the hand's), Coulomb friction and the hand.

    ``coulomb`` (k,) and ``friction_map`` (k x n): friction ``f_k`` acting on the rate ``a_k^T qd`` of row
    ``a_k`` (a unit row for friction on one joint; :func:`~.config.plant_friction`)."""

    table: Table
    ws: DynamicsScratch
    damping: np.ndarray
    coulomb: np.ndarray
    friction_map: np.ndarray
    hand_mass: np.ndarray
    hand_stiffness: np.ndarray
    hand_rest: np.ndarray


class LoopPlant(NamedTuple):
    """The continuous side of a closed-loop device: the compiled closed-loop plant
    (:func:`~hapticdesign.analysis.dynamics.closed_loop_plant.closed_loop_terms`, its ``structure`` and
    warm-started ``loop_ws``), ``C(q, qd) qd^2`` as a vector, the plant's status (0 while the loops
    close on the assembly branch) and the fields of :class:`Plant` the loop reads."""

    structure: tuple
    loop_ws: tuple
    ws: DynamicsScratch
    cqd: np.ndarray
    status: np.ndarray
    damping: np.ndarray
    coulomb: np.ndarray
    friction_map: np.ndarray
    hand_mass: np.ndarray
    hand_stiffness: np.ndarray
    hand_rest: np.ndarray


class Controller(NamedTuple):
    """The digital side: the compensator's tables and switches ``(s_H, s_C, s_G)``, encoder step, delay."""

    table: Table
    ws: DynamicsScratch
    switches: np.ndarray
    quant: float
    delay: int


class LoopController(NamedTuple):
    """The digital side of a closed-loop device: the compensator's own closed-loop plant and
    workspace, ``C(q, qd) qd^2``, its status, and the fields of :class:`Controller` the loop reads."""

    structure: tuple
    loop_ws: tuple
    ws: DynamicsScratch
    cqd: np.ndarray
    status: np.ndarray
    switches: np.ndarray
    quant: float
    delay: int


class Motion(NamedTuple):
    """Which joints follow a path, the paths at every half plant step, and the start state."""

    prescribed: np.ndarray
    path_q: np.ndarray
    path_qd: np.ndarray
    path_qdd: np.ndarray
    q0: np.ndarray
    qd0: np.ndarray


class Timing(NamedTuple):
    """Plant step (s), plant steps per sample, plant steps of the run and between recorded rows; the
    spans (in plant steps, largest first, ending in 1) a step may take and the local error tolerance
    that chooses among them (0: always one plant step, the seed's fixed step; :func:`.kernel.run_loop`)."""

    step: float
    sub: int
    n_steps: int
    stride: int
    spans: np.ndarray
    tolerance: float


class WallLaw(NamedTuple):
    """The virtual wall on one joint, ``tau_imp[joint] = stiffness (q - rest) + damping qd``, or, when
    ``cartesian``, along the handle's direction n: ``tau_imp = J_n^T (stiffness (n.p - rest) + damping
    J_n qd)``. The wall coordinate is ``q[joint]`` or ``n.p``; the run stops once its distance from
    ``reference`` reaches ``stop_excursion`` and the safety switch cuts the torques once it reaches
    ``safety_limit``."""

    cartesian: bool
    joint: int
    stiffness: float
    damping: float
    rest: float
    reference: float
    safety_limit: float
    stop_excursion: float


class Handle(NamedTuple):
    """The folded frame tree (:class:`~hapticdesign.model.walk.KinematicTree`; a closed-loop device's
    loop-opened tree), the handle's node, the wall's unit direction and scratch for node poses and the
    handle's Jacobian (a closed-loop device takes its poses from the plant's or the compensator's
    closed pose instead)."""

    tree: Tree
    node: int
    direction: np.ndarray
    rot: np.ndarray
    pos: np.ndarray
    jac: np.ndarray


class Records(NamedTuple):
    """Recorded rows: positions, velocities, held torque, compensator, wall and constraint torques,
    and the wall coordinate."""

    q: np.ndarray
    qd: np.ndarray
    u: np.ndarray
    tau_f: np.ndarray
    tau_imp: np.ndarray
    tau_c: np.ndarray
    wall: np.ndarray


class Scratch(NamedTuple):
    """The loop's own state and scratch (the kernel allocates nothing): state ``q, qd``, held torque
    ``u`` and its parts, accelerations and constraint torques, RK4 slopes and stage state, the step's
    end state and its acceleration (the error estimate's fifth slope), a Cartesian wall's ``J_n``, the sensor delay line ``buf`` (delay + 1, 3, n) and the sensed ``(q, qd, qdd)``."""

    q: np.ndarray
    qd: np.ndarray
    u: np.ndarray
    tau_f: np.ndarray
    tau_imp: np.ndarray
    qdd: np.ndarray
    tau_c: np.ndarray
    k1q: np.ndarray
    k2q: np.ndarray
    k3q: np.ndarray
    k4q: np.ndarray
    a1: np.ndarray
    a2: np.ndarray
    a3: np.ndarray
    a4: np.ndarray
    c1: np.ndarray
    qs: np.ndarray
    qds: np.ndarray
    q_new: np.ndarray
    qd_new: np.ndarray
    a5: np.ndarray
    jn: np.ndarray
    buf: np.ndarray
    sensed: np.ndarray


def scratch(n: int, delay: int) -> Scratch:
    """The loop's state and scratch for ``n`` joints and a sensor delay of ``delay`` samples."""
    return Scratch(*(np.zeros(n) for _ in range(22)), np.zeros((delay + 1, 3, n)), np.zeros((3, n)))


def table(tables) -> Table:
    """The kernel's view of :class:`~.tables.DynamicsTables`."""
    return Table(*tables.sparse, tables.index, tables.kinds, tables.degrees)


def dynamics_scratch(n: int, n_values: int, n_basis: int, n_entries: int) -> DynamicsScratch:
    """Scratch arrays for one set of tables of ``n`` joints."""
    m = n * (n + 1) // 2
    return DynamicsScratch(
        np.zeros((n, n_values)), np.zeros(n_basis), np.zeros(n_entries), np.zeros(n), np.zeros(n),
        np.zeros(1, dtype=np.int64), np.zeros((n, n)), np.zeros((n, m)), np.zeros(n), np.zeros(m), np.zeros((n, n)),
        np.zeros(n), np.zeros(n, dtype=np.int64),
    )


def loop_dynamics_scratch(n: int) -> DynamicsScratch:
    """Scratch for a closed-loop plant of ``n`` actuated joints: no basis tables; ``C qd^2`` is the one
    column of ``c`` and its velocity product ``qd2`` the constant 1, so the loop reads it as ``c @ qd2``."""
    return DynamicsScratch(
        np.zeros((n, 1)), np.zeros(1), np.zeros(1), np.zeros(n), np.zeros(n), np.zeros(1, dtype=np.int64),
        np.zeros((n, n)), np.zeros((n, 1)), np.zeros(n), np.ones(1), np.zeros((n, n)), np.zeros(n),
        np.zeros(n, dtype=np.int64),
    )


def handle(mechanism, direction: np.ndarray) -> Handle:
    """The kernel's view of a mechanism's handle (end-effector frame) for a wall along ``direction``."""
    tree = mechanism.compiled.tree
    rot, pos = tree.workspace()
    arrays = tree.arrays._replace(coef=np.ascontiguousarray(tree.coef))
    return Handle(arrays, int(tree.frame_node[mechanism.end_effector]), np.ascontiguousarray(direction, dtype=float),
                  rot, pos, np.zeros((6, arrays.coef.shape[1])))


def no_handle(n: int) -> Handle:
    """A placeholder :class:`Handle` for a joint wall (same array types, so one compiled loop)."""
    empty = Tree(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros((0, n)), np.zeros(0),
                 np.zeros((0, 3, 3)), np.zeros((0, 3)))
    return Handle(empty, -1, np.zeros(3), np.zeros((1, 3, 3)), np.zeros((1, 3)), np.zeros((6, n)))
