"""Design indices of any device (trees and closed loops) at workspace poses: one registry, each with its formula,
unit and source (issue 23; docs/indices.md).

At a pose, ``J_v`` is the handle's translational Jacobian over the actuated coordinates (3 x n_a, base frame;
``J T`` with loops, ``qd = T qd_a``) and ``H`` the mass matrix over the actuated coordinates with the reflected
rotor inertia. With ``k = min(3, n_a)`` the directions the handle moves are the ``k`` left singular vectors
``U`` of ``J_v`` (a planar device's plane), ``sigma_1 >= ... >= sigma_k`` its singular values, and the handle's
Cartesian mass on them ``Lambda = (U^T J_v H^-1 J_v^T U)^-1`` (k x k; ``(J_v H^-1 J_v^T)^+`` in that basis).

======================  ==================================================  =========  ===========================
index                   formula                                             unit       source
======================  ==================================================  =========  ===========================
``isotropy``            ``sigma_k / sigma_1``                               1          seed 001 eq. 4.40 (inverse)
``condition``           ``sigma_1 / sigma_k``                               1          seed 001 eq. 4.39-4.40
``manipulability``      ``sigma_1 ... sigma_k`` (``sqrt det(U^T J_v J_v^T U)``)  m^k/rad^k  seed 001 eq. 4.36
``apparent_mass``       largest eigenvalue of ``Lambda``                    kg         Khatib (1987)
``inertia_uniformity``  smallest / largest eigenvalue of ``Lambda``         1          seed 001 eq. 4.99 (inverse)
``force``               the force polytope's inscribed radius               N          :mod:`.force`
``stiffness``           smallest eigenvalue of ``K = U^T K_C[:3, :3] U``    N/m        seed 001 eq. 5.117-5.123
``frequency``           ``sqrt`` of the smallest eigenvalue of (K, Lambda)  rad/s      seed 001 eq. 4.100-4.107
``ln``                  the Linearity Number over the joint region          LN         seed 000 eq. 3.1-3.4
``mass``                the mass of the bodies the coordinates move         kg         the device's bodies
======================  ==================================================  =========  ===========================

``force`` takes ``torque`` (``continuous``, default, or ``peak``): the motors' torque limits, one motor per actuated
coordinate. ``stiffness`` and ``frequency`` need links with sections (``K_C`` of the virtual joint method at the
handle, :func:`~hapticdesign.analysis.stiffness.device.cartesian_stiffness_at`; ``K_C[:3, :3]`` holds the
rotations, seed 001's ``K_CA``). ``ln`` and ``mass`` are one value per design (the same at every point); ``ln``
takes the region of the joint limits (full turns where none) and unit weights (:func:`~..linearity.form.device_form`).
``kmax`` (the stable wall stiffness) needs the simulation layer: :mod:`hapticdesign.simulation.design_indices`.

``m^k/rad^k``: metres per radian for revolute coordinates (m/m for prismatic ones). Reductions over the
workspace points: ``min``, ``max``, ``mean`` (:data:`REDUCTIONS`; ``isotropy`` with ``mean`` over a uniform
Cartesian grid is the global conditioning index of Gosselin & Angeles (1991), with the grid's points as the
measure).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from hapticdesign.analysis import kinematics
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics.device import mass_matrix_at
from hapticdesign.analysis.linearity.form import device_form
from hapticdesign.analysis.metrics import force
from hapticdesign.analysis.metrics.dynamic import modes
from hapticdesign.analysis.stiffness.device import cartesian_stiffness_at
from hapticdesign.analysis.workspace import reach_workspace
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device


@dataclass
class HandleStates:
    """The handle's kinematics and dynamics at closed full poses ``full`` (P, N) of ``device``; each quantity is
    computed once, when an index first asks for it."""

    device: Device | None
    full: np.ndarray
    frame: str | None = None

    @cached_property
    def jacobian(self) -> np.ndarray:
        """``J_v`` (P, 3, n_a)."""
        return handle_jacobians(self.device, self.full, self.frame)

    @cached_property
    def svd(self) -> tuple[np.ndarray, np.ndarray]:
        """``U`` (P, 3, k) and the singular values (P, k) of ``J_v``, largest first."""
        u, s, _ = np.linalg.svd(self.jacobian)
        k = s.shape[-1]
        return u[:, :, :k], s

    @cached_property
    def mass(self) -> np.ndarray:
        """``H`` (P, n_a, n_a) with the reflected rotor inertia."""
        return mass_matrix_at(self.device, self.full)

    @cached_property
    def damping(self) -> np.ndarray:
        """``B`` (n_a, n_a): the joints' and motors' viscous damping
        (:attr:`~hapticdesign.model.device.Device.damping_matrix`)."""
        return self.device.damping_matrix

    @cached_property
    def name(self) -> str:
        """The device's name (for messages)."""
        return self.device.name

    @cached_property
    def motor_map(self) -> np.ndarray | None:
        """The motors' ``A^-1`` (n_a, n_a), or (P, n_a, n_a) per pose; None unless one motor per coordinate
        (:func:`~hapticdesign.analysis.metrics.force.motor_map`)."""
        return force.motor_map(self.device)

    @cached_property
    def torque_limits(self) -> dict[str, np.ndarray | None]:
        """``n_k tau_k`` (n_a,), or (P, n_a) per pose, for ``continuous`` and ``peak`` torques; None where a motor
        lacks it (:func:`~hapticdesign.analysis.metrics.force.torque_limits`)."""
        return {which: force.torque_limits(self.device, which) for which in ("continuous", "peak")}

    @cached_property
    def moving_mass(self) -> np.ndarray:
        """The mass the coordinates move (:func:`moving_mass`) at each pose (P,)."""
        return np.full(len(self.full), moving_mass(self.device))

    @cached_property
    def mobility(self) -> np.ndarray:
        """``U^T J_v H^-1 J_v^T U`` (P, k, k), the inverse of ``Lambda`` (1/kg)."""
        u, _ = self.svd
        jv = self.jacobian
        return np.swapaxes(u, 1, 2) @ jv @ np.linalg.solve(self.mass, np.swapaxes(jv, 1, 2)) @ u

    @cached_property
    def cartesian_mass(self) -> np.ndarray:
        """Eigenvalues (P, k) of ``Lambda`` (kg), ascending."""
        return 1.0 / np.linalg.eigvalsh(self.mobility)[:, ::-1]

    @cached_property
    def cartesian_mass_matrix(self) -> np.ndarray:
        """``Lambda`` (P, k, k) in kg."""
        return np.linalg.inv(self.mobility)

    @cached_property
    def stiffness(self) -> np.ndarray:
        """``U^T K_C[:3, :3] U`` (P, k, k) in N/m: the VJM's translational stiffness on the directions the handle
        moves (:func:`~hapticdesign.analysis.stiffness.device.cartesian_stiffness_at`)."""
        u, _ = self.svd
        k = np.array([cartesian_stiffness_at(self.device, q, self.frame)[:3, :3] for q in self.full])
        return np.swapaxes(u, 1, 2) @ k @ u


    @classmethod
    def of(cls, jacobian: np.ndarray, mass: np.ndarray, **known) -> "HandleStates":
        """The states of poses whose ``J_v`` (P, 3, n_a) and ``H`` (P, n_a, n_a) are known already (many designs'
        poses at once, :mod:`hapticdesign.analysis.design_batch`), with any other quantity known per pose by its
        name (``damping`` (P, n_a, n_a), ``stiffness`` (P, k, k), ``motor_map``, ``torque_limits``, ``moving_mass``,
        ``name``): enough for the indices those quantities give."""
        states = cls(None, np.zeros((len(jacobian), 0)))
        unknown = set(known) - {"damping", "stiffness", "motor_map", "torque_limits", "moving_mass", "name"}
        if unknown:
            raise TypeError(f"HandleStates.of: unknown quantities {sorted(unknown)}")
        states.__dict__.update(jacobian=jacobian, mass=mass, **known)
        return states


