"""Configure and run one sampled-data haptic simulation (seed 000 §4.1.1, §4.2.1).

:func:`simulate` wraps the numba kernel of :mod:`.kernel`; see that module for the model.
Defaults follow the seed: plant step 1e-4 s, sample period 1 ms, joint damping from the device
(0.50, 0.50, 0.35 N m s/rad for the Phantom, Table 4.1), perfect sensors (condition ix), no
modelling error (condition vi), no hand (condition vii), safety switch at 0.06 rad (Fig. 4.7).
"""

from __future__ import annotations

import math

import numpy as np

from hapticdesign.analysis.dynamics.closed_loop_plant import ClosedLoopPlant
from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.dynamics.model import has_trigonometric_basis
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation import kernel, records
from hapticdesign.simulation.config import (
    LoopConfig, Trace, Wall, compensator_device, hand_matrices, plant_damping, plant_friction, rest_pose,
    unit_direction,
)
from hapticdesign.simulation.paths import Path
from hapticdesign.simulation.tables import DynamicsTables, workspace_size
from hapticdesign.simulation.warmup import ensure_compiled
from hapticdesign.workload import loop_bytes, require_memory


Dynamics = DynamicsTables | ClosedLoopPlant
"""What a simulation evaluates H, C qd^2 and G with: a tree's exact basis tables, or a closed-loop
device's compiled plant (its own warm-started workspace, so one per run and per side)."""


def joint_index(device: Device, joint: int | str) -> int:
    """0-based index of an actuated joint given 1-based (``1``) or by coordinate name (``theta1``)."""
    names = device.mechanism.actuated_coordinates
    if isinstance(joint, str) and not joint.strip().lstrip("-").isdigit():
        if joint not in names:
            raise UserError(f"unknown joint {joint!r}; joints: {', '.join(names)}")
        return names.index(joint)
    j = int(joint)
    if not 1 <= j <= len(names):
        raise UserError(f"unknown joint {joint}; the device has joints 1..{len(names)}")
    return j - 1


def _scratch(dynamics: Dynamics) -> records.DynamicsScratch:
    if isinstance(dynamics, ClosedLoopPlant):
        return records.loop_dynamics_scratch(dynamics.n_dof)
    return records.dynamics_scratch(dynamics.n_dof, workspace_size(dynamics), dynamics.index.shape[0], dynamics.n_entries)


def tables_of(device: Device) -> DynamicsTables | None:
    """The exact basis tables of a device whose model has an exact basis (an open chain), to reuse across runs;
    ``None`` for a closed-loop device, whose compiled plant :func:`simulate` builds for each run at its start pose."""
    return DynamicsTables.from_device(device) if has_trigonometric_basis(device.mechanism) else None


def _dynamics(device: Device, tables: DynamicsTables | None, q_start: np.ndarray) -> Dynamics:
    """The given tables, or the device's own: its tables, or its closed-loop plant started at ``q_start``."""
    tables = tables_of(device) if tables is None else tables
    return ClosedLoopPlant(dynamics_of(device), device.standard_parameters(), q_start) if tables is None else tables


def simulate(
    device: Device,
    config: LoopConfig,
    paths: dict[int, Path] | None = None,
    q0: np.ndarray | None = None,
    plant: DynamicsTables | None = None,
    model: DynamicsTables | None = None,
) -> Trace:
    """Simulate the loop; ``paths`` maps 0-based joint indices to prescribed paths (others are free).

    ``plant``/``model`` tables of an open chain may be passed to skip rebuilding them (campaign
    searches). Without ``q0`` the free joints start at :func:`~.config.rest_pose` (0, or a closed-loop
    device's home); a closed-loop device's plant and model are its compiled closed-loop plants
    (:class:`~hapticdesign.analysis.dynamics.closed_loop_plant.ClosedLoopPlant`), started there.
    """
    n = device.n_dof
    q_start = rest_pose(device) if q0 is None else np.asarray(q0, dtype=float).copy()
    for j, path in (paths or {}).items():
        if 0 <= j < n:
            q_start[j] = float(path.sample(np.zeros(1))[0][0])
    hand = hand_matrices(device, config.loop.hand, q_start)
    plant = _dynamics(device, plant, q_start)
    model = _dynamics(compensator_device(device, config), model, q_start)
    return simulate_tables(plant, model, config, plant_damping(device, config), paths, q_start, hand,
                           plant_friction(device, config),
                           handle_of(device, config.wall) if config.wall.cartesian else None)


