"""The design states an index is a function of, built one of three ways (docs/indices.md):

- :class:`HandleStates` of a device at closed full poses (one design, its workspace points);
- :meth:`HandleStates.of`: the handle Jacobians, mass matrices, damping, sections' stiffness, motors and moving
  masses of many designs' poses at once, from the compiled kernels (:mod:`hapticdesign.analysis.design_batch`),
  without a device;
- :class:`ParameterStates`: the parameters of many designs alone (no pose reached).

At a pose, ``J_v`` is the handle's translational Jacobian over the actuated coordinates (3 x n_a, base frame; ``J T``
with loops, ``qd = T qd_a``) and ``H`` the mass matrix over the actuated coordinates with the reflected rotor inertia.
With ``k = min(3, n_a)`` the directions the handle moves are the ``k`` left singular vectors ``U`` of ``J_v`` (a
planar device's plane), and the handle's Cartesian mass on them is ``Lambda = (U^T J_v H^-1 J_v^T U)^-1`` (k x k;
``(J_v H^-1 J_v^T)^+`` in that basis). Each quantity is computed once, when an index first asks for it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from hapticdesign.analysis import kinematics
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics import cartesian
from hapticdesign.analysis.dynamics.cartesian import cartesian_inertia, mobility
from hapticdesign.analysis.dynamics.device import gravity_gradient_at, mass_matrix_at
from hapticdesign.analysis.metrics import force
from hapticdesign.analysis.metrics.kinematic import handle_range_basis
from hapticdesign.analysis.stiffness.device import cartesian_stiffness_at
from hapticdesign.analysis.stiffness.drive import device_drive, elastic
from hapticdesign.errors import UserError
from hapticdesign.model.dense import symmetric_eigenvalues
from hapticdesign.model.actuators import Transmission
from hapticdesign.model.compensator_model import model_device
from hapticdesign.model.device import Device

BATCH_NEEDS = frozenset({"kinematics", "dynamics", "damping", "sections", "motors", "bodies", "gravity",
                         "compliance"})
"""What :meth:`HandleStates.of` gives of many designs' poses: ``J_v`` and ``q`` (kinematics), ``H`` (dynamics),
``B`` (damping), the links' sections (``stiffness``, ``U^T K_C[:3, :3] U``), the motors (``motor_map``,
``torque_limits``), the bodies (``moving_mass``), gravity's gradient (``gravity``) and the compliance between the
motors and the handle (``drive``: the transmissions' and, when the file's links carry sections, the links')."""
POSE_NEEDS = BATCH_NEEDS | {"device"}
"""What a device at poses gives an index: all of :data:`BATCH_NEEDS`, and the ``device`` itself (an index of the
whole device, such as its exact Linearity Number, is evaluated design by design)."""
PARAMETER_NEEDS = frozenset({"parameters"})
"""What :class:`ParameterStates` gives: the device parameters alone."""


@dataclass
class HandleStates:
    """The handle's kinematics and dynamics at closed full poses ``full`` (P, N) of ``device`` (see the module)."""

    device: Device | None
    full: np.ndarray
    frame: str | None = None

    @cached_property
    def J_v(self) -> np.ndarray:
        """``J_v`` (P, 3, n_a)."""
        return handle_jacobians(self._device, self.full, self.frame)

    @cached_property
    def q(self) -> np.ndarray:
        """The actuated coordinates (P, n_a)."""
        return self.full[:, configuration_of(self._device).actuated_index()]

    @cached_property
    def svd(self) -> tuple[np.ndarray, np.ndarray]:
        """``U`` (P, 3, k) and the singular values (P, k) of ``J_v``, largest first
        (:func:`~hapticdesign.analysis.metrics.kinematic.handle_range_basis`)."""
        return self._range[:2]

    @cached_property
    def J_u(self) -> np.ndarray:
        """``U^T J_v`` (P, k, n_a): the Jacobian on the directions the handle moves."""
        return self._range[2]

    @cached_property
    def _range(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return handle_range_basis(self.J_v)

    @cached_property
    def task(self) -> np.ndarray:
        """The task Jacobian ``J_m`` (P, n_a, n_a) of seed 001 ch. 4, square, as many rows as actuated coordinates:
        ``J_v`` (base axes) for 3, ``U^T J_v`` (the plane or line the handle moves in, which leaves every metric
        unchanged by the choice of axes) for 1 or 2, and the handle's twist (``J_v`` over the angular rows) for 6."""
        n_a = self.J_v.shape[-1]
        if n_a == 3:
            return self.J_v
        if n_a < 3:
            return self.J_u
        if n_a == 6:
            return np.concatenate([self.J_v, handle_jacobians(self._device, self.full, self.frame, rows=(3, 6))], 1)
        raise UserError(f"the task Jacobian is square for 1-3 or 6 actuated coordinates; {self.name} has {n_a}")

    @cached_property
    def task_inertia(self) -> np.ndarray:
        """``M_C = J_m^-T H J_m^-1`` (P, n_a, n_a) of the :attr:`task` Jacobian (seed 001 eq. 4.90), kg for
        translational rows."""
        return cartesian_inertia(self.H, self.task)

    @cached_property
    def H(self) -> np.ndarray:
        """``H`` (P, n_a, n_a) with the reflected rotor inertia."""
        return mass_matrix_at(self._device, self.full)

    @cached_property
    def count(self) -> int:
        """How many poses the states hold (P): the leading axis of every per-pose field, and how many values a pose
        index returns."""
        return len(self.full)

    @cached_property
    def designs(self) -> int:
        """How many designs the poses belong to (D, 1 for a device at poses): the poses are the designs' one after the
        other, ``P / D`` points each, and an index ``over="points"`` returns one value per design."""
        return 1

    @cached_property
    def B(self) -> np.ndarray:
        """``B`` (P, n_a, n_a): the joints' and motors' viscous damping at each pose
        (:attr:`~hapticdesign.model.device.Device.damping_matrix`)."""
        return per_pose(self._device.damping_matrix, self.count, 2)

    @cached_property
    def transmission(self) -> Transmission | None:
        """The motors' compliant transmissions (:class:`~hapticdesign.model.actuators.Transmission`, (P, n_a, n_a)
        each), None for rigid motors (:attr:`~hapticdesign.model.device.Device.transmission`)."""
        found = self._device.transmission
        return None if found is None else Transmission(*(per_pose(x, self.count, 2) for x in found))

    @cached_property
    def drive(self) -> Transmission | None:
        """The compliance between the motors and the handle at each pose (:class:`~hapticdesign.model.actuators.
        Transmission`, (P, n_a, n_a) each): the transmissions' and, where the device file gives elastic links, the
        links' in series (:func:`~hapticdesign.analysis.stiffness.drive.device_drive`); None when both are rigid."""
        device = self._device
        found = device_drive(device, self.full, self.J_v, self.frame,
                             self.cartesian_stiffness if elastic(device) else None)
        return None if found is None else Transmission(*(per_pose(x, self.count, 2) for x in found))

    @cached_property
    def gravity(self) -> np.ndarray:
        """``dG/dq`` (P, n_a, n_a): the stiffness gravity adds to the linearized plant at each pose
        (:func:`~hapticdesign.analysis.dynamics.device.gravity_gradient_at`)."""
        return gravity_gradient_at(self._device, self.full)

    def compensator(self, error_percent: float) -> tuple[np.ndarray, np.ndarray]:
        """The compensator's ``H_m`` and ``dG_m/dq`` (P, n_a, n_a each) at the poses, its model carrying a modelling
        error of ``error_percent`` (:func:`~hapticdesign.model.compensator_model.model_device`: masses, mass centres
        and inertias alike, the motors' rotors exact)."""
        key = float(error_percent)
        models = self.__dict__.setdefault("_models", {})
        if key not in models:
            if "model" in self.__dict__:
                models[key] = self.__dict__["model"](key)
            else:
                device = model_device(self._device, key)
                models[key] = mass_matrix_at(device, self.full), gravity_gradient_at(device, self.full)
        return models[key]

    @cached_property
    def name(self) -> str:
        """The device's name (for messages)."""
        return self._device.name

    @cached_property
    def motor_map(self) -> np.ndarray | None:
        """The motors' ``A^-1`` (P, n_a, n_a) at each pose (coordinates x motors); None unless one motor per
        coordinate (:func:`~hapticdesign.analysis.metrics.force.motor_map`)."""
        found = force.motor_map(self._device)
        return None if found is None else per_pose(found, self.count, 2)

    @cached_property
    def torque_limits(self) -> dict[str, np.ndarray | None]:
        """``n_k tau_k`` (P, n_a) at each pose (N m or N on the coordinates' side) for ``continuous`` and ``peak``
        torques; None where a motor lacks it (:func:`~hapticdesign.analysis.metrics.force.torque_limits`)."""
        found = {which: force.torque_limits(self._device, which) for which in ("continuous", "peak")}
        return {which: None if x is None else per_pose(x, self.count, 1) for which, x in found.items()}

    @cached_property
    def moving_mass(self) -> np.ndarray:
        """The mass (kg) the coordinates move (:func:`moving_mass`) at each pose (P,)."""
        return np.full(len(self.full), moving_mass(self._device))

    @cached_property
    def mobility(self) -> np.ndarray:
        """``U^T J_v H^-1 J_v^T U`` (P, k, k), the inverse of ``Lambda`` (1/kg)."""
        return mobility(self.H, self.J_u)

    @cached_property
    def cartesian_mass(self) -> np.ndarray:
        """Eigenvalues (P, k) of ``Lambda`` (kg), ascending."""
        return 1.0 / symmetric_eigenvalues(self.mobility)[:, ::-1]

    @cached_property
    def cartesian_mass_matrix(self) -> np.ndarray:
        """``Lambda`` (P, k, k) in kg."""
        return np.linalg.inv(self.mobility)

    @cached_property
    def cartesian_damping(self) -> np.ndarray:
        """``U^T J_v^+T B J_v^+ U`` (P, k, k) in N s/m: the joints' and motors' damping felt at the handle."""
        return cartesian.damping(self.J_v, self.svd[0], self.B)

    @cached_property
    def cartesian_stiffness(self) -> np.ndarray:
        """The VJM's ``K_C`` (P, 6, 6) at the handle
        (:func:`~hapticdesign.analysis.stiffness.device.cartesian_stiffness_at`)."""
        return np.array([cartesian_stiffness_at(self._device, q, self.frame) for q in self.full])

    @cached_property
    def stiffness(self) -> np.ndarray:
        """``U^T K_C[:3, :3] U`` (P, k, k) in N/m: the VJM's translational stiffness on the directions the handle
        moves."""
        u, _ = self.svd
        return np.swapaxes(u, 1, 2) @ self.cartesian_stiffness[:, :3, :3] @ u

    @property
    def _device(self) -> Device:
        if self.device is None:
            raise UserError("this index needs the device itself (bodies, sections or motors), which the states of "
                            "many designs' poses do not carry: declare what it needs")
        return self.device

    @classmethod
    def of(cls, J_v: np.ndarray, H: np.ndarray, B: np.ndarray | None = None, q: np.ndarray | None = None,
           designs: int = 1, **known) -> "HandleStates":
        """The states of poses whose ``J_v`` (P, 3, n_a), ``H`` (P, n_a, n_a), ``B`` ((n_a, n_a) or per pose) and
        actuated coordinates ``q`` (P, n_a) are known already (many designs' poses at once,
        :mod:`hapticdesign.analysis.design_batch`), with any other quantity of :data:`BATCH_NEEDS` known per pose by
        its name (``stiffness`` (P, k, k), ``motor_map``, ``torque_limits``, ``moving_mass``, ``name``, ``gravity``
        (P, n_a, n_a), ``model``: the compensator's ``H_m`` and ``dG_m/dq`` for a modelling error in percent, as
        :meth:`compensator` gives them, ``transmission``: the motors' compliant transmissions, None when rigid,
        ``drive``: the compliance between the motors and the handle, the transmissions' unless given): enough for an
        index that needs at most :data:`BATCH_NEEDS`, of those quantities given. ``designs``: how many designs the
        poses belong to, one after the other. One design's ``B``, ``motor_map``, ``torque_limits``, ``transmission``
        or ``drive`` (without the leading axis) is taken at every pose,
        so that every field has the leading axis P (the class's docstrings give each shape)."""
        unknown = set(known) - {"stiffness", "motor_map", "torque_limits", "moving_mass", "name", "gravity", "model",
                                "transmission", "drive"}
        if unknown:
            raise TypeError(f"HandleStates.of: unknown quantities {sorted(unknown)}")
        count = len(J_v)
        if "motor_map" in known and known["motor_map"] is not None:
            known["motor_map"] = per_pose(known["motor_map"], count, 2)
        if "torque_limits" in known:
            known["torque_limits"] = {k: None if x is None else per_pose(x, count, 1)
                                      for k, x in known["torque_limits"].items()}
        for name in ("transmission", "drive"):
            if known.get(name) is not None:
                known[name] = Transmission(*(per_pose(x, count, 2) for x in known[name]))
        known.setdefault("drive", known.get("transmission"))
        states = cls(None, np.zeros((count, 0)))
        states.__dict__.update(J_v=J_v, H=H, designs=int(designs), **{"transmission": None, "drive": None, **known})
        for name, value in (("B", None if B is None else per_pose(B, count, 2)), ("q", q)):
            if value is not None:
                states.__dict__[name] = value
        return states


@dataclass
class ParameterStates:
    """The device parameters of many designs (name -> (D,) values, one per design) and a ``cache`` the indices of
    one evaluation share (a closed form of the parameters that several indices read is computed once)."""

    params: Mapping[str, np.ndarray]
    cache: dict = field(default_factory=dict)

    @property
    def count(self) -> int:
        """How many designs the parameters are of (D): how many values an index of the parameters returns."""
        return len(next(iter(self.params.values()), ()))

    @classmethod
    def of_device(cls, device: Device) -> "ParameterStates":
        """The one design ``device`` (its parameters as 1-element arrays)."""
        return cls({name: np.array([float(value)]) for name, value in device.params.items()})


def per_pose(value: np.ndarray, count: int, dims: int) -> np.ndarray:
    """``value`` with the leading axis of ``count`` poses: one design's (``dims`` axes) taken at every pose, or
    values per pose (``dims + 1`` axes, ``count`` first) as they are."""
    value = np.asarray(value, dtype=float)
    if value.ndim == dims:
        return np.repeat(value[None], count, axis=0)
    if value.ndim != dims + 1 or len(value) != count:
        raise ValueError(f"a per-pose quantity is ({count}, ...) with {dims} more axes, got shape {value.shape}")
    return value


def moving_mass(device: Device) -> float:
    """The mass (kg) of the bodies some coordinate moves (those fixed to the base's frames do not count)."""
    compiled = device.mechanism.compiled
    moving = [bool(np.any(compiled.body_path[b] >= 0)) for b in range(len(device.body_names))]
    return float(sum(device.body(name).m for name, moves in zip(device.body_names, moving) if moves))


def handle_jacobians(device: Device, full: np.ndarray, frame: str | None = None,
                     rows: tuple[int, int] = (0, 3)) -> np.ndarray:
    """``J_v T`` (P, 3, n_a): the handle's (or ``frame``'s) translational Jacobian over the actuated coordinates at
    closed full poses (P, N); ``rows`` (3, 6) gives the angular rows, (0, 6) the twist's."""
    space = configuration_of(device)
    full = np.atleast_2d(np.asarray(full, dtype=float))
    _, jac = kinematics.poses_and_jacobians(space.mechanism, full, frame)
    return jac[:, rows[0]:rows[1]] @ space.velocity_transform(full)
