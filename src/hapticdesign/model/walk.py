"""The one walk over a mechanism's frame tree: node poses and frame Jacobians, compiled with Numba.

:class:`KinematicTree` is the compiled frame tree with its constant transforms folded: within a frame,
each run of consecutive constant elementary transforms becomes one constant node carrying its
rotation and translation (computed once, as Robotics Toolbox's ``ETS.compile`` does; a lone constant
translation stays as it is, three multiply-adds being cheaper than a constant 4x4); variable
transforms keep their :class:`~hapticdesign.model.transforms.Axis` code and affine value
``offset + coef . q``. Named frames always end on a node, so bodies and closures attach to nodes.

- :func:`node_poses`: world rotation and origin of every node up to a given one (seed 000
  eq. 2.4-2.7 and 2.24-2.26, one elementary transform at a time);
- :func:`frame_jacobian`: geometric Jacobian (6 x N, rows ``v`` then ``w``) of a node's origin,
  in the base frame or in the node's own frame. The column of a variable transform is its unit
  twist at the current pose (rotation axis ``u`` through the node: ``v = u x (p - p_node)``,
  ``w = u``; translation: ``v = u``; seed 000 eq. 2.20-2.26, seed 001 eq. 5.61-5.66 and
  5.87-5.92), weighted by the coupling coefficients of dependent coordinates (eq. 2.38-2.43);
- :func:`poses_and_jacobians`: both for a batch of coordinate vectors (a single pose is a batch of one);
- :class:`WalkPlan` and :func:`planned_poses`: the same poses for the hot loops of closed loops, nodes in
  an order that puts first those a given set of nodes needs (the loop closures), joint values from the
  non-zero coupling coefficients only, the cosine and sine of a joint angle shared by every node that
  turns by it (or by its negative) and, near an angle already evaluated, continued from there;
- :class:`MotionPlan`, :func:`node_motion` and :func:`add_joint_accelerations`: the velocity walk beside
  the pose walk, the nodes' angular velocities and accelerations (the time derivative of seed 000
  eq. 2.38-2.41) over only the nodes a set of nodes needs.

:class:`Tree`, :class:`WalkPlan` and :class:`MotionPlan` are NamedTuples, the records the compiled
kernels take. The kernels of the hot loops are compiled without numba's reference counting
(``_nrt=False``): they allocate nothing, and each array a record passes would otherwise cost an atomic
increment and decrement per call. :func:`planned_poses` and :func:`frame_jacobian` are inlined into their callers
(numba's ``inline="always"``): a call still copies every field of the records it passes, about 35 ns, a fifth of
a five-bar's walk.

Forward kinematics, the dynamics regressors, the loop-closure kernels and the R-CUBE stiffness model
all call these.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from hapticdesign.model.transforms import Axis, elementary_matrix

CONSTANT = 6
"""Node code of a folded constant transform (after the six :class:`Axis` codes)."""
ANCHOR_RANGE = 1e-2
"""rad: :func:`planned_poses` continues a cosine and sine from their anchor angle up to this far."""


@dataclass(frozen=True)
class KinematicTree:
    """Frame tree with constant transforms folded; the arrays every compiled walk takes.

    ``parent[n]`` is the previous node (``-1`` for the base), ``axis[n]`` an :class:`Axis` code or
    :data:`CONSTANT`, ``coef[n]`` and ``offset[n]`` the affine value of a variable node,
    ``const_rot[n]`` and ``const_pos[n]`` the transform of a constant node, ``frame_node`` the node
    each named frame ends on (``base``: -1) and ``body_node[b]`` the node body ``b`` is attached to.
    """

    parent: np.ndarray
    axis: np.ndarray
    coef: np.ndarray
    offset: np.ndarray
    const_rot: np.ndarray
    const_pos: np.ndarray
    frame_node: dict[str, int]
    body_node: np.ndarray

    @classmethod
    def fold(cls, parent: np.ndarray, axis: np.ndarray, coef: np.ndarray, offset: np.ndarray,
             frame_node: dict[str, int], body_frames: list[str]) -> "KinematicTree":
        """Fold the elementary-transform tree (one node per transform, named frames ending on ``frame_node``)."""
        ends = set(frame_node.values())
        variable = np.any(coef != 0.0, axis=1)
        n_dof = coef.shape[1]
        rows: list[tuple] = []  # (parent, axis, coef, offset, rotation, translation) per folded node
        mapped: dict[int, int] = {-1: -1}
        pending: list[int] = []
        run = np.eye(4)
        for n in range(len(parent)):
            if variable[n]:
                rows.append((mapped[int(parent[n])], int(axis[n]), coef[n], float(offset[n]), np.eye(3), np.zeros(3)))
                mapped[n] = len(rows) - 1
                continue
            matrix = elementary_matrix(Axis(int(axis[n])), float(offset[n]))
            run = matrix if not pending else run @ matrix
            pending.append(n)
            if n not in ends and n + 1 < len(parent) and parent[n + 1] == n and not variable[n + 1]:
                continue  # the run of constants goes on inside this frame
            start = mapped[int(parent[pending[0]])]
            if len(pending) == 1 and axis[n] >= Axis.TX:  # a lone translation is cheaper unfolded
                rows.append((start, int(axis[n]), np.zeros(n_dof), float(offset[n]), np.eye(3), np.zeros(3)))
            else:
                rows.append((start, CONSTANT, np.zeros(n_dof), 0.0, run[:3, :3], run[:3, 3]))
            mapped.update({m: len(rows) - 1 for m in pending})
            pending = []
        nodes = {name: mapped[node] for name, node in frame_node.items()}
        return cls(
            parent=np.array([r[0] for r in rows], dtype=np.int64),
            axis=np.array([r[1] for r in rows], dtype=np.int64),
            coef=np.array([r[2] for r in rows], dtype=float).reshape(len(rows), n_dof),
            offset=np.array([r[3] for r in rows], dtype=float),
            const_rot=np.array([r[4] for r in rows], dtype=float).reshape(len(rows), 3, 3),
            const_pos=np.array([r[5] for r in rows], dtype=float).reshape(len(rows), 3),
            frame_node=nodes,
            body_node=np.array([nodes[f] for f in body_frames], dtype=np.int64),
        )

    @property
    def arrays(self) -> "Tree":
        """The kernels' record of the tree (:class:`Tree`)."""
        return Tree(self.parent, self.axis, self.coef, self.offset, self.const_rot, self.const_pos)

    def plan(self, needed: list[int], moving: list[int]) -> "WalkPlan":
        """:class:`WalkPlan` whose first part is the nodes ``needed`` (and their ancestors), those that the
        coordinates ``moving`` do not move first, and of those first the ones no coordinate moves."""
        first = set()
        for node in needed:
            while node >= 0 and node not in first:
                first.add(node)
                node = int(self.parent[node])
        moved: set[int] = set()
        fixed: set[int] = set()  # the nodes no coordinate moves
        for n in range(len(self.parent)):  # parents come first
            if int(self.parent[n]) in moved or np.any(self.coef[n, list(moving)] != 0.0):
                moved.add(n)
            if (self.parent[n] < 0 or int(self.parent[n]) in fixed) and not np.any(self.coef[n] != 0.0):
                fixed.add(n)
        fixed &= first
        still = sorted(fixed) + sorted(first - moved - fixed)
        order = still + sorted(first & moved) + [n for n in range(len(self.parent)) if n not in first]
        nonzero = [np.flatnonzero(row) for row in self.coef]
        ptr = np.cumsum([0] + [len(k) for k in nonzero])
        source = np.arange(len(self.parent))
        sign = np.ones(len(self.parent))
        seen: dict[tuple, int] = {}
        for n in order:
            if self.axis[n] >= 3:
                continue
            key = (*self.coef[n], self.offset[n])
            negated = tuple(-v for v in key)
            if key in seen:
                source[n] = seen[key]
            elif negated in seen:
                source[n], sign[n] = seen[negated], -1.0
            else:
                seen[key] = n
        return WalkPlan(
            order=np.array(order, dtype=np.int64), n_first=len(first), ptr=ptr.astype(np.int64),
            index=np.concatenate([np.zeros(0, dtype=np.int64)] + nonzero).astype(np.int64),
            value=np.concatenate([np.zeros(0)] + [row[k] for row, k in zip(self.coef, nonzero)]),
            trig_source=source.astype(np.int64), trig_sign=sign, n_still=len(still), n_fixed=len(fixed),
        )

    def workspace(self) -> tuple[np.ndarray, np.ndarray]:
        """Zeroed node rotations (M, 3, 3) and origins (M, 3) for :func:`node_poses`."""
        n_node = max(len(self.parent), 1)
        return np.zeros((n_node, 3, 3)), np.zeros((n_node, 3))


