"""Phantom Premium 1.5 presets, 3 and 6 DOF (seed 000, Tables 2.1-2.5, eq. 2.38-2.43).

Frames: ``body<i>`` carries link i's inertial parameters in the seed's convention (origin
``P_{i-1}``, orientation ``C(0,i)``), ``link<i>`` is DH frame i. The parallelogram links:
link 2a has link 2's orientation and origin ``P_2a = P_2 + l3a C(0,3) u3``; link 3a has link 3's
orientation and origin ``P_3a = P_2a - l2a C(0,2) u1`` (eq. 2.38-2.39);
their mass centres are ``P_2a + C(0,2) r_2a`` and ``P_3a + C(0,3) r_3a`` (eq. 2.31-2.32).
As elementary transforms: ``2a = link2 . Rz(q3) Rx(-pi/2) tz(l3a) Rx(pi/2) Rz(-q3)`` and
``3a = 2a . tx(-l2a) Rz(q3) Rx(-pi/2)`` (the dependent angle ``-q3`` undoes the rotation).

Default inertial parameters of links 1-3: the exactly linear, physically consistent variant of
the seed's example design (eq. 3.33; as printed it has LN = 1.18e-6 and link 2 breaks the triangle
inequality): eq. 3.33's free values with
``r2x, r3z, r3az, Iyy2a, Izz3a`` solved exactly from eq. 3.12-3.26 and ``Ixx2`` lowered from
0.00982641 to 0.00975562 so that link 2 meets the triangle inequality.

Default gimbal (6 DOF, our choice, physically consistent, documented in the README): link 4 a
10 g yoke with its mass centre at the gimbal centre ``P_4`` (``r4 = (0, l3, 0)`` in frame 4,
because ``C(0,3) u3 = C(0,4) u2``) and moments 2e-6 kg m^2; link 5 an 8 g ring centred at
``P_4`` with moments 1e-6 kg m^2; link 6 a 12 g, 30 mm stylus along ``u3`` of frame 6 with
its mass centre 15 mm out (moments 9e-7, 9e-7, 5e-8 kg m^2, a slender rod).

What the generic engines read from the presets (:class:`~hapticdesign.model.device.PresetData`): the practical
bounds of links 2, 3, 2a and 3a (eq. 3.29-3.32) and ours of the gimbal's, the seed's dependent variables of LN = 0
(eq. 3.12-3.26) with their pivots, and the seed's loop settings as the commands' default.
"""

from __future__ import annotations

from collections.abc import Mapping
from math import pi

from hapticdesign.model.device import Device, PresetData
from hapticdesign.model.dh import dh_frames, revolute
from hapticdesign.model.mechanism import BodyAttachment, Frame, JointType, Mechanism
from hapticdesign.model.transforms import Rx, Rz, joint, tx, tz

LENGTHS_3DOF = {"l1": 0.300, "l2": 0.215, "l3": 0.170, "l2a": 0.215, "l3a": 0.0325}
LENGTHS_6DOF = {**LENGTHS_3DOF, "l5": 0.0, "l6": 0.030}
GRAVITY = {"g": 9.81}

LINEAR_DESIGN_3DOF: dict[str, float] = {
    "m1": 0.25, "r1z": 0.15, "Ixx1": 0.009, "Iyy1": 0.009, "Izz1": 0.00015,
    "m2": 0.156, "r2x": -0.0915576923, "Ixx2": 0.00975562, "Iyy2": 0.00488281, "Izz2": 0.00488281,
    "m2a": 0.026, "r2ax": 0.078, "Ixx2a": 0.00488281, "Iyy2a": 0.0047828525, "Izz2a": 0.00488281,
    "m3": 0.031, "r3z": -0.0371470368, "Ixx3": 0.00481407, "Iyy3": 0.00488281, "Izz3": 0.00488281,
    "m3a": 0.242, "r3az": -0.0312332308, "Ixx3a": 0.00488281, "Iyy3a": 0.00488281, "Izz3a": 0.0048846978,
}

GIMBAL_DEFAULT: dict[str, float] = {
    "m4": 0.010, "r4y": 0.170, "Ixx4": 2e-6, "Iyy4": 2e-6, "Izz4": 2e-6,
    "m5": 0.008, "Ixx5": 1e-6, "Iyy5": 1e-6, "Izz5": 1e-6,
    "m6": 0.012, "r6z": 0.015, "Ixx6": 9e-7, "Iyy6": 9e-7, "Izz6": 5e-8,
}


def _arm_frames(p: Mapping[str, float]) -> list[Frame]:
    rows = [
        revolute(0.0, -pi / 2, p["l1"], 0),
        revolute(p["l2"], 0.0, 0.0, 1),
        revolute(0.0, -pi / 2, 0.0, 2),
    ]
    frames = dh_frames(rows, ["1", "2", "3"])
    frames.append(
        Frame("body2a", "link2", (Rz(joint(2)), Rx(-pi / 2), tz(p["l3a"]), Rx(pi / 2), Rz(joint(2, -1.0))))
    )
    frames.append(Frame("body3a", "body2a", (tx(-p["l2a"]), Rz(joint(2)), Rx(-pi / 2))))
    return frames


