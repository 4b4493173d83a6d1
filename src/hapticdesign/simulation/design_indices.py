"""The whole registry of design indices: the analysis layer's (:mod:`hapticdesign.analysis.metrics.indices`) and
``kmax``, the stable Cartesian wall stiffness, which needs the sampled loop's exact analysis of this layer.

``kmax`` (N/m) = the exact stable stiffness of a virtual wall at the handle, every joint free
(:func:`hapticdesign.analysis.wall_stiffness.kmax`: the n-joint sampled loop discretized exactly) with the options
of :data:`~hapticdesign.analysis.wall_stiffness.KMAX_OPTIONS` (the loop's settings, practice's by default: 1 kHz,
one sample of delay, backward-difference velocity, gravity compensation, no hand; ``hand: grasp`` adds the default
grasp) and ``direction`` (a base-frame vector; default: the worst direction). Dry friction and quantization are
not in it: their limit is the simulated loop's, too slow for a study's many designs. The index lives here, above the
analysis layer, because its engine (:mod:`hapticdesign.analysis.sampled_loop`) does; an optimization or a study asks
this module's :func:`evaluate` and :data:`DESIGN_INDICES`.

:func:`evaluate_designs` evaluates many designs of a :class:`~hapticdesign.devices.design_space.DesignSpace` at
once: through the compiled kernels of :mod:`hapticdesign.analysis.design_batch` when the device has closed loops,
the indices need only ``J_v``, ``H`` and ``B`` (:data:`BATCHED`: those of
:data:`~hapticdesign.analysis.metrics.indices.KINEMATIC_DYNAMIC` and ``kmax``) and the variables are geometry
(``parameters``) of a device without bodies that are links (whose masses follow the geometry; the batch keeps the
file's inertial parameters, and its damping ``B``, numbers of the file that no geometry changes); otherwise design
by design (:func:`evaluate`). Both give the same values; ``kmax`` of all designs' points is one search
(:func:`~hapticdesign.analysis.wall_stiffness.wall_limits`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

import numpy as np

from hapticdesign.analysis.design_batch import OK, DesignBatch
from hapticdesign.analysis.metrics.indices import (
    INDICES, KINEMATIC_DYNAMIC, Evaluation, HandleStates, Index, Request, requests_of,
)
from hapticdesign.analysis.metrics.indices import evaluate as evaluate_with
from hapticdesign.devices.design_space import DesignSpace
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.analysis.wall_stiffness import KMAX_OPTIONS, kmax


def _kmax(h: HandleStates, options: Mapping[str, object]) -> np.ndarray:
    return kmax(h.jacobian, h.mass, h.damping, h.svd[0], options)


BATCHED = (*KINEMATIC_DYNAMIC, "kmax")
"""The indices :func:`evaluate_designs` computes from the compiled kernels' ``J_v`` and ``H`` (and the file's ``B``)."""

DESIGN_INDICES: dict[str, Index] = {**INDICES, "kmax": Index(
    "kmax", "N/m", "exact stable wall stiffness of the sampled loop along a direction (or the worst)",
    "seed 000 ch. 4-5; hapticdesign.analysis.sampled_loop.handle_limits", _kmax, KMAX_OPTIONS)}
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
    batch = _batch(space, checked)
    if batch is None:
        return [_one(space, values, points, checked) for values in designs]
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
                             mass[ok].reshape(-1, *mass.shape[2:]), base.damping_matrix)
    values = {r.key: DESIGN_INDICES[r.index].values(states, {**DESIGN_INDICES[r.index].options, **r.options})
              .reshape(-1, len(points)) for r in checked}
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


def _batch(space: DesignSpace, requests: list[Request]) -> DesignBatch | None:
    """The space's compiled structure when the batched path applies (see the module docstring), else None."""
    if (space.base.mechanism.loops is None or any(r.index not in BATCHED for r in requests)
            or any(v.kind != "parameter" for v in space.variables) or space.link_bodies):
        return None
    if space.cache.get("batch") is None:
        try:
            space.cache["batch"] = DesignBatch(space.base)
        except UserError:
            space.cache["batch"] = False
    return space.cache["batch"] or None


def _one(space: DesignSpace, values: Mapping[str, float], points: np.ndarray, requests: list[Request]) -> Evaluation:
    try:
        device = space.device(values)
    except UserError as exc:
        return Evaluation({}, str(exc))
    return evaluate(device, points, requests)