class Tree(NamedTuple):
    """The arrays of a :class:`KinematicTree` every compiled walk reads (numba record)."""

    parent: np.ndarray
    axis: np.ndarray
    coef: np.ndarray
    offset: np.ndarray
    const_rot: np.ndarray
    const_pos: np.ndarray


class WalkPlan(NamedTuple):
    """A walk of a :class:`KinematicTree` for the hot loops (:func:`planned_poses`; a numba record).

    ``order`` lists every node after its parent, the ``n_first`` nodes a chosen set needs first, and of
    those the ``n_still`` that chosen coordinates do not move first (a walk after a change of only those
    coordinates starts after them), and of those the ``n_fixed`` that no coordinate moves first (a walk of the
    same tree at other coordinates starts after them); the coupling coefficients of node ``n`` are the sparse row
    ``value[ptr[n]:ptr[n + 1]]`` at the coordinates ``index[ptr[n]:ptr[n + 1]]`` (in increasing order, so a joint
    value is the same sum as the dense one's);
    a rotation node whose angle (coefficients and offset) equals, or is the negative of, that of an
    earlier node of ``order``, ``trig_source[n]``, takes its cosine and sine (times ``trig_sign[n]``).
    """

    order: np.ndarray
    n_first: int
    ptr: np.ndarray
    index: np.ndarray
    value: np.ndarray
    trig_source: np.ndarray
    trig_sign: np.ndarray
    n_still: int
    n_fixed: int

    def workspace(self) -> np.ndarray:
        """The scratch of :func:`planned_poses` (:func:`trig_workspace`)."""
        return trig_workspace(len(self.order))