def _bodies(names: list[str]) -> tuple[BodyAttachment, ...]:
    return tuple(BodyAttachment(n, f"body{n}") for n in names)


def phantom_3dof_mechanism(p: Mapping[str, float]) -> Mechanism:
    frames = _arm_frames(p)
    frames.append(Frame("stylus", "link3", (tz(p["l3"]),)))
    return Mechanism(
        coordinates=("theta1", "theta2", "theta3"),
        joint_types=(JointType.REVOLUTE,) * 3,
        frames=tuple(frames),
        bodies=_bodies(["1", "2", "2a", "3", "3a"]),
        gravity=(0.0, 0.0, -p["g"]),
        end_effector="stylus",
    )


def phantom_6dof_mechanism(p: Mapping[str, float]) -> Mechanism:
    frames = _arm_frames(p)
    rows = [
        revolute(0.0, pi / 2, p["l3"], 3),
        revolute(0.0, -pi / 2, 0.0, 4, offset=-pi / 2),
        revolute(0.0, 0.0, p["l5"], 5),
    ]
    frames += dh_frames(rows, ["4", "5", "6"], parent="link3")
    frames.append(Frame("stylus", "link6", (tz(p["l6"]),)))
    return Mechanism(
        coordinates=tuple(f"theta{i}" for i in range(1, 7)),
        joint_types=(JointType.REVOLUTE,) * 6,
        frames=tuple(frames),
        bodies=_bodies(["1", "2", "2a", "3", "3a", "4", "5", "6"]),
        gravity=(0.0, 0.0, -p["g"]),
        end_effector="stylus",
    )


def _arm_bounds(heavy: tuple[float, float], light: tuple[float, float]) -> dict:
    r, moments = (-0.25, 0.25), (1e-5, 1e-2)
    return {"2": (heavy, r, moments, 1e-2), "3a": (heavy, r, moments, 1e-2),
            "2a": (light, r, moments, 1e-2), "3": (light, r, moments, 1e-2)}


# Eq. 3.29-3.32 (= eq. 3.35-3.38): link 2 and 3a heavy, link 2a and 3 light.
ARM_BOUNDS = _arm_bounds((0.15, 0.30), (0.02, 0.15))
# Our practical bounds for the gimbal links (not in the seed): 5-50 g, moments 1e-7..1e-3 kg m^2.
GIMBAL_BOUNDS = {b: ((0.005, 0.05), (-0.25, 0.25), (1e-7, 1e-3), 1e-3) for b in ("4", "5", "6")}
# The seed's dependent variables (eq. 3.12-3.26) and the standard parameters used as pivots for them (r2z enters
# through J2xz = -Ixz2 - m2 r2x r2z, r3y through J3yz).
SEED_DEPENDENTS = ("r2x", "r2y", "r2z", "r2ay", "r3x", "r3y", "r3z", "r3ax", "r3az",
                   "Iyy2a", "Izz3a", "Ixy2", "Iyz2", "Ixy3", "Ixz3")
SEED_PIVOTS = ("h2x", "h2y", "J2xz", "h2ay", "h3x", "J3yz", "h3z", "h3ax", "h3az",
               "J2ayy", "J3azz", "J2xy", "J2yz", "J3xy", "J3xz")
# The seed's presets keep the seed's loop settings and performance criteria by default.
DATA_3DOF = PresetData("seed", ARM_BOUNDS, SEED_DEPENDENTS, SEED_PIVOTS)
DATA_6DOF = PresetData("seed", {**ARM_BOUNDS, **GIMBAL_BOUNDS})


def _complete(device: Device, values: Mapping[str, float], data: PresetData) -> Device:
    base = {name: 0.0 for name in device.parameter_names()}
    base.update(values)
    return Device(device.name, device.description, device.kinematic, device.builder, base, device.damping,
                  preset_data=data)


def phantom_3dof() -> Device:
    kin = {**LENGTHS_3DOF, **GRAVITY}
    skeleton = Device(
        "phantom-3dof",
        "Phantom Premium 1.5, 3 DOF with parallelogram (seed 000 Tables 2.1-2.3)",
        tuple(kin),
        phantom_3dof_mechanism,
        kin,
        damping=(0.50, 0.50, 0.35),
    )
    return _complete(skeleton, {**kin, **LINEAR_DESIGN_3DOF}, DATA_3DOF)


def phantom_6dof() -> Device:
    kin = {**LENGTHS_6DOF, **GRAVITY}
    skeleton = Device(
        "phantom-6dof",
        "Phantom Premium 1.5, 6 DOF with gimbal (seed 000 Tables 2.1-2.5)",
        tuple(kin),
        phantom_6dof_mechanism,
        kin,
        damping=(0.50, 0.50, 0.35, 0.01, 0.01, 0.01),
    )
    return _complete(skeleton, {**kin, **LINEAR_DESIGN_3DOF, **GIMBAL_DEFAULT}, DATA_6DOF)
