"""Mechanism: a tree of frames built from elementary transforms, with bodies attached to frames.

A serial chain is a path in this tree; a hybrid (closed-loop) mechanism such as the Phantom's
parallelogram is a tree whose dependent transforms are driven by affine combinations of the
independent coordinates (seed 000 eq. 2.38-2.43). Loops whose closure is not affine (a five-bar
with separate base pivots, a delta) keep their passive joints as tree coordinates and add closure
constraints (:class:`~hapticdesign.model.loops.ClosedLoops`, ``loops``). Jacobians, dynamics,
stiffness and metrics all consume the compiled form :class:`CompiledMechanism`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from functools import cached_property

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.loops import ClosedLoops
from hapticdesign.model.transforms import ElementaryTransform
from hapticdesign.model.walk import KinematicTree, poses_and_jacobians


class JointType(str, Enum):
    REVOLUTE = "revolute"
    PRISMATIC = "prismatic"


@dataclass(frozen=True)
class Frame:
    """A named frame: ``parent`` (``None`` for the base) followed by ``transforms``."""

    name: str
    parent: str | None
    transforms: tuple[ElementaryTransform, ...]


@dataclass(frozen=True)
class BodyAttachment:
    """A rigid body whose inertial parameters are expressed in the frame ``frame``."""

    name: str
    frame: str


@dataclass
class Mechanism:
    """Independent coordinates, frames and bodies of a device.

    ``gravity`` is the gravitational acceleration vector in the base frame
    (seed 000 eq. 2.46: ``[0, 0, -g]``).
    """

    coordinates: tuple[str, ...]
    joint_types: tuple[JointType, ...]
    frames: tuple[Frame, ...]
    bodies: tuple[BodyAttachment, ...]
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    end_effector: str | None = None
    metadata: dict = field(default_factory=dict)
    loops: ClosedLoops = field(default_factory=ClosedLoops)
    """The closed loops (a tree's are the empty ones, the default)."""

    def __post_init__(self) -> None:
        names = [f.name for f in self.frames]
        if len(set(names)) != len(names):
            raise UserError("frame names must be unique")
        known = {"base"}
        for f in self.frames:
            if f.parent not in known and f.parent is not None:
                raise UserError(f"frame {f.name}: parent {f.parent!r} is not defined before it")
            known.add(f.name)
            for et in f.transforms:
                for k, _ in et.value.coefficients:
                    if not 0 <= k < self.n_dof:
                        raise UserError(f"frame {f.name}: coordinate index {k} out of range")
        for b in self.bodies:
            if b.frame not in known:
                raise UserError(f"body {b.name}: unknown frame {b.frame!r}")
        if self.end_effector is not None and self.end_effector not in known:
            raise UserError(f"unknown end-effector frame {self.end_effector!r}")
        self.loops.validate(self.coordinates, known)

    @property
    def n_dof(self) -> int:
        return len(self.coordinates)

    @property
    def n_actuated(self) -> int:
        """Independent (actuated) coordinates: all of them for a tree, fewer with passive joints."""
        return self.n_dof - len(self.loops.passive)

    @property
    def actuated_coordinates(self) -> tuple[str, ...]:
        return tuple(self.coordinates[k] for k in self.loops.actuated(self.n_dof))

    @property
    def body_names(self) -> tuple[str, ...]:
        return tuple(b.name for b in self.bodies)

    @cached_property
    def compiled(self) -> "CompiledMechanism":
        return CompiledMechanism.from_mechanism(self)

    def frame_pose(self, q: np.ndarray, frame: str) -> np.ndarray:
        """World pose (4x4) of a named frame at coordinates ``q``."""
        return self.compiled.frame_pose(np.asarray(q, dtype=float), frame)


UNFOLDED = "unfolded"
"""The node numbering with one node per elementary transform (:class:`CompiledMechanism`'s own arrays)."""
FOLDED = "folded"
"""The node numbering with the constant transforms folded into the nodes (``CompiledMechanism.tree``)."""


@dataclass(frozen=True)
class CompiledMechanism:
    """Flat arrays of the frame tree: one node per elementary transform.

    ``node_parent[n]`` is the previous node (``-1`` for the base), ``node_axis[n]`` the
    :class:`~hapticdesign.model.transforms.Axis` code, ``node_coef[n]`` and ``node_offset[n]`` the
    affine joint value, ``body_node[b]`` the node whose frame body ``b`` is attached to, and
    ``body_path[b]`` the variable nodes from the base to that body (padded with ``-1``).

    One device's frames are walked on two node numberings, each for its own job (:meth:`nodes`):

    - :data:`UNFOLDED`, these arrays, one node per elementary transform: the symbolic derivation and drawing, and
      the walks over many designs of one geometry, whose constant transforms differ from design to design so that
      none can be folded (the design batch, :mod:`hapticdesign.analysis.design_batch`, and the inverse kinematics,
      :mod:`hapticdesign.analysis.reach_kernel`, which one device shares with them as a batch of one);
    - :data:`FOLDED`, ``tree``, the same tree with its constant transforms folded into the variable nodes
      (:class:`~hapticdesign.model.walk.KinematicTree`): the walks of one geometry, fewer nodes per pose (forward
      kinematics, the loop solver of :mod:`hapticdesign.analysis.loops`, the dynamics and the simulation plant).

    Poses closed on either are the same; a kernel takes the closures on the numbering of the tree it walks.
    """

    n_dof: int
    node_parent: np.ndarray
    node_axis: np.ndarray
    node_coef: np.ndarray
    node_offset: np.ndarray
    frame_node: dict[str, int]
    body_node: np.ndarray
    body_path: np.ndarray
    gravity: np.ndarray
    prismatic: np.ndarray
    tree: KinematicTree

    @classmethod
    def from_mechanism(cls, mech: Mechanism) -> "CompiledMechanism":
        parent, axis, coef, offset = [], [], [], []
        frame_node: dict[str, int] = {"base": -1}
        for f in mech.frames:
            last = frame_node["base" if f.parent is None else f.parent]
            for et in f.transforms:
                parent.append(last)
                axis.append(int(et.axis))
                coef.append(et.value.dense(mech.n_dof))
                offset.append(float(et.value.offset))
                last = len(parent) - 1
            frame_node[f.name] = last
        node_coef = np.array(coef, dtype=float).reshape(len(parent), mech.n_dof)
        variable = np.any(node_coef != 0.0, axis=1)
        paths = []
        for b in mech.bodies:
            path, n = [], frame_node[b.frame]
            while n >= 0:
                if variable[n]:
                    path.append(n)
                n = parent[n]
            paths.append(path[::-1])
        width = max([len(p) for p in paths] + [1])
        body_path = -np.ones((len(paths), width), dtype=np.int64)
        for i, p in enumerate(paths):
            body_path[i, : len(p)] = p
        prismatic = np.array([t == JointType.PRISMATIC for t in mech.joint_types], dtype=bool)
        node_parent = np.array(parent, dtype=np.int64)
        node_axis = np.array(axis, dtype=np.int64)
        node_offset = np.array(offset, dtype=float)
        return cls(
            n_dof=mech.n_dof,
            node_parent=node_parent,
            node_axis=node_axis,
            node_coef=node_coef,
            node_offset=node_offset,
            frame_node=frame_node,
            body_node=np.array([frame_node[b.frame] for b in mech.bodies], dtype=np.int64),
            body_path=body_path,
            gravity=np.array(mech.gravity, dtype=float),
            prismatic=prismatic,
            tree=KinematicTree.fold(node_parent, node_axis, node_coef, node_offset, frame_node,
                                    [b.frame for b in mech.bodies]),
        )

    def nodes(self, numbering: str) -> dict[str, int]:
        """Frame name to the node it ends on (-1: the base) in ``numbering``, :data:`FOLDED` or :data:`UNFOLDED`."""
        return {UNFOLDED: self.frame_node, FOLDED: self.tree.frame_node}[numbering]

    def path_to(self, frame: str) -> list[int]:
        """Nodes from the base to ``frame``, in order."""
        if frame not in self.frame_node:
            raise UserError(f"unknown frame {frame!r}; frames: {', '.join(sorted(self.frame_node))}")
        path, n = [], self.frame_node[frame]
        while n >= 0:
            path.append(n)
            n = int(self.node_parent[n])
        return path[::-1]

    def frame_node_of(self, frame: str) -> int:
        """Node of the folded ``tree`` on which ``frame`` ends (-1: the base)."""
        if frame not in self.tree.frame_node:
            raise UserError(f"unknown frame {frame!r}; frames: {', '.join(sorted(self.tree.frame_node))}")
        return self.tree.frame_node[frame]

    def frame_pose(self, q: np.ndarray, frame: str) -> np.ndarray:
        """World pose (4x4) of ``frame`` at coordinates ``q`` (N,), by the compiled walk."""
        poses = np.empty((1, 4, 4))
        poses_and_jacobians(np.ascontiguousarray(q, dtype=float).reshape(1, -1), *self.tree.arrays,
                            self.frame_node_of(frame), False, poses, np.empty((1, 6, self.n_dof)))
        return poses[0]
