"""The whole registry of design indices: the analysis layer's (:mod:`hapticdesign.analysis.metrics.indices`) and
``kmax``, the stable Cartesian wall stiffness, which needs the sampled loop's exact analysis of this layer.

``kmax`` (N/m) = the exact stable stiffness of a virtual wall at the handle
(:func:`hapticdesign.analysis.wall_stiffness.wall_limit`: the 1-DOF model of the handle along a direction, mass
``1 / (u^T J_v H^-1 J_v^T u)`` and damping ``u^T J_v^+T B J_v^+ u``, the loop discretized exactly) with the
options ``period`` (s, default 0.001), ``delay`` (samples, default 1), ``damping`` (the wall's virtual damper, N s/m,
default 0) and ``direction`` (a base-frame vector; default: the worst direction). The index lives here, above the
analysis layer, because its engine (:mod:`hapticdesign.analysis.sampled_loop`) does; an optimization or a study asks
this module's :func:`evaluate` and :data:`DESIGN_INDICES`.

:func:`evaluate_designs` evaluates many designs of a :class:`~hapticdesign.devices.design_space.DesignSpace` at
once, a generation at a time, through the compiled kernels of :mod:`hapticdesign.analysis.design_batch` (trees and
closed loops alike, every kind of design variable: geometry, sections, inertial parameters, link bodies, motors):
:meth:`~hapticdesign.devices.design_space.DesignSpace.batch_values` gives each design's inertial parameters,
reflected rotor inertia, damping ``B``, motors and sections, the batch each design's ``J_v``, ``H`` and ``K_C`` at
the points, and every index but ``ln`` (:data:`~hapticdesign.analysis.metrics.indices.PER_DESIGN`) follows from
them; ``ln``, and a device whose handle moves in fewer directions than it has actuated coordinates (or more than
3), go design by design (:func:`evaluate`). Both give the same values; ``kmax`` of all designs' points is one
search (:func:`~hapticdesign.analysis.wall_stiffness.wall_limits`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence

import numpy as np

from hapticdesign.analysis.design_batch import DesignBatch
from hapticdesign.analysis.metrics.indices import (
    INDICES, PER_DESIGN, Evaluation, HandleStates, Index, Request, requests_of,
)
from hapticdesign.analysis.metrics.indices import evaluate as evaluate_with
from hapticdesign.devices.design_space import DesignSpace
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.analysis.wall_stiffness import wall_limits


MAX_PERIOD = 1.0
"""Longest sample period (s) of ``kmax``'s loop: a haptic loop samples far faster than 1 Hz, and the exact
discretization of a handle's mass over much longer periods overflows."""


def _options(options: Mapping[str, object]) -> tuple[float, int, float, np.ndarray | None]:
    period, delay, damping, direction = (options[k] for k in ("period", "delay", "damping", "direction"))
    if isinstance(period, bool) or not isinstance(period, (int, float)) or not 0 < period <= MAX_PERIOD:
        raise UserError(f"index kmax: the sample period is a positive number of seconds, at most {MAX_PERIOD:g} s, "
                        f"got {period!r}")
    if isinstance(delay, bool) or not isinstance(delay, int) or not 0 <= delay <= 100:
        raise UserError(f"index kmax: the delay is a whole number of samples from 0 to 100, got {delay!r}")
    if isinstance(damping, bool) or not isinstance(damping, (int, float)) or not (math.isfinite(damping)
                                                                                   and damping >= 0):
        raise UserError(f"index kmax: the wall's damping is a number >= 0 (N s/m), got {damping!r}")
    if direction is not None:
        direction = np.asarray(direction, dtype=float)
        if direction.shape != (3,) or not np.all(np.isfinite(direction)) or not np.linalg.norm(direction) > 0:
            raise UserError(f"index kmax: the direction is 3 finite numbers, not all 0, got {options['direction']!r}")
        direction = direction / np.linalg.norm(direction)
    return float(period), delay, float(damping), direction


def _kmax(h: HandleStates, options: Mapping[str, object]) -> np.ndarray:
    period, delay, virtual, direction = _options(options)
    basis = h.svd[0]
    pinv = np.linalg.pinv(h.jacobian) @ basis
    along = None
    if direction is not None:
        along = np.swapaxes(basis, 1, 2) @ direction
        if not np.all(np.abs(np.linalg.norm(along, axis=1) - 1.0) <= 1e-9):
            raise UserError(f"index kmax: the direction {np.round(direction, 6).tolist()} is not one the handle "
                            "moves in")
        along = along[:, None, :]
    return wall_limits(h.mobility, np.swapaxes(pinv, 1, 2) @ h.damping @ pinv, period, delay, virtual, along)