def handle_of(device: Device, wall: Wall) -> records.Handle:
    """The kernel's handle kinematics for a Cartesian ``wall`` on ``device`` (its end-effector frame)."""
    mech = device.mechanism
    if mech.end_effector is None:
        raise UserError("a Cartesian wall needs a device that names its end-effector (handle) frame")
    return records.handle(mech, unit_direction(wall.direction))


def simulate_tables(
    plant: Dynamics,
    model: Dynamics,
    config: LoopConfig,
    damping,
    paths: dict[int, Path] | None = None,
    q0: np.ndarray | None = None,
    hand: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    coulomb: tuple[np.ndarray, np.ndarray] | None = None,
    handle: records.Handle | None = None,
) -> Trace:
    """Simulate the loop for plant and compensator dynamics directly (any number of joints): exact
    basis tables, or closed-loop plants started at ``q0`` (each used by one run only); a Cartesian
    wall needs the device's ``handle`` (:func:`handle_of`). ``damping`` is one value per joint or a
    matrix; ``coulomb`` the friction ``(A, f)`` of :func:`~.config.plant_friction`."""
    n = plant.n_dof
    config.require_simulated()
    sub = config.steps_per_sample()
    if not (config.duration > 0 and math.isfinite(config.duration)):
        raise UserError(f"the duration must be positive, got {config.duration}")
    wall = config.wall
    if not 0 <= wall.joint < n:
        raise UserError(f"unknown joint {wall.joint + 1}; the device has joints 1..{n}")
    if not all(math.isfinite(v) for v in (wall.stiffness, wall.equilibrium)):
        raise UserError("the wall stiffness and equilibrium must be finite")
    if wall.cartesian and handle is None:
        raise UserError("a Cartesian wall needs the device's handle kinematics")
    paths = dict(paths or {})
    for j in paths:
        if not 0 <= j < n:
            raise UserError(f"unknown joint {j + 1}; the device has joints 1..{n}")
    loop = config.loop
    quant = 0.0 if config.counts is None else 2 * np.pi / config.counts
    damping = np.asarray(damping, dtype=float)
    if damping.shape == (n,):
        damping = np.diag(damping)
    if damping.shape != (n, n) or not np.all(np.isfinite(damping)):
        raise UserError(f"expected {n} finite joint dampings, got {damping.tolist()}")
    ratio = config.duration / config.step
    if not math.isfinite(ratio):
        raise UserError(f"the simulated time {config.duration:g} s over the plant step {config.step:g} s overflows")
    n_steps = int(round(ratio))
    stride = config.record_stride or sub
    if stride < 1:
        raise UserError("the record stride must be at least one plant step")
    if loop.delay * loop.period >= config.duration:
        raise UserError(f"the sensor delay ({loop.delay} samples = {loop.delay * loop.period:g} s) "
                        f"must be shorter than the simulated time ({config.duration:g} s)")
    require_memory(f"a simulation of {n_steps:,} plant steps", loop_bytes(n_steps, n, stride, loop.delay))
    q_start = np.zeros(n) if q0 is None else np.asarray(q0, dtype=float).copy()
    t_half = 0.5 * config.step * np.arange(2 * n_steps + 1)
    path_q, path_qd, path_qdd = (np.zeros((t_half.size, n)) for _ in range(3))
    prescribed = np.zeros(n, dtype=np.bool_)
    for j, path in paths.items():
        prescribed[j] = True
        path_q[:, j], path_qd[:, j], path_qdd[:, j] = path.sample(t_half)
        q_start[j] = path_q[0, j]
    hand_mass, hand_damping, hand_stiffness = hand if hand is not None else (np.zeros((n, n)),) * 3
    n_rec = n_steps // stride + 1
    rec = records.Records(*(np.zeros((n_rec, n)) for _ in range(6)), np.zeros(n_rec))
    switches = np.array(config.switches, dtype=float)
    friction_map, friction = (np.zeros((0, n)), np.zeros(0)) if coulomb is None else coulomb
    plant_record = _plant_record(plant, damping + hand_damping, np.asarray(friction, dtype=float),
                                 np.ascontiguousarray(friction_map, dtype=float), hand_mass, hand_stiffness,
                                 q_start.copy())
    controller = _controller_record(model, switches, quant, int(loop.delay))
    motion = records.Motion(prescribed, path_q, path_qd, path_qdd, q_start, np.zeros(n))
    adaptive = config.adaptive(isinstance(plant, ClosedLoopPlant))
    timing = records.Timing(float(config.step), sub, n_steps, stride, step_spans(sub, stride) if adaptive
                            else np.ones(1, dtype=np.int64), float(config.tolerance) if adaptive else 0.0)
    handle = handle if wall.cartesian else records.no_handle(n)
    if wall.cartesian:
        ensure_compiled(kernel.handle_coordinate, q_start, np.zeros(n), handle, plant_record)
    reference = (float(kernel.handle_coordinate(q_start, np.zeros(n), handle, plant_record)) if wall.cartesian
                 else float(q_start[wall.joint]))
    rest = reference + float(wall.equilibrium) if wall.cartesian else float(wall.equilibrium)
    law = records.WallLaw(
        cartesian=wall.cartesian, joint=wall.joint, stiffness=float(wall.stiffness), damping=float(loop.wall_damping),
        rest=rest, reference=reference,
        safety_limit=math.inf if config.safety_limit is None else float(config.safety_limit),
        stop_excursion=math.inf if config.stop_excursion is None else float(config.stop_excursion),
    )
    scratch = records.scratch(n, controller.delay)
    ensure_compiled(kernel.run_loop, plant_record, controller, motion, timing, law, handle, rec, scratch)
    written, status, trip, peak, end_time, taken = kernel.run_loop(plant_record, controller, motion, timing, law, handle, rec,
                                                                   scratch)
    t = np.arange(written) * stride * config.step
    q, qd, u, tau_f, tau_imp, tau_c, position = (r[:written] for r in rec)
    return Trace(t, q, qd, u, tau_f, tau_imp, tau_c, int(status), None if trip < 0 else float(trip),
                 float(peak), float(end_time), position, int(taken))


