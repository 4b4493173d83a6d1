"""Many designs of one device through compiled kernels: workspace poses, ``J_v T``, ``H`` and ``K_C`` per design.

An optimization evaluates thousands of designs that differ only in numbers: lengths, masses, motors. Building each
design's mechanism, loop solver and models in Python costs milliseconds, so :class:`DesignBatch` builds the
*structure* once (the frame tree with one node per elementary transform, its walk plan, the closures, the bodies)
and takes per design only what changes:

- the node offsets, affine in the kinematic parameters (a device file's values are affine expressions, so
  ``offset = offset_0 + S (p - p_0)`` exactly; ``S`` is found once by building the mechanism at ``p_0 + e_k``);
- the standard inertial parameters, the motors' reflected inertia, damping and torque limits, and the elastic
  links' rigidities (:class:`DesignValues`, which a design space fills from its variables).

A tree is a closed-loop device without loops (no closures, no passive coordinates: Pinocchio's view), so trees and
closed loops take the same kernels. The frame tree, the closures on its node numbering
(:data:`~hapticdesign.model.mechanism.UNFOLDED`, :meth:`~hapticdesign.model.mechanism.CompiledMechanism.nodes`)
and the handle's node are the
configuration space's (:func:`~.reach_kernel.structure_of`), the statuses those every loop kernel returns
(:mod:`.loops.records`), the Newton start at home :meth:`~hapticdesign.model.loops.ClosedLoops.guess`.

:func:`~.reach_kernel.reach_designs`, the one inverse kinematics
(:meth:`~hapticdesign.analysis.configuration.Configuration.reach` runs it for one device), then reaches the
workspace points of every design in one compiled call and leaves ``J_v T`` (3 x n_a) at each point.
:func:`mass_designs` gives ``H`` at those poses with the closed-loop dynamics' own pose kernels
(:mod:`hapticdesign.analysis.dynamics.actuated_kernel`), and :func:`vjm_designs` the virtual joint method's rows
there (the handle's and the closures' Jacobians over the coordinates and the six virtual coordinates of each elastic
link), from which ``K_C`` follows as :func:`~hapticdesign.analysis.stiffness.device.cartesian_stiffness_at` gives it
one pose at a time.
``tests/design/test_design_batch.py`` checks them against the one-design path (:mod:`.metrics.indices`) for every
kind of design variable.
"""

from __future__ import annotations

from typing import Callable, NamedTuple

import numpy as np
from numba import njit

from hapticdesign.analysis.configuration import IK_SINGULAR, check_limits, configuration_of, reach_settings
from hapticdesign.analysis.dynamics.actuated_kernel import Bodies, passive_paths, pose_dynamics, pose_terms, terms_into
from hapticdesign.analysis.dynamics.device import GRADIENT_STEP
from hapticdesign.analysis.loops import closure_kernel as ck
from hapticdesign.analysis.loops.records import NO_HOME, OK
from hapticdesign.analysis.reach_kernel import MESSAGES, Reached, reach_designs, structure_of
from hapticdesign.analysis.stiffness import vjm
from hapticdesign.analysis.stiffness.device import end_compliance
from hapticdesign.errors import UserError
from hapticdesign.model.actuators import Transmission
from hapticdesign.model.compensator_model import scaled_standard
from hapticdesign.model.device import Device, build_mechanism
from hapticdesign.model.walk import MotionPlan, Tree, frame_jacobian, node_poses, planned_poses, trig_workspace

