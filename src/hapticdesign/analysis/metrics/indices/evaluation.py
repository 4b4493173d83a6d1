"""Design indices evaluated: one design at workspace points (:func:`evaluate`, :func:`evaluate_at`), many designs at
once (:func:`evaluate_designs`), the parameters of many designs (:func:`evaluate_parameters`), and the reductions
over the points (docs/indices.md).

:func:`evaluate_designs` evaluates many designs of a :class:`~hapticdesign.devices.design_space.DesignSpace` at once,
a generation at a time, through the compiled kernels of :mod:`hapticdesign.analysis.design_batch` (trees and closed
loops alike, every kind of design variable: geometry, sections, inertial parameters, link bodies, motors):
:meth:`~hapticdesign.devices.design_space.DesignSpace.batch_values` gives each design's inertial parameters,
reflected rotor inertia, damping ``B``, motors and sections, the batch each design's ``J_v``, ``H`` and ``K_C`` at
the points, and every index that needs at most what they give (:data:`~.states.BATCH_NEEDS`) follows from them; an
index of the whole device (``ln``, which needs the ``device``), and a device whose handle moves in fewer directions
than it has actuated coordinates (or more than 3), go design by design (:func:`evaluate`). Both give the same
values; ``kmax`` of all designs' points is one search (:func:`~hapticdesign.analysis.wall_stiffness.wall_limits`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import NamedTuple, Protocol

import numpy as np

from hapticdesign.analysis.design_batch import DesignBatch
from hapticdesign.analysis.metrics.indices.registry import INDICES, Index, Request, requests_of
from hapticdesign.analysis.metrics.indices.states import BATCH_NEEDS, HandleStates, ParameterStates
from hapticdesign.analysis.stiffness.drive import compliant_drive, elastic, joint_compliance
from hapticdesign.analysis.workspace import reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device


def _at_center(values: np.ndarray, center: int | None) -> float:
    if center is None:
        raise UserError("reduction center needs the box's centre among the workspace points (an odd grid)")
    return float(values[center])


REDUCTIONS: dict[str, Callable[[np.ndarray, int | None], float]] = {
    "min": lambda v, _: float(np.min(v)),
    "max": lambda v, _: float(np.max(v)),
    "mean": lambda v, _: float(np.mean(v)),
    "median": lambda v, _: float(np.median(v)),
    "center": _at_center,
}
"""Reductions of an index over the workspace points (P,), given the place of the box's centre among them (None when
it is not one of them). Each weighs the grid's points alike: ``mean`` is the arithmetic mean (``isotropy`` with
``mean`` over a uniform Cartesian grid is the global conditioning index of Gosselin & Angeles (1991)), ``median`` the
middle value (the mean of the two middle ones for an even count), ``min`` and ``max`` the extremes of the points
(a finer grid that holds the coarser one's points, grid 5 of grid 3's, can only widen them), ``center`` the value at the box's centre (docs/indices.md)."""


class Evaluation(NamedTuple):
    """Values per request key per point (P,), or ``reason`` (one line) when the design fails (``values`` empty)."""

    values: dict[str, np.ndarray]
    reason: str | None = None


class DesignFamily(Protocol):
    """What :func:`evaluate_designs` reads of a family of designs
    (:class:`hapticdesign.devices.design_space.DesignSpace`)."""

    base: Device
    cache: dict
    home_position: np.ndarray | None

    def batch_values(self, designs: Sequence[Mapping[str, float]], batch: DesignBatch): ...

    def device(self, values: Mapping[str, float]) -> Device: ...


def evaluate(device: Device, points: np.ndarray, requests: Iterable[str | Request], frame: str | None = None,
             registry: Mapping[str, Index] = INDICES) -> Evaluation:
    """The indices ``requests`` at the workspace ``points`` (P, 3), reached in order from home
    (:func:`~hapticdesign.analysis.workspace.reach_workspace`). A point the handle does not reach (out of reach,
    behind a singularity, outside the joint limits), or an index the design cannot give, makes the design fail:
    the reason says why (naming the point)."""
    checked = requests_of(requests, registry)
    try:
        poses = reach_workspace(device, points, frame)
        return evaluate_at(device, poses.full, checked, frame, registry)
    except UserError as exc:
        return Evaluation({}, str(exc))