@njit(cache=True)
def trig_workspace(n_node):
    """Per node (M, 5): cosine and sine of its angle, then an anchor angle (none yet: NaN) and its cosine and sine."""
    out = np.zeros((max(n_node, 1), 5))
    out[:, 2] = np.nan
    return out


@njit(cache=True, _nrt=False, forceinline=True)
def planned_poses(q, tree, plan, start, stop, rot, pos, trig):
    """:func:`node_poses` of the nodes ``order[start:stop]`` of a :class:`WalkPlan` ``plan`` on the :class:`Tree` ``tree``.

    The nodes before ``start`` in the plan's order must hold their poses (and ``trig`` their cosines and
    sines) at the same ``q``. ``trig``: :func:`trig_workspace`, kept from call to call. A rotation angle
    ``v`` within :data:`ANCHOR_RANGE` of its node's anchor angle ``v0`` (where ``cos`` and ``sin`` were last
    evaluated) follows from the angle-sum formulas with ``d = v - v0``: ``cos d = 1 - d^2/2 + d^4/24 - d^6/720``,
    ``sin d = d - d^3/6 + d^5/120 - d^7/5040`` (nested, multiplying by the reciprocals rather than dividing),
    whose first omitted terms (``d^8/40320 < 2.5e-21``, ``d^9/362880 < 3e-24``) are far below a unit of round-off;
    a farther angle is evaluated and becomes the anchor.
    Along a motion (Newton's iterations, the integrator's stages) most walks need no ``cos`` or ``sin``.
    """
    parent, axis, offset, const_rot, const_pos = tree.parent, tree.axis, tree.offset, tree.const_rot, tree.const_pos
    order, ptr, index, value, source, sign = plan.order, plan.ptr, plan.index, plan.value, plan.trig_source, plan.trig_sign
    for i in range(start, stop):
        n = order[i]
        pn = parent[n]
        ax = axis[n]
        if ax == CONSTANT:
            _constant_node(n, pn, const_rot, const_pos, rot, pos)
            continue
        if ax < 3:
            s = source[n]
            if s == n:
                v = offset[n]
                for k in range(ptr[n], ptr[n + 1]):
                    v += value[k] * q[index[k]]
                d = v - trig[n, 2]
                if abs(d) <= ANCHOR_RANGE:
                    d2 = d * d
                    cd = 1.0 - d2 * 0.5 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0)))
                    sd = d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))))
                    trig[n, 0] = trig[n, 3] * cd - trig[n, 4] * sd
                    trig[n, 1] = trig[n, 4] * cd + trig[n, 3] * sd
                else:
                    trig[n, 0] = trig[n, 3] = np.cos(v)
                    trig[n, 1] = trig[n, 4] = np.sin(v)
                    trig[n, 2] = v
            cv = trig[s, 0]
            sv = sign[n] * trig[s, 1]
            b = 1 if ax == 0 else (2 if ax == 1 else 0)  # the other two columns, cyclic after ax, turn
            c = 2 if ax == 0 else (0 if ax == 1 else 1)
            if pn >= 0:
                for r in range(3):
                    rb = rot[pn, r, b]
                    rc = rot[pn, r, c]
                    rot[n, r, ax] = rot[pn, r, ax]
                    rot[n, r, b] = rb * cv + rc * sv
                    rot[n, r, c] = -rb * sv + rc * cv
                    pos[n, r] = pos[pn, r]
            else:
                for r in range(3):
                    rb = 1.0 if r == b else 0.0
                    rc = 1.0 if r == c else 0.0
                    rot[n, r, ax] = 1.0 if r == ax else 0.0
                    rot[n, r, b] = rb * cv + rc * sv
                    rot[n, r, c] = -rb * sv + rc * cv
                    pos[n, r] = 0.0
        else:  # the parent's rotation, the origin moved along column a
            a = ax - 3
            v = offset[n]
            for k in range(ptr[n], ptr[n + 1]):
                v += value[k] * q[index[k]]
            if pn >= 0:
                for r in range(3):
                    for j in range(3):
                        rot[n, r, j] = rot[pn, r, j]
                    pos[n, r] = pos[pn, r] + rot[pn, r, a] * v
            else:
                for r in range(3):
                    for j in range(3):
                        rot[n, r, j] = 1.0 if r == j else 0.0
                    pos[n, r] = 0.0 + (1.0 if r == a else 0.0) * v


