"""Design indices evaluated: one design at workspace points (:func:`evaluate`, :func:`evaluate_at`), many designs at
once (:func:`evaluate_designs`), the parameters of many designs (:func:`evaluate_parameters`), and the reductions
over the points (docs/indices.md).

:func:`evaluate_designs` goes through the compiled kernels of :mod:`hapticdesign.analysis.design_batch` when the
device has closed loops, every index asked needs at most what the kernels give (:data:`~.states.BATCH_NEEDS`:
``J_v``, ``H`` and the damping ``B``) and the variables are geometry (``parameters``) of a device without bodies that
are links (whose masses follow the geometry; the batch keeps the file's inertial parameters, and its damping ``B``,
numbers of the file that no geometry changes); otherwise design by design (:func:`evaluate`). Both give the same
values; ``kmax`` of all designs' points is one search (:func:`~hapticdesign.analysis.wall_stiffness.wall_limits`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import NamedTuple, Protocol

import numpy as np

from hapticdesign.analysis.design_batch import OK, DesignBatch
from hapticdesign.analysis.metrics.indices.registry import INDICES, Index, Request, requests_of
from hapticdesign.analysis.metrics.indices.states import BATCH_NEEDS, HandleStates, ParameterStates
from hapticdesign.analysis.workspace import reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device

REDUCTIONS: dict[str, Callable[[np.ndarray], float]] = {
    "min": lambda v: float(np.min(v)),
    "max": lambda v: float(np.max(v)),
    "mean": lambda v: float(np.mean(v)),
}
"""Reductions of an index over the workspace points (the mean weighs each grid point alike; ``isotropy`` with
``mean`` over a uniform Cartesian grid is the global conditioning index of Gosselin & Angeles (1991))."""


class Evaluation(NamedTuple):
    """Values per request key per point (P,), or ``reason`` (one line) when the design fails (``values`` empty)."""

    values: dict[str, np.ndarray]
    reason: str | None = None


class DesignFamily(Protocol):
    """What :func:`evaluate_designs` reads of a family of designs
    (:class:`hapticdesign.devices.design_space.DesignSpace`)."""

    base: Device
    variables: Sequence
    link_bodies: object
    cache: dict

    def checked_values(self, values: Mapping[str, float]) -> dict[str, float]: ...

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
    batch = _batch(space, checked, registry)
    if batch is None:
        return [_one(space, values, points, checked, registry) for values in designs]
    kinematic = np.tile(batch.p0, (len(designs), 1))
    column = {name: k for k, name in enumerate(batch.names)}
    refused: dict[int, str] = {}
    for d, values in enumerate(designs):
        try:
            for name, value in space.checked_values(values).items():
                kinematic[d, column[name]] = value
        except UserError as exc:
            refused[d] = str(exc)
    offsets = batch.offsets(kinematic)
    reached = batch.reach_points(offsets, points)
    base = space.base
    mass = batch.mass_matrices(offsets, reached, base.standard_parameters(), base.reflected_inertia)
    ok = reached.status == OK
    states = HandleStates.of(reached.jvt[ok].reshape(-1, 3, reached.jvt.shape[-1]),
                             mass[ok].reshape(-1, *mass.shape[2:]), base.damping_matrix,
                             reached.full[ok][..., batch.closures.actuated].reshape(-1, len(batch.closures.actuated)))
    values = {r.key: registry[r.index].values(states, r.options).reshape(-1, len(points)) for r in checked}
    out, row = [], 0
    for d in range(len(designs)):
        if d in refused:
            out.append(Evaluation({}, refused[d]))
        elif not ok[d]:
            out.append(Evaluation({}, batch.reason(reached, d, points)))
        else:
            out.append(Evaluation({key: v[row] for key, v in values.items()}))
        row += int(ok[d])
    return out


def batched(requests: list[Request], registry: Mapping[str, Index] = INDICES) -> bool:
    """True when every index of ``requests`` needs at most what the compiled kernels give (:data:`BATCH_NEEDS`)."""
    return all(registry[r.index].needs <= BATCH_NEEDS for r in requests)


def _batch(space: DesignFamily, requests: list[Request], registry: Mapping[str, Index]) -> DesignBatch | None:
    """The space's compiled structure when the batched path applies (see the module docstring), else None."""
    if (space.base.mechanism.loops is None or not batched(requests, registry)
            or any(v.kind != "parameter" for v in space.variables) or space.link_bodies):
        return None
    if space.cache.get("batch") is None:
        try:
            space.cache["batch"] = DesignBatch(space.base)
        except UserError:
            space.cache["batch"] = False
    return space.cache["batch"] or None


def _one(space: DesignFamily, values: Mapping[str, float], points: np.ndarray, requests: list[Request],
         registry: Mapping[str, Index]) -> Evaluation:
    try:
        device = space.device(values)
    except UserError as exc:
        return Evaluation({}, str(exc))
    return evaluate(device, points, requests, registry=registry)


def reduce(values: np.ndarray, how: str) -> float:
    """An index over the workspace points reduced by ``min``, ``max`` or ``mean``."""
    if how not in REDUCTIONS:
        raise UserError(f"unknown reduction {how!r} (use {', '.join(REDUCTIONS)})")
    return REDUCTIONS[how](values)
