"""Seed 000's linearization conditions of the 3-DOF Phantom (eq. 3.12-3.26) as printed, written out by hand."""

from __future__ import annotations


def seed_equations(p: dict, l2: float, l3a: float) -> dict:
    """Eq. 3.12-3.26 as printed (eq. 3.22 read as l3a^2 m2a: with the printed l4^2 m2a the conditions do not give LN = 0)."""
    p = dict(p)
    p["r2x"] = -(l2 * p["m2a"] + l2 * p["m3"] + p["m2a"] * p["r2ax"]) / p["m2"]
    p["r2y"] = p["r2ay"] = p["r3x"] = p["r3ax"] = 0.0
    p["r3az"] = (-l2 * l3a * p["m3a"] + l3a * p["m2a"] * p["r2ax"]) / (l2 * p["m3a"])
    p["r3z"] = -(l3a * p["m2a"] + l3a * p["m3a"] + p["m3a"] * p["r3az"]) / p["m3"]
    p["r3y"] = (-p["Iyz3"] - p["Iyz3a"] + l3a * p["m2a"] * p["r2az"] - l3a * p["m3a"] * p["r3ay"]
                - p["m3a"] * p["r3ay"] * p["r3az"]) / (p["m3"] * p["r3z"])
    p["r2z"] = (-p["Ixz2"] - p["Ixz2a"] - l2 * p["m2a"] * p["r2az"] - p["m2a"] * p["r2ax"] * p["r2az"]
                + l2 * p["m3"] * p["r3y"]) / (p["m2"] * p["r2x"])
    p["Iyy2a"] = (p["Ixx2"] + p["Ixx2a"] - p["Iyy2"] - l2**2 * p["m2a"] - l2**2 * p["m3"] - 2 * l2 * p["m2a"] * p["r2ax"]
                  - p["m2a"] * p["r2ax"] ** 2 - p["m2"] * p["r2x"] ** 2)
    p["Izz3a"] = (p["Ixx3"] + p["Ixx3a"] - p["Izz3"] + l3a**2 * p["m2a"] + l3a**2 * p["m3a"] + 2 * l3a * p["m3a"] * p["r3az"]
                  + p["m3a"] * p["r3az"] ** 2 + p["m3"] * p["r3z"] ** 2)
    p["Ixy2"], p["Iyz2"], p["Ixy3"], p["Ixz3"] = -p["Ixy2a"], -p["Iyz2a"], -p["Ixy3a"], -p["Ixz3a"]
    return p