@njit(cache=True, inline="always")
def _parent_pose(n, pn, rot, pos):
    """Start node ``n`` at its parent's pose (the base's identity when ``pn < 0``), before its own transform."""
    for i in range(3):
        for j in range(3):
            rot[n, i, j] = rot[pn, i, j] if pn >= 0 else (1.0 if i == j else 0.0)
        pos[n, i] = pos[pn, i] if pn >= 0 else 0.0


@njit(cache=True, inline="always")
def _constant_node(n, pn, const_rot, const_pos, rot, pos):
    """World pose of a folded constant node ``n``: its parent's pose (the base for ``pn < 0``) times its transform."""
    for i in range(3):
        if pn < 0:
            for j in range(3):
                rot[n, i, j] = const_rot[n, i, j]
            pos[n, i] = const_pos[n, i]
        else:
            for j in range(3):
                rot[n, i, j] = (rot[pn, i, 0] * const_rot[n, 0, j] + rot[pn, i, 1] * const_rot[n, 1, j]
                                + rot[pn, i, 2] * const_rot[n, 2, j])
            pos[n, i] = (pos[pn, i] + rot[pn, i, 0] * const_pos[n, 0] + rot[pn, i, 1] * const_pos[n, 1]
                         + rot[pn, i, 2] * const_pos[n, 2])


