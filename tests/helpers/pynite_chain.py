"""An independent finite-element oracle for link compliance: a clamped chain of 3D beams in PyNiteFEA."""

from __future__ import annotations

import numpy as np
from Pynite import FEModel3D

LOADS = ("FX", "FY", "FZ", "MX", "MY", "MZ")


def chain_compliance(points, sections, materials) -> np.ndarray:
    """The 6 x 6 compliance at the last node of a chain of beams through ``points``, clamped at the first: column k is
    the node's (DX, DY, DZ, RX, RY, RZ) under a unit load k of :data:`LOADS`. ``sections``: (A, I, J) per beam (the
    same I about both axes), ``materials``: (E, G) per beam."""
    fe = FEModel3D()
    names = [f"n{k}" for k in range(len(points))]
    for name, p in zip(names, points):
        fe.add_node(name, *map(float, p))
    for k, ((A, I, J), (E, G)) in enumerate(zip(sections, materials)):
        fe.add_section(f"s{k}", A, I, I, J)
        fe.add_material(f"m{k}", E, G, 0.3, 1000.0)
        fe.add_member(f"b{k}", names[k], names[k + 1], f"m{k}", f"s{k}")
    fe.def_support(names[0], True, True, True, True, True, True)
    for load in LOADS:
        fe.add_node_load(names[-1], load, 1.0, case=load)
        fe.add_load_combo(load, {load: 1.0})
    fe.analyze_linear()
    n = fe.nodes[names[-1]]
    return np.column_stack([[n.DX[c], n.DY[c], n.DZ[c], n.RX[c], n.RY[c], n.RZ[c]] for c in LOADS])