def evaluate_at(device: Device, full: np.ndarray, requests: list[Request], frame: str | None = None,
                registry: Mapping[str, Index] = INDICES) -> Evaluation:
    """The checked ``requests`` at closed full poses (P, N); an index the design cannot give raises UserError. An
    index of the parameters alone has the design's one value at every pose."""
    states = HandleStates(device, np.atleast_2d(full), frame)
    parameters = None
    values = {}
    for request in requests:
        index = registry[request.index]
        if index.of_parameters:
            parameters = parameters or ParameterStates.of_device(device)
            values[request.key] = np.full(len(states.full), index.values(parameters, request.options)[0])
        else:
            values[request.key] = index.values(states, request.options)
    return Evaluation(values)


def evaluate_parameters(params: Mapping[str, np.ndarray], requests: list[Request],
                        registry: Mapping[str, Index] = INDICES) -> dict[str, np.ndarray]:
    """The checked ``requests`` of indices of the parameters alone, for the designs whose parameters are ``params``
    (name -> (D,) values): (D,) values per request key, the closed forms they share computed once."""
    states = ParameterStates(params)
    return {r.key: registry[r.index].values(states, r.options) for r in requests}


def evaluate_designs(space: DesignFamily, designs: Sequence[Mapping[str, float]], points: np.ndarray,
                     requests: Iterable[str | Request], registry: Mapping[str, Index] = INDICES) -> list[Evaluation]:
    """:func:`evaluate` of each design (variable values) of ``space`` at the workspace ``points`` (P, 3); a design the
    device file refuses fails with its reason (see the module docstring for the batched path)."""
    checked = requests_of(requests, registry)
    points = np.asarray(points, dtype=float)
    batch = _batch(space, checked, registry) if designs else None
    if batch is None:
        return [_one(space, values, points, checked, registry) for values in designs]
    links = any("compliance" in registry[r.index].needs for r in checked) and elastic(space.base)
    sections = links or any("sections" in registry[r.index].needs for r in checked)
    gravity = any("gravity" in registry[r.index].needs for r in checked)
    got = batch.evaluate(space.batch_values(designs, batch), points, sections, space.home_position, gravity)
    ok, v = got.ok, got.values
    per_pose = np.repeat(np.flatnonzero(ok), len(points))
    n_a = got.jacobian.shape[-1]
    transmission = None if v.transmission is None else v.transmission.taken(per_pose)
    drive = transmission if not (links and ok.any()) else compliant_drive(
        transmission, joint_compliance(got.jacobian[ok].reshape(-1, 3, n_a), got.stiffness[ok].reshape(-1, 6, 6)),
        v.reflected[per_pose], v.motor_damping[per_pose])
    states = HandleStates.of(
        got.jacobian[ok].reshape(-1, 3, n_a), got.mass[ok].reshape(-1, n_a, n_a), v.damping[per_pose],
        got.q[ok].reshape(-1, n_a), int(ok.sum()), motor_map=None if v.motor_map is None else v.motor_map[per_pose],
        torque_limits={k: None if t is None else t[per_pose] for k, t in v.torques.items()},
        moving_mass=got.moving_mass[per_pose], name=space.base.name,
        transmission=transmission, drive=drive,
        model=lambda error: tuple(x[ok].reshape(-1, n_a, n_a) for x in got.model(error)),
        **({} if got.gravity is None else {"gravity": got.gravity[ok].reshape(-1, n_a, n_a)}))
    if sections:
        u = states.svd[0]
        states.__dict__["stiffness"] = np.swapaxes(u, 1, 2) @ got.stiffness[ok].reshape(-1, 6, 6)[:, :3, :3] @ u
    values, failed = {}, None
    try:
        for r in checked if ok.any() else ():
            values[r.key] = np.asarray(registry[r.index].values(states, r.options), dtype=float).reshape(-1, len(points))
    except UserError as exc:  # an index no design of the space can give (the same for each, as design by design)
        failed = str(exc)
    rows = (dict(zip(values, row)) for row in zip(*values.values()))  # the designs that reached, in order
    out = []
    for d, reached in enumerate(ok.tolist()):
        if not reached:
            out.append(Evaluation({}, got.reasons[d]))
        elif failed is not None:
            out.append(Evaluation({}, failed))
        else:
            out.append(Evaluation(next(rows, {})))
    return out