@njit(cache=True)
def node_poses(q, parent, axis, coef, offset, const_rot, const_pos, last, rot, pos):
    """World rotation ``rot[n]`` and origin ``pos[n]`` of nodes ``0 .. last`` at coordinates ``q``."""
    for n in range(last + 1):
        pn = parent[n]
        if axis[n] == CONSTANT:
            _constant_node(n, pn, const_rot, const_pos, rot, pos)
            continue
        v = offset[n]
        for k in range(q.shape[0]):
            v += coef[n, k] * q[k]
        _parent_pose(n, pn, rot, pos)
        a = axis[n] % 3
        if axis[n] < 3:
            b = (a + 1) % 3
            c = (a + 2) % 3
            cv = np.cos(v)
            sv = np.sin(v)
            for i in range(3):
                rb = rot[n, i, b]
                rc = rot[n, i, c]
                rot[n, i, b] = rb * cv + rc * sv
                rot[n, i, c] = -rb * sv + rc * cv
        else:
            for i in range(3):
                pos[n, i] += rot[n, i, a] * v


@njit(cache=True, inline="always")
def unit_twist(rot, pos, axis, n, point):
    """Unit twist ``(v, w)`` of variable node ``n`` at the origin of node ``point``: ``(u x (p - p_n), u)`` for
    a rotation about the world axis ``u`` through the node, ``(u, 0)`` for a translation along it (seed 000
    eq. 2.20-2.26); every Jacobian column of the walks."""
    a = axis[n] % 3
    u0, u1, u2 = rot[n, 0, a], rot[n, 1, a], rot[n, 2, a]
    if axis[n] >= 3:
        return u0, u1, u2, 0.0, 0.0, 0.0
    r0, r1, r2 = pos[point, 0] - pos[n, 0], pos[point, 1] - pos[n, 1], pos[point, 2] - pos[n, 2]
    return u1 * r2 - u2 * r1, u2 * r0 - u0 * r2, u0 * r1 - u1 * r0, u0, u1, u2


@njit(cache=True, _nrt=False, forceinline=True)
def frame_jacobian(node, parent, axis, coef, rot, pos, body, jac):
    """Jacobian (6 x N, rows v then w) of the origin of node ``node`` (-1: the base) at the poses ``rot, pos``;
    only its rows ``v`` when ``jac`` has 3 rows.

    In the base frame, or with ``body`` in the node's own frame (``R^T v``, ``R^T w``).
    """
    n_dof = jac.shape[1]
    angular = jac.shape[0] == 6
    for i in range(jac.shape[0]):
        for k in range(n_dof):
            jac[i, k] = 0.0
    if node < 0:
        return
    n = node
    while n >= 0:
        if axis[n] != CONSTANT:
            rotation = axis[n] < 3 and angular
            v0, v1, v2, u0, u1, u2 = unit_twist(rot, pos, axis, n, node)
            if body:
                v0, v1, v2 = _to_node(rot, node, v0, v1, v2)
                if rotation:
                    u0, u1, u2 = _to_node(rot, node, u0, u1, u2)
            for k in range(n_dof):
                c = coef[n, k]
                if c != 0.0:
                    jac[0, k] += c * v0
                    jac[1, k] += c * v1
                    jac[2, k] += c * v2
                    if rotation:
                        jac[3, k] += c * u0
                        jac[4, k] += c * u1
                        jac[5, k] += c * u2
        n = parent[n]


@njit(cache=True, inline="always")
def _to_node(rot, node, x0, x1, x2):
    """``R^T x`` with ``R`` the world rotation of ``node``: a base-frame vector in the node's axes."""
    return (rot[node, 0, 0] * x0 + rot[node, 1, 0] * x1 + rot[node, 2, 0] * x2,
            rot[node, 0, 1] * x0 + rot[node, 1, 1] * x1 + rot[node, 2, 1] * x2,
            rot[node, 0, 2] * x0 + rot[node, 1, 2] * x1 + rot[node, 2, 2] * x2)


