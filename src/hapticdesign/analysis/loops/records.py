"""The typed records the compiled loop-closure and closed-loop dynamics kernels take (numba NamedTuples).

Pinocchio's Model/Data split in numba form: what a closed-loop mechanism *is* comes in read-only
records built once per geometry (the folded tree :class:`~hapticdesign.model.walk.Tree`, its
:class:`~hapticdesign.model.walk.WalkPlan` and :class:`~hapticdesign.model.walk.MotionPlan`, the
:class:`Closures` and the solver's :class:`Settings`); what a kernel writes comes in a
:class:`ClosureScratch` built once per caller, so that the kernels allocate nothing in their loops and read
``ws.pinv`` by name rather than a slot number.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from hapticdesign.model.loops import ClosedLoops
from hapticdesign.model.mechanism import Mechanism
from hapticdesign.model.walk import trig_workspace

OK, NO_CLOSURE, SINGULAR, BRANCH_CHANGE, ILL_CONDITIONED, NO_HOME, OUT_OF_REACH = 0, 1, 2, 3, 4, 5, 6
"""The status every loop kernel returns (one enum for the closure kernels, the plant and the design batch): a pose
closed; the loops cannot close; ``Phi_p`` (or the inverse kinematics' system) singular; the way left the assembly
branch (or the working mode); too close to a singularity for the accuracy; the loops do not close at home from the
assembly guess; the handle does not reach a point."""


class Closures(NamedTuple):
    """The closures as flat arrays: frame nodes per loop, (loop, component) per constraint row (loop after
    loop), and the actuated and passive coordinates."""

    frame_a: np.ndarray
    frame_b: np.ndarray
    row_loop: np.ndarray
    row_comp: np.ndarray
    actuated: np.ndarray
    passive: np.ndarray

    @classmethod
    def of(cls, mech: Mechanism, numbering: str) -> "Closures":
        """The closures of ``mech`` on the nodes of ``numbering``
        (:meth:`~hapticdesign.model.mechanism.CompiledMechanism.nodes`: the loop solver's ``FOLDED``, the design
        batch's and the inverse kinematics' ``UNFOLDED``); none for a tree, whose loops are empty."""
        loops: ClosedLoops = mech.loops
        nodes = mech.compiled.nodes(numbering)
        rows = [(i, c) for i, closure in enumerate(loops.closures) for c in closure.components]
        return cls(
            frame_a=np.array([nodes[c.frames[0]] for c in loops.closures], dtype=np.int64),
            frame_b=np.array([nodes[c.frames[1]] for c in loops.closures], dtype=np.int64),
            row_loop=np.array([r[0] for r in rows], dtype=np.int64),
            row_comp=np.array([r[1] for r in rows], dtype=np.int64),
            actuated=np.array(loops.actuated(mech.n_dof), dtype=np.int64),
            passive=np.array(loops.passive, dtype=np.int64),
        )


class Settings(NamedTuple):
    """The loop solver's settings: largest continuation step (actuated infinity norm, rad or m), closure
    tolerance, Newton iterations, the pivot ratio of ``Phi_p`` below which it is singular, the smallest
    continuation step as a fraction of a segment, the relative error bound above which a closed pose is
    not trusted, and the rounding floor of the closure residual (m)."""

    max_step: float
    tol: float
    max_iter: int
    singular_ratio: float
    min_fraction: float
    accuracy: float
    floor: float


class ClosureScratch(NamedTuple):
    """Scratch of the closed-loop kernels (one per caller; nothing is allocated in their loops).

    Node poses ``rot``, ``pos`` and the walk plan's cosines and sines ``trig``; the closure residual
    ``res``, ``Phi`` (m x N), a right-hand side ``rhs`` (m x 1), an LU scratch ``lu`` and ``Phi_p^-1``
    ``pinv`` (m x m); the node motions ``w``, ``al``, ``ac``; ``T`` (N x n_a), every node's joint-value rate
    per actuated rate ``node_t`` (``coef T``) and for one rate vector ``rate``; per body the world Jacobian of
    its origin over the actuated rates ``ja`` (``J_b T``, 6 x n_a); ``Phidot qd`` ``bias``, ``gamma``;
    each coordinate's place among the passive ones ``slot`` (-1: actuated); the node accelerations of
    ``gamma`` ``dal``, ``dac``; the passive values a continuation step predicted ``predicted``.
    """

    rot: np.ndarray
    pos: np.ndarray
    trig: np.ndarray
    res: np.ndarray
    phi: np.ndarray
    rhs: np.ndarray
    lu: np.ndarray
    pinv: np.ndarray
    w: np.ndarray
    al: np.ndarray
    ac: np.ndarray
    t: np.ndarray
    node_t: np.ndarray
    rate: np.ndarray
    ja: np.ndarray
    bias: np.ndarray
    gamma: np.ndarray
    slot: np.ndarray
    dal: np.ndarray
    dac: np.ndarray
    predicted: np.ndarray


@njit(cache=True)
def closure_scratch(n_node, n_dof, na, passive, n_body):
    """A zeroed :class:`ClosureScratch` for a tree of ``n_node`` nodes, ``n_dof`` coordinates, ``na`` actuated and
    the ``passive`` ones, and ``n_body`` bodies."""
    n_node = max(n_node, 1)
    npas = passive.shape[0]
    slot = np.full(n_dof, -1, dtype=np.int64)
    for r in range(npas):
        slot[passive[r]] = r
    return ClosureScratch(
        np.zeros((n_node, 3, 3)), np.zeros((n_node, 3)), trig_workspace(n_node),
        np.zeros(npas), np.zeros((npas, n_dof)), np.zeros((npas, 1)), np.zeros((npas, npas)), np.zeros((npas, npas)),
        np.zeros((n_node, 3)), np.zeros((n_node, 3)), np.zeros((n_node, 3)),
        np.zeros((n_dof, na)), np.zeros((n_node, na)), np.zeros(n_node), np.zeros((n_body, 6, na)),
        np.zeros(npas), np.zeros(npas), slot, np.zeros((n_node, 3)), np.zeros((n_node, 3)), np.zeros(npas),
    )
