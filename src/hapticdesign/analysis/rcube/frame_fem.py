"""Finite-element check of the R-CUBE's VJM stiffness with a 3D beam frame (seed 001 §5.2.5, ch. 8).

The seed verified its virtual-joint model against ANSYS Workbench (§5.2.5, Fig. 5.10). Here the
three chains become a frame of Euler-Bernoulli beams in PyNiteFEA, built by walking the same chain
description the VJM differentiates (:func:`hapticdesign.model.rcube.stiffness_chain_mechanism`,
eq. 5.77-5.81) at its undeflected pose:

- a constant translation after the actuated joint is a link: one beam member from where the link
  starts to the virtual joint that lumps its compliance in the VJM (eq. 5.75); its section is the
  link's tube (eq. 5.162-5.165), bent with the laminate's axial modulus ``E_x`` and twisted with
  ``G_xy`` (eq. 5.179, 5.181);
- a passive revolute joint (``phi2..phi5``, eq. 5.13-5.14) is a moment release about its axis at
  the end of the adjacent member (the node between two coincident joints plays the cross of the
  universal joint ``phi2, phi3``);
- the actuated joint ``q_i1`` is locked: the link-1 root is clamped;
- the three chains end at one node, the platform point (a rigid platform of zero size, as eq. 5.123
  assumes when it adds the chains' stiffnesses at one point).

``K_C`` follows from six unit load cases at the platform node (the compliance's columns).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from math import atan2, degrees

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.files import save_figure
from hapticdesign.analysis.rcube.design import RCubeDesign
from hapticdesign.analysis.rcube.kinematics import inverse_kinematics, require_regular
from hapticdesign.model.mechanism import Mechanism
from hapticdesign.model.rcube import ACTIVE_INDEX, N_VIRTUAL, stiffness_chain_mechanism, stiffness_coordinates
from hapticdesign.model.transforms import Axis, elementary_matrix

PLATFORM = "platform"
LOAD_DIRECTIONS = ("FX", "FY", "FZ", "MX", "MY", "MZ")
_GEOMETRY_TOLERANCE = 1e-9


@dataclass
class Member:
    """A beam from node ``i`` to node ``j`` for link ``link`` (0, 1, 2) of chain ``chain``.

    ``release_i`` / ``release_j``: the axis (unit 3-vector, base frame) of a passive revolute joint
    at that end, or ``None`` (rigid connection).
    """

    name: str
    i: str
    j: str
    chain: int
    link: int
    release_i: np.ndarray | None = None
    release_j: np.ndarray | None = None


@dataclass
class FrameModel:
    """Nodes (name -> base-frame position, m), beams and clamped nodes of the R-CUBE frame."""

    nodes: dict[str, np.ndarray] = field(default_factory=dict)
    members: list[Member] = field(default_factory=list)
    supports: list[str] = field(default_factory=list)


def _coordinate_kind(index: int) -> str:
    """``virtual``, ``passive`` or ``active`` for a coordinate index of eq. 5.86."""
    if index < N_VIRTUAL:
        return "virtual"
    return "active" if index == ACTIVE_INDEX else "passive"


def _walk(mech: Mechanism, Q: np.ndarray, frame: str):
    """Yield ``(axis, coordinate index or None, value, pose after the transform)`` along ``frame``."""
    c = mech.compiled
    T = np.eye(4)
    for n in c.path_to(frame):
        axis = Axis(int(c.node_axis[n]))
        used = np.flatnonzero(c.node_coef[n])
        value = float(c.node_offset[n] + c.node_coef[n] @ Q)
        T = T @ elementary_matrix(axis, value)
        yield axis, (int(used[0]) if len(used) else None), value, T


class _ChainBuilder:
    """Turns one chain's transform walk into nodes, members and releases (see the module docstring)."""

    def __init__(self, model: FrameModel, chain: int, end_node: str) -> None:
        self.model, self.chain, self.end_node = model, chain, end_node
        self.point: str | None = None
        self.start = np.zeros(3)
        self.incoming: Member | None = None
        self.pending: list[np.ndarray] = []

    def ground(self, T: np.ndarray) -> None:
        """The actuated joint (locked): a clamped node where the chain leaves its base."""
        self.point = self._node(T[:3, 3], f"c{self.chain}_base")
        self.model.supports.append(self.point)
        self.start = T[:3, 3].copy()

    def link_end(self, T: np.ndarray, link: int) -> None:
        """A virtual joint: the link that started at the last node ends here (eq. 5.75-5.81)."""
        end = T[:3, 3]
        if np.linalg.norm(end - self.start) < _GEOMETRY_TOLERANCE:
            return
        name = f"c{self.chain}_l{link + 1}"
        j = self._node(end, f"c{self.chain}_tip{link + 1}")
        member = Member(name, self.point, j, self.chain, link)
        if self.pending:
            member.release_i = self._single(self.pending, name)
            self.pending = []
        self.model.members.append(member)
        self.point, self.incoming, self.start = j, member, end.copy()

    def passive_joint(self, axis: np.ndarray) -> None:
        """A passive revolute joint: released at the incoming member's end when free, else at the next start."""
        m = self.incoming
        if m is not None and m.release_j is None and not self.pending:
            m.release_j = axis
        else:
            self.pending.append(axis)

    def finish(self, T: np.ndarray) -> None:
        if self.pending:
            raise UserError(f"chain {self.chain + 1}: passive joints after the last link cannot be modelled")
        if np.linalg.norm(T[:3, 3] - self.model.nodes[self.point]) > _GEOMETRY_TOLERANCE:
            raise UserError(f"chain {self.chain + 1}: a constant offset after the last link has no beam")

    def _single(self, axes: list[np.ndarray], name: str) -> np.ndarray:
        if len(axes) > 1:
            raise UserError(f"{name}: more than two coincident passive joints cannot be released on one beam end")
        return axes[0]

    def _node(self, position: np.ndarray, name: str) -> str:
        if name.endswith("tip3"):
            name = self.end_node
        nodes = self.model.nodes
        if name in nodes:
            if np.linalg.norm(nodes[name] - position) > 1e-7:
                raise UserError(f"the chains do not meet at the platform (gap {np.linalg.norm(nodes[name] - position):.3g} m)")
            return name
        nodes[name] = np.asarray(position, dtype=float).copy()
        return name