@njit(cache=True)
def mass_designs(offsets, full, status, shape, plan, bodies, loops, params, out):
    """``H`` (actuated coordinates, without the reflected rotor inertia) at the poses ``full`` (D, P, N) of the
    designs whose status is OK, for their standard parameters ``params`` (D, 10 B), into ``out`` (D, P, n_a, n_a)
    (:func:`~hapticdesign.analysis.dynamics.actuated_kernel.terms_into`, the kernel of one device's ``H`` and
    ``G`` at closed poses)."""
    n_pose = full.shape[1]
    s = pose_dynamics(shape.parent.shape[0], loops, bodies, full.shape[2])
    g = np.zeros((n_pose, s.g.shape[0]))
    ratios = np.zeros(n_pose)
    for d in range(full.shape[0]):
        if status[d] == OK:
            tree = Tree(shape.parent, shape.axis, shape.coef, offsets[d], shape.const_rot, shape.const_pos)
            terms_into(full[d], tree, plan, bodies, loops, params[d:d + 1], s, out[d], g, ratios)


@njit(cache=True)
def gravity_designs(offsets, full, status, shape, plan, bodies, loops, params, step, out):
    """``K_G = dG/dq_a`` (actuated coordinates) at the poses ``full`` (D, P, N) of the designs whose status is OK into
    ``out`` (D, P, n_a, n_a), by central differences of ``G`` over ``+-step`` along each actuated coordinate's
    motion ``T e_j`` (the passive coordinates follow to first order; the second-order miss of the closure is even in
    the step and cancels in the difference)."""
    n_design, n_pose, n = full.shape
    s = pose_dynamics(shape.parent.shape[0], loops, bodies, n)
    na = s.h.shape[0]
    g_up = np.zeros(na)
    t = np.zeros((n, na))
    q = np.zeros(n)
    for d in range(n_design):
        if status[d] != OK:
            continue
        tree = Tree(shape.parent, shape.axis, shape.coef, offsets[d], shape.const_rot, shape.const_pos)
        sets = params[d:d + 1]
        for p in range(n_pose):
            pose_terms(full[d, p], tree, plan, bodies, loops, sets, s)
            t[:] = s.closure.t
            for j in range(na):
                for i in range(n):
                    q[i] = full[d, p, i] + step * t[i, j]
                pose_terms(q, tree, plan, bodies, loops, sets, s)
                g_up[:] = s.g
                for i in range(n):
                    q[i] = full[d, p, i] - step * t[i, j]
                pose_terms(q, tree, plan, bodies, loops, sets, s)
                for i in range(na):
                    out[d, p, i, j] = (g_up[i] - s.g[i]) / (2.0 * step)


@njit(cache=True)
def frame_vectors(offsets, shape, start, end, out):
    """Per design (offsets D x nodes) and pair of nodes ``start[l]``, ``end[l]`` (-1: the base), the origin of
    ``end`` from that of ``start`` at ``q = 0`` in ``start``'s axes and in ``end``'s, into ``out`` (D, L, 2, 3)."""
    n_node = shape.parent.shape[0]
    rot, pos = np.zeros((n_node, 3, 3)), np.zeros((n_node, 3))
    q = np.zeros(shape.coef.shape[1])
    for d in range(offsets.shape[0]):
        node_poses(q, shape.parent, shape.axis, shape.coef, offsets[d], shape.const_rot, shape.const_pos,
                   n_node - 1, rot, pos)
        for k in range(start.shape[0]):
            a, b = start[k], end[k]
            for i in range(3):
                out[d, k, 0, i] = 0.0
                out[d, k, 1, i] = 0.0
                for c in range(3):
                    delta = pos[b, c] - (pos[a, c] if a >= 0 else 0.0)
                    out[d, k, 0, i] += (rot[a, c, i] if a >= 0 else (1.0 if c == i else 0.0)) * delta
                    out[d, k, 1, i] += rot[b, c, i] * delta


@njit(cache=True, inline="always")
def _moves(parent, node, point):
    """Whether ``node`` is ``point`` or one of its ancestors (a joint at ``node`` moves ``point``)."""
    while point >= 0:
        if point == node:
            return True
        point = parent[point]
    return False


