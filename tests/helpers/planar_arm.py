"""A planar two-link arm (shoulder q1, elbow q2 + elbow offset) in the base x-z plane, as a device-file mapping.

Its home pose (q = 0) has the elbow at ``elbow`` (rad), away from the stretched-out singularity; the links carry
aluminium tubes and the joints motors, so every kind of design variable has something to change.
"""

from __future__ import annotations

import math


def planar_arm(l1: float = 0.2, l2: float = 0.2 / math.sqrt(2.0), elbow: float = 3 * math.pi / 4,
               link_bodies: bool = False) -> dict:
    """The device-file mapping of the arm (lengths in m, ``elbow`` the elbow angle at home in rad); with
    ``link_bodies`` its two bodies are the links' tube and rod (``bodies: - {name: 1, link: upper}``)."""
    arm = {
        "name": "planar-arm",
        "parameters": {"l1": l1, "l2": l2, "e": elbow},
        "joints": [{"name": "q1"}, {"name": "q2"}],
        "frames": [
            {"name": "upper", "transforms": [{"Rx": "pi/2"}, {"Rz": "q1"}]},
            {"name": "elbow", "parent": "upper", "transforms": [{"tx": "l1"}]},
            {"name": "lower", "parent": "elbow", "transforms": [{"Rz": "q2"}, {"Rz": "e"}]},
            {"name": "tip", "parent": "lower", "transforms": [{"tx": "l2"}]},
        ],
        "end_effector": "tip",
        "bodies": [
            {"name": "1", "frame": "upper", "m": 0.3, "rx": l1 / 2, "Ixx": 1e-5, "Iyy": 0.3 * l1**2 / 12 + 0.3 * l1**2 / 4,
             "Izz": 0.3 * l1**2 / 12 + 0.3 * l1**2 / 4},
            {"name": "2", "frame": "lower", "m": 0.2, "rx": l2 / 2, "Ixx": 1e-5, "Iyy": 0.2 * l2**2 / 3,
             "Izz": 0.2 * l2**2 / 3},
        ],
        "actuators": [{"joint": "q1", "rotor_inertia": 1e-6, "gear_ratio": 10.0, "torque_continuous": 0.03},
                      {"joint": "q2", "rotor_inertia": 2e-6, "gear_ratio": 8.0, "torque_continuous": 0.02}],
        "links": [{"name": "upper", "from": "upper", "to": "elbow", "section": {"shape": "tube", "D": 0.012, "d": 0.010},
                   "material": "aluminium_6061"},
                  {"name": "lower", "from": "lower", "to": "tip", "section": {"shape": "rod", "D": 0.008},
                   "material": "aluminium_6061"}],
    }
    if link_bodies:
        arm["bodies"] = [{"name": "1", "link": "upper"}, {"name": "2", "link": "lower"}]
    return arm


def reaches(l1: float, l2: float, point) -> bool:
    """Whether the two-link arm (links ``l1``, ``l2``, joints free) reaches ``point`` (x, y, z; m) of its x-z plane: the
    closed form ``|l1 - l2| <= r <= l1 + l2``, ``r`` the point's distance from the shoulder (at the origin)."""
    x, y, z = (float(v) for v in point)
    r = math.hypot(x, z)
    return abs(y) < 1e-12 and abs(l1 - l2) <= r <= l1 + l2


def points_reached(l1: float, l2: float, points) -> int:
    """How many of ``points`` the two-link arm reaches (:func:`reaches`)."""
    return sum(reaches(l1, l2, p) for p in points)