def handle_jacobians(device: Device, full: np.ndarray, frame: str | None = None) -> np.ndarray:
    """``J_v T`` (P, 3, n_a): the handle's (or ``frame``'s) translational Jacobian over the actuated coordinates at
    closed full poses (P, N)."""
    space = configuration_of(device)
    full = np.atleast_2d(np.asarray(full, dtype=float))
    _, jac = kinematics.poses_and_jacobians(space.mechanism, full, frame)
    return jac[:, :3] @ space.velocity_transform(full)


@dataclass(frozen=True)
class Index:
    """A design index: its name, unit, formula, source, its values at the poses of :class:`HandleStates` for the
    request's options, and the options it takes with their defaults."""

    name: str
    unit: str
    formula: str
    source: str
    values: Callable[[HandleStates, Mapping[str, object]], np.ndarray]
    options: Mapping[str, object] = field(default_factory=dict)


@dataclass(frozen=True)
class Request:
    """An index asked for, with options (``kmax``'s sample period, ...); its values are keyed by ``key``."""

    index: str
    options: Mapping[str, object] = field(default_factory=dict)
    label: str | None = None

    @property
    def key(self) -> str:
        return self.label or self.index


def _isotropy(h: HandleStates, options) -> np.ndarray:
    s = h.svd[1]
    return s[:, -1] / s[:, 0]