@njit(cache=True, inline="always")
def _virtual_twist(rot, pos, node, i, point, c):
    """Component ``c`` of the unit twist (v, w) at the origin of ``point`` of virtual coordinate ``i`` (tx ty tz Rx
    Ry Rz in ``node``'s axes) appended to ``node``."""
    a = i % 3
    if c >= 3:
        return rot[node, c - 3, a] if i >= 3 else 0.0
    if i < 3:
        return rot[node, c, a]
    u0, u1, u2 = rot[node, 0, a], rot[node, 1, a], rot[node, 2, a]
    r0, r1, r2 = pos[point, 0] - pos[node, 0], pos[point, 1] - pos[node, 1], pos[point, 2] - pos[node, 2]
    if c == 0:
        return u1 * r2 - u2 * r1
    if c == 1:
        return u2 * r0 - u0 * r2
    return u0 * r1 - u1 * r0


@njit(cache=True)
def vjm_designs(offsets, full, status, shape, plan, loops, handle, ends, rows, virtual):
    """The rows of the virtual joint method at the poses ``full`` (D, P, N) of the designs whose status is OK: the
    handle's twist Jacobian over the coordinates and the closures' ``Phi`` into ``rows`` (D, P, 6 + m, N), and the
    columns of the six virtual coordinates appended to each elastic link's end node ``ends[l]`` into ``virtual``
    (D, P, 6 + m, 6 L) (:mod:`hapticdesign.analysis.stiffness.device`, eq. 5.93-5.97)."""
    n_design, n_pose, n = full.shape
    n_node = shape.parent.shape[0]
    m = loops.row_loop.shape[0]
    rot, pos, trig = np.zeros((n_node, 3, 3)), np.zeros((n_node, 3)), trig_workspace(n_node)
    jac, phi = np.zeros((6, n)), np.zeros((m, n))
    parent = shape.parent
    for d in range(n_design):
        if status[d] != OK:
            continue
        tree = Tree(shape.parent, shape.axis, shape.coef, offsets[d], shape.const_rot, shape.const_pos)
        for p in range(n_pose):
            planned_poses(full[d, p], tree, plan, np.int64(0), n_node, rot, pos, trig)
            frame_jacobian(handle, shape.parent, shape.axis, shape.coef, rot, pos, np.bool_(False), jac)
            rows[d, p, :6] = jac
            if m > 0:
                ck.closure_jacobian(loops, tree, plan, rot, pos, phi)
                rows[d, p, 6:] = phi
            for k in range(ends.shape[0]):
                e = ends[k]
                at_handle = _moves(parent, e, handle)
                for i in range(6):
                    col = 6 * k + i
                    for c in range(6):
                        virtual[d, p, c, col] = _virtual_twist(rot, pos, e, i, handle, c) if at_handle else 0.0
                    for r in range(m):
                        a, b = loops.frame_a[loops.row_loop[r]], loops.frame_b[loops.row_loop[r]]
                        c = loops.row_comp[r]
                        value = 0.0
                        if a >= 0 and _moves(parent, e, a):
                            value += _virtual_twist(rot, pos, e, i, a, c)
                        if b >= 0 and _moves(parent, e, b):
                            value -= _virtual_twist(rot, pos, e, i, b, c)
                        virtual[d, p, 6 + r, col] = value


def _per_design(params: np.ndarray, d: int) -> np.ndarray:
    """Standard parameters (D, 10 B) of ``d`` designs from one set (10 B,) or one per design: always a new writable
    C array, so that the kernels see one array type (a read-only broadcast view would compile them once more)."""
    return np.array(np.broadcast_to(np.atleast_2d(params), (d, np.shape(params)[-1])), dtype=float, order="C")