@njit(cache=True)
def poses_and_jacobians(qs, parent, axis, coef, offset, const_rot, const_pos, node, body, poses, jac):
    """World poses (P, 4, 4) and Jacobians (P, 6, N) of node ``node`` at coordinates ``qs`` (P, N), into the outputs."""
    n_node = max(node + 1, 1)
    rot = np.zeros((n_node, 3, 3))
    pos = np.zeros((n_node, 3))
    for p in range(qs.shape[0]):
        node_poses(qs[p], parent, axis, coef, offset, const_rot, const_pos, node, rot, pos)
        for i in range(3):
            for j in range(3):
                poses[p, i, j] = rot[node, i, j] if node >= 0 else (1.0 if i == j else 0.0)
            poses[p, i, 3] = pos[node, i] if node >= 0 else 0.0
            poses[p, 3, i] = 0.0
        poses[p, 3, 3] = 1.0
        frame_jacobian(node, parent, axis, coef, rot, pos, body, jac[p])


class MotionPlan(NamedTuple):
    """The nodes whose motions (:func:`node_motion`) a set of nodes needs, in tree order (a numba record).

    Those nodes and, among their ancestors, the variable ones: the others (constants, fixed
    translations) only carry a motion along a rigid offset, which the next kept node takes from its
    kept ancestor ``parent[i]`` (``-1``: the base) over the origin difference. ``moves[i]`` is False when
    node ``order[i]`` has its kept ancestor's origin (only rotations between them), so that its origin
    acceleration is the ancestor's.
    """

    order: np.ndarray
    parent: np.ndarray
    moves: np.ndarray

    @classmethod
    def of(cls, tree: KinematicTree, needed: list[int]) -> "MotionPlan":
        """The plan of the nodes ``needed`` (``-1``, the base, needs none) on the folded tree ``tree``."""
        variable = np.any(tree.coef != 0.0, axis=1)
        path: set[int] = set()
        for node in needed:
            while node >= 0 and node not in path:
                path.add(node)
                node = int(tree.parent[node])
        order = sorted(n for n in path if variable[n] or n in needed)
        kept = set(order)
        parents, moves = [], []
        for n in order:
            e, moved = n, False
            while e >= 0 and (e == n or e not in kept):
                shift = tree.axis[e] >= 3 if tree.axis[e] != CONSTANT else bool(np.any(tree.const_pos[e] != 0.0))
                moved = moved or bool(shift)
                e = int(tree.parent[e])
            parents.append(e)
            moves.append(moved)
        return cls(order=np.array(order, dtype=np.int64), parent=np.array(parents, dtype=np.int64),
                   moves=np.array(moves, dtype=np.bool_))