def chain_frame(model: FrameModel, mech: Mechanism, chain: int, Q: np.ndarray) -> None:
    """Add chain ``chain`` (its stiffness mechanism at coordinates ``Q``, eq. 5.86) to ``model``."""
    b = _ChainBuilder(model, chain, PLATFORM)
    T_last = np.eye(4)
    for axis, index, value, T in _walk(mech, Q, mech.end_effector):
        kind = None if index is None else _coordinate_kind(index)
        if kind == "active":
            b.ground(T)
        elif kind == "virtual" and index % 6 == 0:
            b.link_end(T, index // 6)
        elif kind == "passive" and axis.is_rotation:
            b.passive_joint(T[:3, axis.unit].copy())
        elif kind is None and not axis.is_rotation and value != 0.0 and b.point is not None:
            pass  # a link's length: the member is created at the link's virtual joint
        T_last = T
    b.finish(T_last)


def frame_model(design: RCubeDesign, position) -> FrameModel:
    """The R-CUBE as a beam frame at a platform position (undeflected pose, eq. 5.30-5.45)."""
    if not getattr(design, "rigid_joints", True):
        raise UserError("the beam frame models ideal joints (actuated locked, passive free); joint springs are not modelled")
    r = np.asarray(position, dtype=float)
    q = inverse_kinematics(design.geometry, r)
    require_regular(design.geometry, q)
    model = FrameModel()
    for i in range(3):
        mech = stiffness_chain_mechanism(design.geometry, i, design.centres)
        chain_frame(model, mech, i, stiffness_coordinates(q[i]))
    return model


def _local_axes(member) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """PyNite's local x, y, z of a member (rows of its direction-cosine matrix)."""
    D = member.T()[:3, :3]
    return D[0], D[1], D[2]


def _orient(member, axis: np.ndarray) -> None:
    """Rotate the member about its local x so that its local z is ``axis`` (perpendicular to it)."""
    x, y, z = _local_axes(member)
    if abs(float(np.dot(axis, x))) > 1e-9:
        raise UserError(f"member {member.name}: a joint axis not perpendicular to the beam cannot be released")
    member.rotation = degrees(atan2(-float(np.dot(axis, y)), float(np.dot(axis, z))))


def _release_flags(member, spec: Member) -> list[bool]:
    """PyNite release flags: the moment about each joint axis (local z or y) at that end."""
    first = spec.release_i if spec.release_i is not None else spec.release_j
    if first is not None:
        _orient(member, first)
    x, y, z = _local_axes(member)
    flags = [False] * 12
    for offset, a in ((0, spec.release_i), (6, spec.release_j)):
        if a is None:
            continue
        if abs(abs(float(np.dot(a, z))) - 1.0) < 1e-9:
            flags[offset + 5] = True
        elif abs(abs(float(np.dot(a, y))) - 1.0) < 1e-9:
            flags[offset + 4] = True
        else:
            raise UserError(f"member {spec.name}: the two joint axes at its ends are neither parallel nor perpendicular")
    return flags


def pynite_model(design: RCubeDesign, frame: FrameModel):
    """A PyNiteFEA ``FEModel3D`` of ``frame`` with the design's tubes and moduli (``E_x``, ``G_xy``)."""
    from Pynite import FEModel3D

    fe = FEModel3D()
    for name, p in frame.nodes.items():
        fe.add_node(name, *map(float, p))
    for k, link in enumerate(design.links):
        s, m = link.section, link.moduli
        fe.add_section(f"tube{k + 1}", s.area, s.second_moment, s.second_moment, s.polar_moment)
        fe.add_material(f"link{k + 1}", m.E_x, m.G_xy, 0.3, link.density)  # nu enters plates only
    for spec in frame.members:
        fe.add_member(spec.name, spec.i, spec.j, f"link{spec.link + 1}", f"tube{spec.link + 1}")
        fe.members[spec.name].Releases = _release_flags(fe.members[spec.name], spec)
    for name in frame.supports:
        fe.def_support(name, True, True, True, True, True, True)
    return fe


def _unit_load_cases(fe, node: str) -> None:
    for d in LOAD_DIRECTIONS:
        fe.add_node_load(node, d, 1.0, case=d)
        fe.add_load_combo(d, {d: 1.0})


def _node_displacements(fe, node: str, combo: str) -> np.ndarray:
    n = fe.nodes[node]
    return np.array([n.DX[combo], n.DY[combo], n.DZ[combo], n.RX[combo], n.RY[combo], n.RZ[combo]])


def platform_compliance(design: RCubeDesign, position, releases: bool = True) -> np.ndarray:
    """6 x 6 compliance of the platform node from six unit load cases, linear analysis.

    ``releases=False`` locks the passive joints too (the FE counterpart of eq. 6.60-6.61).
    """
    frame = frame_model(design, position)
    if not releases:
        for m in frame.members:
            m.release_i = m.release_j = None
    fe = pynite_model(design, frame)
    _unit_load_cases(fe, PLATFORM)
    fe.analyze_linear(check_stability=True)
    return np.column_stack([_node_displacements(fe, PLATFORM, d) for d in LOAD_DIRECTIONS])


def fe_stiffness(design: RCubeDesign, position, releases: bool = True) -> np.ndarray:
    """``K_C`` of the beam frame at the platform point: the inverse of :func:`platform_compliance`."""
    return np.linalg.inv(platform_compliance(design, position, releases))


SEED_TEST_ANGLES = np.radians([
    [30, -30, 30], [0, -30, 30], [30, -30, -30], [0, -30, -30], [0, 0, 30],
    [0, 30, 30], [0, 0, -30], [-30, -30, -30], [0, 0, 0], [30, 30, 30],
])
"""Active angles ``q_11, q_21, q_31`` of the seed's ANSYS test points TP1-TP10 (Table 5.2)."""

SEED_LOAD_SIGNS = np.array([
    [1, 1, 1], [1, 1, -1], [1, -1, 1], [1, -1, -1], [-1, 1, 1], [-1, 1, -1], [-1, -1, 1], [-1, -1, -1],
])
"""Signs of the +-5 N load combinations LC1-LC8 of Table 5.1: all eight sign combinations, as its text
says; the printed LC7 repeats LC5 (+5 N along u2), evidently for -5 N."""


def seed_test_positions(design: RCubeDesign) -> np.ndarray:
    """Platform positions of Table 5.2's test points for this design (eq. 5.28), ``(10, 3)``."""
    from hapticdesign.analysis.rcube.kinematics import forward_kinematics

    return forward_kinematics(design.geometry, SEED_TEST_ANGLES)


@dataclass(frozen=True)
class Agreement:
    """VJM and FE at one position: ``K_C`` of both, the relative differences of its translational
    (N/m) and rotational (N m/rad) blocks (eq. 6.54, Frobenius norm) and the platform deflections
    (m) under ``load`` N along x, y and z (rows)."""

    position: np.ndarray
    K_vjm: np.ndarray
    K_fe: np.ndarray
    deflection_vjm: np.ndarray
    deflection_fe: np.ndarray

    @property
    def translational_difference(self) -> float:
        return _block_difference(self.K_fe[:3, :3], self.K_vjm[:3, :3])

    @property
    def rotational_difference(self) -> float:
        return _block_difference(self.K_fe[3:, 3:], self.K_vjm[3:, 3:])

    @property
    def deflection_difference(self) -> float:
        """Largest ``|d_FE - d_VJM| / |d_VJM|`` over the three load directions (translations)."""
        num = np.linalg.norm(self.deflection_fe[:, :3] - self.deflection_vjm[:, :3], axis=1)
        return float(np.max(num / np.linalg.norm(self.deflection_vjm[:, :3], axis=1)))


def _block_difference(fe: np.ndarray, vjm_block: np.ndarray) -> float:
    return float(np.linalg.norm(fe - vjm_block) / np.linalg.norm(vjm_block))


def compare(design: RCubeDesign, position, load: float = 20.0, locked: bool = False) -> Agreement:
    """VJM ``K_C`` (eq. 5.121-5.123; ``locked``: eq. 6.60-6.61) against the beam frame at one position,
    and the deflections ``K_C^-1 F`` under ``load`` N along each axis (the seed's 20 N, §6.6)."""
    from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness

    r = np.asarray(position, dtype=float)
    K_vjm = cartesian_stiffness(design, r, passive=not locked)
    C_fe = platform_compliance(design, r, releases=not locked)
    F = np.zeros((3, 6))
    F[:, :3] = load * np.eye(3)
    return Agreement(r, K_vjm, np.linalg.inv(C_fe), np.linalg.solve(K_vjm, F.T).T, (C_fe @ F.T).T)


def seed_load_deflections(agreement: Agreement, magnitude: float = 5.0) -> tuple[np.ndarray, np.ndarray]:
    """``|deflection|`` (m) of VJM and FE under Table 5.1's +-5 N combinations, ``(8,)`` each."""
    F = np.zeros((len(SEED_LOAD_SIGNS), 6))
    F[:, :3] = magnitude * SEED_LOAD_SIGNS
    d_vjm = np.linalg.solve(agreement.K_vjm, F.T).T[:, :3]
    d_fe = np.linalg.solve(agreement.K_fe, F.T).T[:, :3]
    return np.linalg.norm(d_vjm, axis=1), np.linalg.norm(d_fe, axis=1)


def save_correlation_figure(agreements: list[Agreement], path) -> None:
    """FE against VJM deflection under Table 5.1's loads at each position (the seed's Fig. 5.10)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.0, 4.5))
    top = 0.0
    for k, a in enumerate(agreements):
        d_vjm, d_fe = seed_load_deflections(a)
        ax.plot(d_vjm * 1e3, d_fe * 1e3, "o", ms=4, label=f"pose {k + 1}")
        top = max(top, d_vjm.max() * 1e3, d_fe.max() * 1e3)
    ax.plot([0, top], [0, top], "k-", lw=0.8, label="FE = VJM")
    ax.set_xlabel("VJM deflection |K_C^-1 F| [mm]")
    ax.set_ylabel("PyNiteFEA beam-frame deflection [mm]")
    ax.set_title("R-CUBE: FE vs VJM under the ±5 N loads of Table 5.1", fontsize=9)
    ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    save_figure(fig, path, dpi=150)
    plt.close(fig)