class DesignValues(NamedTuple):
    """What changes from design to design, for :meth:`DesignBatch.evaluate` (D designs; filled from a design space's
    variables by :meth:`hapticdesign.devices.design_space.DesignSpace.batch_values`): kinematic parameters (D, K) in
    the order of :attr:`DesignBatch.names`, standard inertial parameters (D, 10 B), the motors' reflected inertia
    and the damping ``B`` (D, n_a, n_a), the motors' ``A^-1`` (D, n_a, n_a; None unless one motor per coordinate),
    ``n_k tau_k`` per torque kind (``continuous``, ``peak``: (D, n_a), or None where a motor lacks it), the
    elastic links' rigidities ``E A, E I, G J`` (D, L, 3; None without elastic links), and per design the reason
    the device file refuses it (None: a valid design)."""

    kinematic: np.ndarray
    standard: np.ndarray
    reflected: np.ndarray
    damping: np.ndarray
    motor_map: np.ndarray | None
    torques: dict
    rigidity: np.ndarray | None
    refused: list
    transmission: Transmission | None = None
    """The motors' compliant transmissions (D, n_a, n_a) each, None when the motors are rigid."""
    motor_damping: np.ndarray | None = None
    """The motors' own damping ``B_m`` (D, n_a, n_a): the part of ``B`` on the motors' side of a compliant drive."""


class Evaluated(NamedTuple):
    """Many designs at the workspace points (:meth:`DesignBatch.evaluate`): ``J_v`` (D, P, 3, n_a), ``H`` with the
    reflected rotor inertia (D, P, n_a, n_a), the actuated coordinates ``q`` (D, P, n_a), the VJM's ``K_C``
    (D, P, 6, 6; None unless asked), the gravity gradient (None unless asked), the mass the
    coordinates move (D,), whether each design reached every point (D,) and else why not (one line), and the
    design values it was given (``B``, the motors)."""

    jacobian: np.ndarray
    mass: np.ndarray
    q: np.ndarray
    stiffness: np.ndarray | None
    moving_mass: np.ndarray
    ok: np.ndarray
    reasons: list
    values: DesignValues
    gravity: np.ndarray | None = None
    """``dG/dq`` (D, P, n_a, n_a) when asked."""
    model: Callable[[float], tuple[np.ndarray, np.ndarray]] | None = None
    """The compensator's ``H`` and ``dG/dq`` (D, P, n_a, n_a each) at the same poses for a modelling error in percent
    (:func:`~hapticdesign.model.compensator_model.scaled_standard` of each design's parameters, the rotors exact)."""