def _condition(h: HandleStates, options) -> np.ndarray:
    s = h.svd[1]
    return s[:, 0] / s[:, -1]


def _manipulability(h: HandleStates, options) -> np.ndarray:
    return np.prod(h.svd[1], axis=1)


def _apparent_mass(h: HandleStates, options) -> np.ndarray:
    return h.cartesian_mass.max(axis=1)


def _inertia_uniformity(h: HandleStates, options) -> np.ndarray:
    m = h.cartesian_mass
    return m.min(axis=1) / m.max(axis=1)


def _force(h: HandleStates, options) -> np.ndarray:
    which = options["torque"]
    if which not in ("continuous", "peak"):
        raise UserError(f"index force: torque is continuous or peak, got {which!r}")
    inverse, limits = h.motor_map, h.torque_limits[str(which)]
    if inverse is None or limits is None:
        raise UserError(f"index force needs one motor per actuated coordinate, each with torque_{which} (device "
                        f"{h.name})")
    return force.inscribed_force(h.jacobian, h.svd[0], inverse, limits)


def _stiffness(h: HandleStates, options) -> np.ndarray:
    return np.linalg.eigvalsh(h.stiffness)[:, 0]


def _frequency(h: HandleStates, options) -> np.ndarray:
    return np.array([modes(m, k).frequencies[0] for m, k in zip(h.cartesian_mass_matrix, h.stiffness)])


def _ln(h: HandleStates, options) -> np.ndarray:
    value = float(device_form(h.device).ln(h.device.standard_parameters()))
    return np.full(len(h.full), value)


def _mass(h: HandleStates, options) -> np.ndarray:
    return h.moving_mass


def moving_mass(device: Device) -> float:
    """The mass (kg) of the bodies some coordinate moves (those fixed to the base's frames do not count)."""
    compiled = device.mechanism.compiled
    moving = [bool(np.any(compiled.body_path[b] >= 0)) for b in range(len(device.body_names))]
    return float(sum(device.body(name).m for name, moves in zip(device.body_names, moving) if moves))


