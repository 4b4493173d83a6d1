"""The built-in design indices, registered with :func:`~.registry.index` as a user's would be (docs/indices.md).

With ``U``, ``sigma_1 >= ... >= sigma_k`` and ``Lambda`` of :mod:`.states`:

======================  ==================================================  =========  ===========================
index                   formula                                             unit       source
======================  ==================================================  =========  ===========================
``isotropy``            ``sigma_k / sigma_1``                               1          seed 001 eq. 4.40 (inverse)
``condition``           ``sigma_1 / sigma_k``                               1          seed 001 eq. 4.39-4.40
``manipulability``      ``sigma_1 ... sigma_k`` (``sqrt det(U^T J_v J_v^T U)``)  m^k/rad^k  seed 001 eq. 4.36
``apparent_mass``       largest eigenvalue of ``Lambda``                    kg         Khatib (1987)
``inertia_uniformity``  smallest / largest eigenvalue of ``Lambda``         1          seed 001 eq. 4.99 (inverse)
``I_m``                 ``det M_C`` of the task Jacobian ``J_m``            kg^k       seed 001 eq. 4.92-4.93
``I_d``                 ``|det J_m| / det H``                               1/(kg m)^k seed 001 eq. 4.97
``I_f``                 ``||M_C||_F``                                       kg         seed 001 eq. 4.98
``I_e``                 ``||M_C|| ||M_C^-1||``                              1          seed 001 eq. 4.99
``acceleration_radius`` smallest singular value of ``J_m H^-1``             1/(kg m)   seed 001 eq. 4.96
``force``               the force polytope's inscribed radius               N          :mod:`..force`
``stiffness``           smallest eigenvalue of ``K = U^T K_C[:3, :3] U``    N/m        seed 001 eq. 5.117-5.123
``frequency``           ``sqrt`` of the smallest eigenvalue of (K, Lambda)  rad/s      seed 001 eq. 4.100-4.107
``kmax``                the exact stable wall stiffness                     N/m        seed 000 ch. 4-5
``ln``                  the Linearity Number over the joint region          LN         seed 000 eq. 3.1-3.4
``mass``                the mass of the bodies the coordinates move         kg         the device's bodies
======================  ==================================================  =========  ===========================

``condition`` and ``manipulability`` take ``jacobian``: ``handle`` (default, ``J_v``) or ``task``, the square task
Jacobian ``J_m`` of seed 001 ch. 4 (:attr:`.states.HandleStates.task`: the handle's twist for six coordinates), on
which ``I_m`` ... ``acceleration_radius`` are, with ``M_C = J_m^-T H J_m^-1``. ``force`` takes ``torque``
(``continuous``, default, or ``peak``): the motors' torque limits, one motor per actuated coordinate. ``stiffness``
and ``frequency`` need links with sections (``K_C`` of the virtual joint method at the handle,
:func:`~hapticdesign.analysis.stiffness.device.cartesian_stiffness_at`; ``K_C[:3, :3]`` holds the rotations,
seed 001's ``K_CA``). ``kmax`` is :func:`hapticdesign.analysis.wall_stiffness.kmax`: the n-joint sampled
loop about the pose, every joint free, gravity's gradient in it, discretized exactly (its options: the loop's settings of
:data:`~hapticdesign.analysis.wall_stiffness.KMAX_OPTIONS`, practice's by default, ``direction`` and ``hand``).
``ln`` and ``mass`` are one value per design (the same at every point); ``ln`` takes the region of the joint limits (full turns where none) and
unit weights (:func:`~hapticdesign.analysis.linearity.form.device_form`). ``m^k/rad^k``: metres per radian for
revolute coordinates (m/m for prismatic ones).
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.linearity.form import device_form
from hapticdesign.analysis.metrics import force as polytope
from hapticdesign.analysis.metrics import dynamic, kinematic
from hapticdesign.analysis.metrics.dynamic import modes
from hapticdesign.analysis.metrics.indices.registry import index
from hapticdesign.analysis.metrics.indices.states import HandleStates
from hapticdesign.analysis.wall_stiffness import kmax as wall_kmax
from hapticdesign.errors import UserError
from hapticdesign.model.dense import symmetric_eigenvalues


@index(unit="1", formula="sigma_min(J_v) / sigma_max(J_v)",
       source="seed 001 eq. 4.40 (inverse of the condition number)", needs=("kinematics",))
def isotropy(pose: HandleStates) -> np.ndarray:
    return 1.0 / kinematic.condition_of_singular_values(pose.svd[1])


@index(unit="1", formula="sigma_max(J_v) / sigma_min(J_v)", source="seed 001 eq. 4.39-4.40", needs=("kinematics",))
def condition(pose: HandleStates, jacobian: str = "handle") -> np.ndarray:
    if _jacobian(jacobian) == "task":
        return kinematic.condition_number(pose.task)
    return kinematic.condition_of_singular_values(pose.svd[1])


@index(unit="m^k/rad^k", formula="sqrt(det(U^T J_v J_v^T U))", source="seed 001 eq. 4.36 (Yoshikawa 1985)",
       needs=("kinematics",))
def manipulability(pose: HandleStates, jacobian: str = "handle") -> np.ndarray:
    if _jacobian(jacobian) == "task":
        return kinematic.manipulability(pose.task)
    return kinematic.manipulability(pose.J_u)


def _jacobian(which: str) -> str:
    if which not in ("handle", "task"):
        raise UserError(f"the jacobian of an index is handle or task, got {which!r}")
    return which


@index(unit="kg", formula="largest eigenvalue of Lambda = (J_v H^-1 J_v^T)^+", source="Khatib (1987); seed 001 §4.3")
def apparent_mass(pose: HandleStates) -> np.ndarray:
    return pose.cartesian_mass.max(axis=1)


@index(unit="1", formula="smallest / largest eigenvalue of Lambda", source="inverse of seed 001 eq. 4.99 (I_e)")
def inertia_uniformity(pose: HandleStates) -> np.ndarray:
    m = pose.cartesian_mass
    return m.min(axis=1) / m.max(axis=1)


@index(unit="kg^k", formula="det M_C, M_C = J_m^-T H J_m^-1 (task Jacobian J_m)", source="seed 001 eq. 4.92-4.93")
def I_m(pose: HandleStates) -> np.ndarray:
    return dynamic.inertia_volume(pose.task_inertia)


@index(unit="1/(kg^k m^k)", formula="|det J_m| / det H (task Jacobian J_m)", source="seed 001 eq. 4.97")
def I_d(pose: HandleStates) -> np.ndarray:
    return dynamic.dynamic_manipulability(pose.H, pose.task)


@index(unit="kg", formula="||M_C||_F (task Jacobian J_m)", source="seed 001 eq. 4.98")
def I_f(pose: HandleStates) -> np.ndarray:
    return dynamic.inertia_frobenius(pose.task_inertia)


@index(unit="1", formula="||M_C|| ||M_C^-1|| (task Jacobian J_m)", source="seed 001 eq. 4.99")
def I_e(pose: HandleStates) -> np.ndarray:
    return dynamic.inertia_uniformity(pose.task_inertia)


@index(unit="1/(kg m)", formula="smallest singular value of J_m H^-1 (task Jacobian J_m)",
       source="seed 001 eq. 4.96 (Graettinger and Krogh)")
def acceleration_radius(pose: HandleStates) -> np.ndarray:
    return dynamic.acceleration_radius(pose.H, pose.task)


@index(unit="N", formula="min_k n_k tau_k / |(A^-T J_v^T U)_k|: the force polytope's inscribed radius",
       source="force polytope (Chiacchio et al. 1997); hapticdesign.analysis.metrics.force",
       needs=("kinematics", "motors"))
def force(pose: HandleStates, torque: str = "continuous") -> np.ndarray:
    if torque not in ("continuous", "peak"):
        raise UserError(f"index force: torque is continuous or peak, got {torque!r}")
    inverse, limits = pose.motor_map, pose.torque_limits[str(torque)]
    if inverse is None or limits is None:
        raise UserError(f"index force needs one motor per actuated coordinate, each with torque_{torque} (device "
                        f"{pose.name})")
    return polytope.inscribed_force(pose.J_v, pose.svd[0], inverse, limits)


@index(unit="N/m", formula="smallest eigenvalue of U^T K_C[:3, :3] U (VJM)", source="seed 001 eq. 5.117-5.123 (K_CA)",
       needs=("kinematics", "sections"))
def stiffness(pose: HandleStates) -> np.ndarray:
    return symmetric_eigenvalues(pose.stiffness)[:, 0]


@index(unit="rad/s", formula="sqrt of the smallest eigenvalue of K v = w^2 Lambda v (U^T K_C[:3, :3] U, Lambda)",
       source="seed 001 eq. 4.100-4.107, 7.11-7.13", needs=("kinematics", "dynamics", "sections"))
def frequency(pose: HandleStates) -> np.ndarray:
    return np.array([modes(m, k).frequencies[0] for m, k in zip(pose.cartesian_mass_matrix, pose.stiffness)])


@index(unit="N/m", formula="exact stable wall stiffness of the sampled loop along a direction (or the worst)",
       source="seed 000 ch. 4-5; hapticdesign.analysis.sampled_loop.handle_limits",
       needs=("kinematics", "dynamics", "damping", "gravity", "compliance"), renamed={"damping": "wall_damping"})
def kmax(pose: HandleStates, period: float = 0.001, delay: int = 1, wall_damping: float = 0.0,
         direction: list[float] | None = None, velocity: str = "difference", compensation: str = "gravity",
         error_percent: float = 0.0, hand: object = None) -> np.ndarray:
    options = dict(period=period, delay=delay, wall_damping=wall_damping, direction=direction, velocity=velocity,
                   compensation=compensation, error_percent=error_percent, hand=hand)
    return wall_kmax(pose.J_v, pose.H, pose.B, (pose.svd[0], pose.mobility, pose.cartesian_damping), options,
                     pose.gravity, None if error_percent == 0 else pose.compensator(error_percent),
                     pose.drive)


@index(unit="LN", formula="Linearity Number over the joint region (limits, else full turns)",
       source="seed 000 eq. 3.1-3.4", needs=("device",))
def ln(pose: HandleStates) -> np.ndarray:
    device = pose.device
    return np.full(len(pose.full), float(device_form(device).ln(device.standard_parameters())))


@index(unit="kg", formula="sum of the masses of the bodies the coordinates move", source="the device file's bodies",
       needs=("bodies",))
def mass(pose: HandleStates) -> np.ndarray:
    return pose.moving_mass