class DesignBatch:
    """The compiled structure of a device's geometry family (see the module docstring): designs that share the
    file's frames, loops and bodies and differ in kinematic parameters, inertial parameters, sections and motors.
    A tree is a closed-loop device without loops (no closures, no passive coordinates)."""

    def __init__(self, device: Device, frame: str | None = None):
        mech = device.mechanism
        space = configuration_of(device)
        c = mech.compiled
        n_a = mech.n_actuated
        if n_a > 3:
            raise UserError("the batched design kernels take devices whose handle moves in as many directions as they "
                            "have actuated coordinates (at most 3)")
        self.device, self.names = device, tuple(device.kinematic)
        self.p0 = np.array([device.params[k] for k in self.names], dtype=float)
        self.offset0 = c.node_offset.copy()
        self.sensitivity = self._sensitivity(device)
        structure = structure_of(mech, frame)
        self.shape, self.closures, self.handle = structure.shape, structure.closures, structure.handle
        self.frame = frame or mech.end_effector
        plan = structure.raw.plan([*self.closures.frame_a, *self.closures.frame_b, self.handle],
                                  list(self.closures.passive))
        self.plan = self._unshared(plan)
        body_node = c.body_node.astype(np.int64)
        ptr, nodes = passive_paths(c.node_parent, self.plan, body_node, self.closures.passive)
        self.bodies = Bodies(body_node=body_node, gravity=c.gravity,
                             motion=MotionPlan.of(structure.raw, [*body_node, *self.closures.frame_a,
                                                                  *self.closures.frame_b]),
                             path_ptr=ptr, path_nodes=nodes)
        self.moving = [b for b in range(len(device.body_names)) if np.any(c.body_path[b] >= 0)]
        """The bodies some coordinate moves (:func:`~hapticdesign.analysis.metrics.indices.moving_mass`)."""
        self.settings = space.settings
        guess = mech.loops.guess(mech.n_dof)
        jac = space.position_and_jacobian(space.full(space.home), frame)[1]
        s = np.linalg.svd(jac, compute_uv=False)
        if not s[-1] > IK_SINGULAR * s[0]:
            raise UserError("the batched design kernels take devices whose handle moves in as many directions as they "
                            "have actuated coordinates at home")
        self.reach = reach_settings(self.handle, jac, guess, self.settings)
        elastic = device.elasticity
        self.elastic_links = () if elastic is None else elastic.links
        self.springs = () if elastic is None else tuple(elastic.joints)
        self.ends = np.array([c.frame_node[link.end] for link in self.elastic_links], dtype=np.int64)

    def _sensitivity(self, device: Device) -> np.ndarray:
        """``d offset / d p`` (nodes x parameters), exact for the affine values of a device file."""
        out = np.zeros((len(self.offset0), len(self.names)))
        for k, name in enumerate(self.names):
            shifted = tuple((n, float(v) + (1.0 if n == name else 0.0)) for n, v in device.kinematic_values())
            out[:, k] = build_mechanism(device.builder, shifted).compiled.node_offset - self.offset0
        return out

    def _unshared(self, plan):
        """The plan without shared cosines and sines between nodes whose angles parameters move differently."""
        source, sign = plan.trig_source.copy(), plan.trig_sign.copy()
        for n, s in enumerate(source):
            if s != n and not np.allclose(self.sensitivity[n], sign[n] * self.sensitivity[s], rtol=0, atol=1e-12):
                source[n], sign[n] = n, 1.0
        return plan._replace(trig_source=source, trig_sign=sign)

    def offsets(self, kinematic: np.ndarray) -> np.ndarray:
        """Node offsets (D, nodes) of designs with kinematic parameters ``kinematic`` (D, parameters) in the order of
        ``names``."""
        return self.offset0 + (np.atleast_2d(kinematic) - self.p0) @ self.sensitivity.T

    def frame_vectors(self, offsets: np.ndarray, pairs: list[tuple[str, str]]) -> np.ndarray:
        """Per design and pair of frames ``(start, end)``, the origin of ``end`` from that of ``start`` (at q = 0),
        in ``start``'s axes and in ``end``'s: (D, L, 2, 3)."""
        nodes = self.device.mechanism.compiled.frame_node
        start = np.array([nodes[a] for a, _ in pairs], dtype=np.int64)
        end = np.array([nodes[b] for _, b in pairs], dtype=np.int64)
        out = np.zeros((len(offsets), len(pairs), 2, 3))
        frame_vectors(np.ascontiguousarray(offsets, dtype=float), self.shape, start, end, out)
        return out

    def reach_points(self, offsets: np.ndarray, points: np.ndarray) -> Reached:
        """:func:`reach_designs` of the designs' offsets (D, nodes) to ``points`` (P, 3)."""
        offsets = np.ascontiguousarray(offsets, dtype=float)
        d, p, n, na = len(offsets), len(points), len(self.reach.guess), len(self.closures.actuated)
        out = Reached(np.zeros((d, p, n)), np.zeros((d, p, 3, na)), np.zeros(d, dtype=np.int64),
                      np.zeros(d, dtype=np.int64), np.zeros((d, 3)))
        reach_designs(offsets, np.ascontiguousarray(points, dtype=float), self.shape, self.plan, self.closures,
                      self.settings, self.reach, out)
        return out

    def mass_matrices(self, offsets: np.ndarray, reached: Reached, params: np.ndarray,
                      reflected: np.ndarray) -> np.ndarray:
        """``H`` (D, P, n_a, n_a) at the reached poses, standard parameters ``params`` (D, 10 B) or one set for every
        design (10 B,), and reflected rotor inertia ``reflected`` (D, n_a, n_a) or (n_a, n_a)."""
        d, p = reached.status.shape[0], reached.full.shape[1]
        na = len(self.closures.actuated)
        h = np.zeros((d, p, na, na))
        params = _per_design(params, d)
        mass_designs(np.ascontiguousarray(offsets, dtype=float), reached.full, reached.status, self.shape, self.plan,
                     self.bodies, self.closures, params, h)
        return h + (reflected[:, None] if np.ndim(reflected) == 3 else reflected)

    def gravity_gradients(self, offsets: np.ndarray, reached: Reached, params: np.ndarray) -> np.ndarray:
        """``dG/dq`` (D, P, n_a, n_a) at the reached poses, standard parameters ``params`` (D, 10 B)
        (:func:`gravity_designs`; the step of :func:`~hapticdesign.analysis.dynamics.device.gravity_gradient`)."""
        d, p = reached.status.shape[0], reached.full.shape[1]
        na = len(self.closures.actuated)
        out = np.zeros((d, p, na, na))
        params = _per_design(params, d)
        gravity_designs(np.ascontiguousarray(offsets, dtype=float), reached.full, reached.status, self.shape,
                        self.plan, self.bodies, self.closures, params, GRADIENT_STEP, out)
        return out

    def stiffness(self, offsets: np.ndarray, reached: Reached, rigidity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The VJM's ``K_C`` (D, P, 6, 6) at the reached poses of the designs whose status is OK, for the elastic
        links' rigidities (D, L, 3) (:func:`~hapticdesign.analysis.stiffness.device.cartesian_stiffness_at`), and
        per design whether it is defined at every point (False: the handle is rigid in some direction there)."""
        d, p, n = reached.full.shape
        defined = reached.status == OK
        chosen = np.flatnonzero(defined)  # only these designs' rows are built (no copies of the others' zeros)
        offsets = np.ascontiguousarray(offsets[chosen], dtype=float)
        m, links = len(self.closures.row_loop), len(self.elastic_links)
        rows, virtual = np.zeros((len(chosen), p, 6 + m, n)), np.zeros((len(chosen), p, 6 + m, 6 * links))
        vjm_designs(offsets, reached.full[chosen], reached.status[chosen], self.shape, self.plan, self.closures,
                    self.handle, self.ends, rows, virtual)
        axis = self.frame_vectors(offsets, [(link.start, link.end) for link in self.elastic_links])[:, :, 1]
        compliance = end_compliance(axis, *np.moveaxis(rigidity[chosen], -1, 0))
        index = {name: k for k, name in enumerate(self.device.mechanism.coordinates)}
        spring_columns = [index[name] for name, _ in self.springs]
        size = 6 * links + len(self.springs)
        c_theta = np.zeros((len(chosen), size, size))
        for k in range(links):
            c_theta[:, 6 * k:6 * k + 6, 6 * k:6 * k + 6] = compliance[:, k]
        for k, (_, value) in enumerate(self.springs):
            c_theta[:, 6 * links + k, 6 * links + k] = 1.0 / value
        j_theta = np.concatenate([virtual, rows[..., spring_columns]], axis=-1) if spring_columns else virtual
        j_p = rows[..., self.closures.passive]
        out = np.zeros((d, p, 6, 6))
        try:
            out[chosen] = self._cartesian(j_theta, c_theta[:, None], j_p)
        except UserError:  # some pose is singular: design by design, to tell which
            for row, k in enumerate(chosen):
                try:
                    out[k] = self._cartesian(j_theta[row], c_theta[row], j_p[row])
                except UserError:
                    defined[k] = False
        return out, defined

    def _cartesian(self, j_theta: np.ndarray, c_theta: np.ndarray, j_p: np.ndarray) -> np.ndarray:
        if len(self.closures.passive):
            return vjm.chain_stiffness(j_theta, c_theta, j_p)[..., :6, :6]
        return vjm.locked_stiffness(j_theta, c_theta)[..., :6, :6]

    def evaluate(self, values: DesignValues, points: np.ndarray, stiffness: bool = False,
                 home: np.ndarray | None = None, gravity: bool = False) -> Evaluated:
        """Every design of ``values`` at the workspace ``points`` (P, 3), reached in order from home: ``J_v``, ``H``
        (the design's inertial parameters and motors), ``K_C`` when ``stiffness`` (the design's sections), the
        moving mass, and the reason of each design that fails (refused by the device file, a point not reached or
        outside the joint limits, a pose where the handle is rigid in some direction), and ``dG/dq`` when
        ``gravity`` (:meth:`gravity_gradients`). ``home``: the handle's home
        position of a device file that gives one (``home: {position}``); each design's home is then where its
        handle reaches that position from the file's home joint values (as the design's own device file puts it,
        :func:`~hapticdesign.devices.device_file.home_at`), so the home follows the design's geometry."""
        points = np.asarray(points, dtype=float)
        offsets = self.offsets(values.kinematic)
        if home is None:
            reached = self.reach_points(offsets, points)
        else:
            first = self.reach_points(offsets, np.vstack([np.asarray(home, dtype=float)[None], points]))
            reached = first._replace(full=first.full[:, 1:], jvt=first.jvt[:, 1:], point=first.point - 1)
        reasons = list(values.refused)
        limited = any(span is not None for span in self.device.joint_limits())
        for d in range(len(reasons)):
            if reasons[d] is None and reached.status[d] != OK:
                reasons[d] = self.reason(reached, d, points, home)
            elif reasons[d] is None and limited:
                try:
                    check_limits(self.device, reached.full[d][:, self.closures.actuated], points)
                except UserError as exc:
                    reasons[d] = str(exc)
        ok = np.array([r is None for r in reasons], dtype=bool)
        reached = reached._replace(status=np.where(ok, OK, NO_HOME))
        mass = self.mass_matrices(offsets, reached, values.standard, values.reflected)
        masses = values.standard.reshape(len(ok), -1, 10)[:, :, 0]
        moving = sum((masses[:, b] for b in self.moving), np.zeros(len(ok)))
        k_c = None
        if stiffness:
            k_c, defined = self.stiffness(offsets, reached, values.rigidity)
            for d in np.flatnonzero(ok & ~defined):
                reasons[d] = (f"the end effector {self.frame!r} is rigid in some direction at this pose: the elastic "
                              "links and joint springs do not reach it, or the pose is singular")
            ok &= defined
        grad = self.gravity_gradients(offsets, reached, values.standard) if gravity else None

        def model(error_percent: float) -> tuple[np.ndarray, np.ndarray]:
            standard = scaled_standard(values.standard, 1.0 - error_percent / 100.0)
            return (self.mass_matrices(offsets, reached, standard, values.reflected),
                    self.gravity_gradients(offsets, reached, standard))

        return Evaluated(reached.jvt, mass, reached.full[..., self.closures.actuated], k_c, moving, ok, reasons, values,
                         grad, model)

    def reason(self, reached: Reached, design: int, points: np.ndarray, home: np.ndarray | None = None) -> str | None:
        """One line on why ``design`` failed (naming the point, or the ``home`` position), or None."""
        code = int(reached.status[design])
        if code == OK:
            return None
        if code == NO_HOME:
            return MESSAGES[NO_HOME]
        index = int(reached.point[design])
        if index < 0 and home is None:
            where = "home"
        else:
            named = "(" + ", ".join(f"{v:.6g}" for v in (home if index < 0 else points[index])) + ") m"
            where = named if index >= 0 else f"its home position {named}"
        return f"the handle cannot reach {where}: {MESSAGES[code]}"