def warm_up(device: Device) -> None:
    """Compile the loop for ``device``'s kind of dynamics (a tree's tables or a closed-loop plant), with a joint
    wall and, when the device names its handle, a Cartesian one, or load it from numba's cache: two
    sample periods of each, results discarded. Run once before starting workers, so that they load the
    kernels instead of each compiling them (:mod:`.warmup`)."""
    walls = [Wall(joint=0, stiffness=0.0)]
    if device.mechanism.end_effector is not None:
        walls.append(Wall(joint=0, stiffness=0.0, direction=(1.0, 0.0, 0.0)))
    for wall in walls:
        simulate(device, LoopConfig(duration=2 * LoopConfig().loop.period, wall=wall))


def step_spans(sub: int, stride: int) -> np.ndarray:
    """The spans (plant steps, largest first) an adaptive step may take: the divisors of both the sample
    period and the record stride, so that steps end on every sample instant and recorded row."""
    g = math.gcd(sub, stride)
    return np.array([d for d in range(g, 0, -1) if g % d == 0], dtype=np.int64)


def _plant_record(plant: Dynamics, damping, friction, friction_map, hand_mass, hand_stiffness, hand_rest):
    """The kernel's plant: :class:`~.records.Plant` of tables or :class:`~.records.LoopPlant`."""
    if isinstance(plant, ClosedLoopPlant):
        return records.LoopPlant(plant.structure, plant.workspace, _scratch(plant), np.zeros(plant.n_dof),
                                 np.zeros(1, dtype=np.int64), damping, friction, friction_map, hand_mass,
                                 hand_stiffness, hand_rest)
    return records.Plant(records.table(plant), _scratch(plant), damping, friction, friction_map, hand_mass,
                         hand_stiffness, hand_rest)


def _controller_record(model: Dynamics, switches: np.ndarray, quant: float, delay: int):
    """The kernel's compensator: :class:`~.records.Controller` of tables or :class:`~.records.LoopController`."""
    if isinstance(model, ClosedLoopPlant):
        return records.LoopController(model.structure, model.workspace, _scratch(model), np.zeros(model.n_dof),
                                      np.zeros(1, dtype=np.int64), switches, quant, delay)
    return records.Controller(records.table(model), _scratch(model), switches, quant, delay)