INDICES: dict[str, Index] = {index.name: index for index in (
    Index("isotropy", "1", "sigma_min(J_v) / sigma_max(J_v)", "seed 001 eq. 4.40 (inverse of the condition number)",
          _isotropy),
    Index("condition", "1", "sigma_max(J_v) / sigma_min(J_v)", "seed 001 eq. 4.39-4.40", _condition),
    Index("manipulability", "m^k/rad^k", "sqrt(det(U^T J_v J_v^T U))", "seed 001 eq. 4.36 (Yoshikawa 1985)",
          _manipulability),
    Index("apparent_mass", "kg", "largest eigenvalue of Lambda = (J_v H^-1 J_v^T)^+", "Khatib (1987); seed 001 §4.3",
          _apparent_mass),
    Index("inertia_uniformity", "1", "smallest / largest eigenvalue of Lambda",
          "inverse of seed 001 eq. 4.99 (I_e)", _inertia_uniformity),
    Index("force", "N", "min_k n_k tau_k / |(A^-T J_v^T U)_k|: the force polytope's inscribed radius",
          "force polytope (Chiacchio et al. 1997); hapticdesign.analysis.metrics.force", _force,
          {"torque": "continuous"}),
    Index("stiffness", "N/m", "smallest eigenvalue of U^T K_C[:3, :3] U (VJM)", "seed 001 eq. 5.117-5.123 (K_CA)",
          _stiffness),
    Index("frequency", "rad/s", "sqrt of the smallest eigenvalue of K v = w^2 Lambda v (U^T K_C[:3, :3] U, Lambda)",
          "seed 001 eq. 4.100-4.107, 7.11-7.13", _frequency),
    Index("ln", "LN", "Linearity Number over the joint region (limits, else full turns)",
          "seed 000 eq. 3.1-3.4", _ln),
    Index("mass", "kg", "sum of the masses of the bodies the coordinates move", "the device file's bodies", _mass),
)}
"""The registry of the analysis layer: index name -> :class:`Index` (``kmax`` needs the simulation layer:
:mod:`hapticdesign.simulation.design_indices` holds the whole registry)."""

PER_DESIGN = ("ln",)
"""The indices of a whole device (its exact dynamics), not of quantities :meth:`HandleStates.of` takes: the
batched design kernels do not give them."""

REDUCTIONS: dict[str, Callable[[np.ndarray], float]] = {
    "min": lambda v: float(np.min(v)),
    "max": lambda v: float(np.max(v)),
    "mean": lambda v: float(np.mean(v)),
}
"""Reductions of an index over the workspace points (the mean weighs each grid point alike)."""


class Evaluation(NamedTuple):
    """Values per request key per point (P,), or ``reason`` (one line) when the design fails (``values`` empty)."""

    values: dict[str, np.ndarray]
    reason: str | None = None


def requests_of(requests: Iterable[str | Request], registry: Mapping[str, Index] = INDICES) -> list[Request]:
    """The requests (index names or :class:`Request`), each of a registered index with known options; an unknown
    index or option raises a one-line UserError."""
    out = []
    for request in requests:
        request = Request(request) if isinstance(request, str) else request
        if request.index not in registry:
            raise UserError(f"unknown index {request.index!r} (indices: {', '.join(registry)})")
        known = registry[request.index].options
        unknown = [k for k in request.options if k not in known]
        if unknown:
            raise UserError(f"index {request.index}: unknown option {unknown[0]!r} (options: "
                            f"{', '.join(known) or 'none'})")
        out.append(request)
    keys = [r.key for r in out]
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise UserError(f"index {twice[0]} is asked twice (give each request its own label)")
    return out


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
    """The checked ``requests`` at closed full poses (P, N); an index the design cannot give raises UserError."""
    states = HandleStates(device, np.atleast_2d(full), frame)
    values = {}
    for request in requests:
        index = registry[request.index]
        values[request.key] = np.asarray(index.values(states, {**index.options, **request.options}), dtype=float)
    return Evaluation(values)


def reduce(values: np.ndarray, how: str) -> float:
    """An index over the workspace points reduced by ``min``, ``max`` or ``mean``."""
    if how not in REDUCTIONS:
        raise UserError(f"unknown reduction {how!r} (use {', '.join(REDUCTIONS)})")
    return REDUCTIONS[how](values)