def batched(requests: list[Request], registry: Mapping[str, Index] = INDICES) -> bool:
    """True when every index of ``requests`` needs at most what the compiled kernels give (:data:`BATCH_NEEDS`)."""
    return all(registry[r.index].needs <= BATCH_NEEDS for r in requests)


def _batch(space: DesignFamily, requests: list[Request], registry: Mapping[str, Index]) -> DesignBatch | None:
    """The space's compiled structure when the batched path applies (see the module docstring), else None: design
    by design for an index of the whole device, and for one that needs the sections of a device without elastic
    links or joints (where the device's own evaluation says why)."""
    elastic = space.base.elasticity
    if not batched(requests, registry) or (
            any("sections" in registry[r.index].needs for r in requests)
            and (elastic is None or not (elastic.links or elastic.joints))):
        return None
    if space.cache.get("batch") is None:
        try:
            space.cache["batch"] = DesignBatch(space.base)
        except UserError:
            space.cache["batch"] = False
    return space.cache["batch"] or None


def _one(space: DesignFamily, values: Mapping[str, float], points: np.ndarray, requests: list[Request],
         registry: Mapping[str, Index]) -> Evaluation:
    """One design's evaluation, or why it has none: the device file refuses it or an index cannot be computed."""
    try:
        return evaluate(space.device(values), points, requests, registry=registry)
    except UserError as exc:
        return Evaluation({}, str(exc))


def check_reduction(how: str) -> str:
    """``how`` when it names a reduction (:data:`REDUCTIONS`), else a one-line UserError."""
    if how not in REDUCTIONS:
        raise UserError(f"unknown reduction {how!r} (use {', '.join(REDUCTIONS)})")
    return how


def reduce(values: np.ndarray, how: str, center: int | None = None) -> float:
    """An index over the workspace points (P,) reduced by ``how`` (:data:`REDUCTIONS`); ``center``: the place of the
    box's centre among the points, which ``center`` reads
    (:attr:`~hapticdesign.analysis.workspace.Workspace.center_index`)."""
    return REDUCTIONS[check_reduction(how)](values, center)


def reduced_at(values: np.ndarray, how: str, center: int | None = None) -> int | None:
    """The place among the points (P,) where the reduction ``how`` takes its value: the first smallest (``min``), the
    first largest (``max``), ``center``; None for ``mean`` and ``median``, which no one point holds."""
    if check_reduction(how) == "center":
        return center
    if how in ("min", "max"):
        return int(np.argmin(values) if how == "min" else np.argmax(values))
    return None


TIE = 1e-9
"""Relative difference within which two points' values tie for an extreme (:func:`spread`)."""


def spread(values: np.ndarray, center: int | None = None) -> dict[str, float | int | None]:
    """An index over the points (P,) by every reduction (``center`` None where the centre is not among them), where
    the extremes are taken (``min_at``, ``max_at``: the first place among the points) and at how many points
    (``min_count``, ``max_count``: the points within :data:`TIE` of the extreme, e.g. a symmetric device's mirrored
    corners)."""
    out: dict[str, float | int | None] = {
        how: None if how == "center" and center is None else reduce(values, how, center) for how in REDUCTIONS}
    for how in ("min", "max"):
        out[f"{how}_at"] = reduced_at(values, how)
        out[f"{how}_count"] = int(np.count_nonzero(np.abs(values - out[how]) <= TIE * abs(out[how])))
    return out


def reduction_label(how: str, points: int, grid: int) -> str:
    """How coarse a reduction over a grid is, in words: ``max of 27 points, grid 3``."""
    return f"{check_reduction(how)} of {points} points, grid {grid}"