@njit(cache=True)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True, _nrt=False)
def node_motion(rate, motion, axis, rot, pos, w, al, ac):
    """World angular velocity ``w`` and, at zero joint accelerations, the angular and origin accelerations
    ``al``, ``ac`` of the nodes of a :class:`MotionPlan` ``motion``, for the rate
    ``rate[n]`` of each node's joint value.

    From the kept ancestor ``k`` (the base: at rest), over the origin difference ``d = p_n - p_k``:
    rotation node (axis ``u``, rate ``s``): ``w = w_k + s u``, ``al = al_k + w_k x s u``,
    ``ac = ac_k + al_k x d + w_k x (w_k x d)``; translation node: ``w = w_k``, ``al = al_k``,
    ``ac = ac_k + al_k x d + w_k x (w_k x d) + 2 w_k x s u`` (the time derivative of seed 000 eq. 2.38-2.41).
    """
    order, kept, moves = motion.order, motion.parent, motion.moves
    for i in range(order.shape[0]):
        n = order[i]
        p = kept[i]
        s = rate[n]
        a = axis[n] % 3
        u0, u1, u2 = rot[n, 0, a], rot[n, 1, a], rot[n, 2, a]
        if p >= 0:
            w0, w1, w2 = w[p, 0], w[p, 1], w[p, 2]
            l0, l1, l2 = al[p, 0], al[p, 1], al[p, 2]
            a0, a1, a2 = ac[p, 0], ac[p, 1], ac[p, 2]
        else:
            w0 = w1 = w2 = l0 = l1 = l2 = a0 = a1 = a2 = 0.0
        if p >= 0 and moves[i]:
            d0, d1, d2 = pos[n, 0] - pos[p, 0], pos[n, 1] - pos[p, 1], pos[n, 2] - pos[p, 2]
            wd0, wd1, wd2 = _cross(w0, w1, w2, d0, d1, d2)
            ww0, ww1, ww2 = _cross(w0, w1, w2, wd0, wd1, wd2)
            ld0, ld1, ld2 = _cross(l0, l1, l2, d0, d1, d2)
            a0, a1, a2 = a0 + ld0 + ww0, a1 + ld1 + ww1, a2 + ld2 + ww2
        x0, x1, x2 = _cross(w0, w1, w2, s * u0, s * u1, s * u2)
        if axis[n] < 3:
            w[n, 0], w[n, 1], w[n, 2] = w0 + s * u0, w1 + s * u1, w2 + s * u2
            al[n, 0], al[n, 1], al[n, 2] = l0 + x0, l1 + x1, l2 + x2
            ac[n, 0], ac[n, 1], ac[n, 2] = a0, a1, a2
        else:
            w[n, 0], w[n, 1], w[n, 2] = w0, w1, w2
            al[n, 0], al[n, 1], al[n, 2] = l0, l1, l2
            ac[n, 0], ac[n, 1], ac[n, 2] = a0 + 2.0 * x0, a1 + 2.0 * x1, a2 + 2.0 * x2


@njit(cache=True, _nrt=False)
def add_joint_accelerations(acc, motion, axis, rot, pos, al, ac, dal, dac):
    """Add to the node accelerations ``al``, ``ac`` those of the joint-value accelerations ``acc[n]`` at zero rates
    (the nodes of a motion plan, as :func:`node_motion`).

    The rate-free part of :func:`node_motion` (linear in ``acc``): from the kept ancestor ``k``, a node carries
    its angular acceleration ``dal_k`` over the origin difference ``d`` (``dac = dac_k + dal_k x d``) and adds
    ``acc u`` to the angular acceleration (rotation) or to the origin's (translation). ``dal``, ``dac``:
    scratch (M x 3).
    """
    order, kept, moves = motion.order, motion.parent, motion.moves
    for i in range(order.shape[0]):
        n = order[i]
        p = kept[i]
        s = acc[n]
        a = axis[n] % 3
        u0, u1, u2 = s * rot[n, 0, a], s * rot[n, 1, a], s * rot[n, 2, a]
        if p >= 0:
            l0, l1, l2 = dal[p, 0], dal[p, 1], dal[p, 2]
            a0, a1, a2 = dac[p, 0], dac[p, 1], dac[p, 2]
            if moves[i]:
                x0, x1, x2 = _cross(l0, l1, l2, pos[n, 0] - pos[p, 0], pos[n, 1] - pos[p, 1], pos[n, 2] - pos[p, 2])
                a0, a1, a2 = a0 + x0, a1 + x1, a2 + x2
        else:
            l0 = l1 = l2 = a0 = a1 = a2 = 0.0
        if axis[n] < 3:
            l0, l1, l2 = l0 + u0, l1 + u1, l2 + u2
        else:
            a0, a1, a2 = a0 + u0, a1 + u1, a2 + u2
        dal[n, 0], dal[n, 1], dal[n, 2] = l0, l1, l2
        dac[n, 0], dac[n, 1], dac[n, 2] = a0, a1, a2
        al[n, 0] += l0
        al[n, 1] += l1
        al[n, 2] += l2
        ac[n, 0] += a0
        ac[n, 1] += a1
        ac[n, 2] += a2