DESIGN_INDICES: dict[str, Index] = {**INDICES, "kmax": Index(
    "kmax", "N/m", "exact stable wall stiffness of the sampled loop along a direction (or the worst)",
    "seed 000 ch. 4-5; hapticdesign.analysis.sampled_loop.exact_boundary", _kmax,
    {"period": 0.001, "delay": 1, "damping": 0.0, "direction": None})}
"""Every design index: name -> :class:`~hapticdesign.analysis.metrics.indices.Index`."""


def evaluate(device: Device, points: np.ndarray, requests: Iterable[str | Request],
             frame: str | None = None) -> Evaluation:
    """The indices ``requests`` (any of :data:`DESIGN_INDICES`) at the workspace ``points`` (P, 3), reached in order
    from home (:func:`hapticdesign.analysis.metrics.indices.evaluate`)."""
    return evaluate_with(device, points, requests, frame, DESIGN_INDICES)


def evaluate_designs(space: DesignSpace, designs: Sequence[Mapping[str, float]], points: np.ndarray,
                     requests: Iterable[str | Request]) -> list[Evaluation]:
    """:func:`evaluate` of each design (variable values) of ``space`` at the workspace ``points`` (P, 3); a design the
    device file refuses fails with its reason (see the module docstring for the batched path)."""
    checked = requests_of(requests, DESIGN_INDICES)
    points = np.asarray(points, dtype=float)
    batch = _batch(space, checked) if designs else None
    if batch is None:
        return [_one(space, values, points, checked) for values in designs]
    stiffness = any(r.index in ("stiffness", "frequency") for r in checked)
    got = batch.evaluate(space.batch_values(designs, batch), points, stiffness)
    ok, v = got.ok, got.values
    per_pose = np.repeat(np.flatnonzero(ok), len(points))
    n_a = got.jacobian.shape[-1]
    states = HandleStates.of(
        got.jacobian[ok].reshape(-1, 3, n_a), got.mass[ok].reshape(-1, n_a, n_a), damping=v.damping[per_pose],
        motor_map=None if v.motor_map is None else v.motor_map[per_pose],
        torque_limits={k: None if t is None else t[per_pose] for k, t in v.torques.items()},
        moving_mass=got.moving_mass[per_pose], name=space.base.name)
    if stiffness:
        u = states.svd[0]
        states.__dict__["stiffness"] = np.swapaxes(u, 1, 2) @ got.stiffness[ok].reshape(-1, 6, 6)[:, :3, :3] @ u
    values, failed = {}, None
    try:
        for r in checked if ok.any() else ():
            index = DESIGN_INDICES[r.index]
            values[r.key] = np.asarray(index.values(states, {**index.options, **r.options}),
                                       dtype=float).reshape(-1, len(points))
    except UserError as exc:  # an index no design of the space can give (the same for each, as design by design)
        failed = str(exc)
    out, row = [], 0
    for d in range(len(designs)):
        if not ok[d]:
            out.append(Evaluation({}, got.reasons[d]))
        elif failed is not None:
            out.append(Evaluation({}, failed))
        else:
            out.append(Evaluation({key: value[row] for key, value in values.items()}))
        row += int(ok[d])
    return out


def _batch(space: DesignSpace, requests: list[Request]) -> DesignBatch | None:
    """The space's compiled structure when the batched path applies (every index but those of
    :data:`~hapticdesign.analysis.metrics.indices.PER_DESIGN`; a device whose handle moves in as many directions
    as it has actuated coordinates, at most 3), else None."""
    elastic = space.base.elasticity
    if any(r.index in PER_DESIGN for r in requests) or (
            any(r.index in ("stiffness", "frequency") for r in requests)
            and (elastic is None or not (elastic.links or elastic.joints))):
        return None  # design by design (an index of the whole device; or one the device cannot give, said there)
    if space.cache.get("batch") is None:
        try:
            space.cache["batch"] = DesignBatch(space.base)
        except UserError:
            space.cache["batch"] = False
    return space.cache["batch"] or None


def _one(space: DesignSpace, values: Mapping[str, float], points: np.ndarray, requests: list[Request]) -> Evaluation:
    """One design's evaluation, or why it has none: the device file refuses it or an index cannot be computed."""
    try:
        return evaluate(space.device(values), points, requests)
    except UserError as exc:
        return Evaluation({}, str(exc))
