"""What ``rcube optimize``'s design explorer shows (seed 001 §7.1-7.2): the kinematic synthesis's designs, the final
populations of the bound sets' NSGA-II runs (the designs the runs kept; the runs keep no other), the merged front of
Table 7.2, the design selected by the weighted RMS of Table 7.5, and per front design its picture at home and the
commands that reproduce its numbers. The data is :func:`~hapticdesign.optimization.study_explorer.explorer_table`'s,
so the page is the one every study opens in (:func:`hapticdesign.interface.report.optimization_page.explorer_page`).
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.rcube.kinematics import chain_paths
from hapticdesign.analysis.view.skeleton import scale_length
from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.optimization.rcube.chain import ChainResult
from hapticdesign.optimization.rcube.constraints import CubeWorkspace, link1_length
from hapticdesign.optimization.rcube.objectives import OBJECTIVE_NAMES, geometry_of
from hapticdesign.optimization.rcube.synthesis import TOTAL_LENGTH_LIMIT
from hapticdesign.optimization.study_explorer import explorer_table, quantity
from hapticdesign.optimization.study_run import Record

OBJECTIVES = (
    ("1", "tan q_max (eq. 6.82)"),
    ("kg^3", "det M_C with two links folded (eq. 6.83)"),
    ("m^3/N^3", "1 / det K_CA fully extended (eq. 6.84)"),
)
"""The unit of each synthesis objective (``O1, O2, O3``, all minimized) and what it is."""
TITLE = "Modified R-CUBE: kinematic synthesis (seed 001 §7.1-7.2)"
FRONT_FILE = "table_7_2_front.csv"
"""The front's table the chain writes (in mm and degrees; the explorer shows SI units)."""
TOTAL = "l1 + l2 + l3"
"""The total link length, kept below :data:`~hapticdesign.optimization.rcube.synthesis.TOTAL_LENGTH_LIMIT` on the
front (§7.1)."""


def picture(geometry: RCubeGeometry) -> dict:
    """The design at home as the explorer draws a device (the shape of
    :func:`~hapticdesign.analysis.view.skeleton.snapshot`): each chain's links l1, l2, l3 as bars from its base to the
    platform (:func:`~hapticdesign.analysis.rcube.kinematics.chain_paths`), no masses."""
    paths = chain_paths(geometry)
    origins = {"origin": [0.0, 0.0, 0.0]}
    links, bars = [], []
    for k, path in enumerate(paths, start=1):
        names = [f"chain {k} base", f"chain {k} elbow 1", f"chain {k} elbow 2"]
        origins.update({name: [float(v) for v in p] for name, p in zip(names, path[:3])})
        links.append(["origin", names[0]])
        bars += [[[float(v) for v in a], [float(v) for v in b]] for a, b in zip(path[:-1], path[1:])]
    origins["platform"] = [float(v) for v in geometry.home]
    points = np.array([*origins.values()])
    return {"q": [], "origins": origins, "links": links, "bars": bars, "plates": [], "masses": [],
            "end_effector": "platform", "scale": scale_length(float(np.ptp(points, axis=0).max())),
            "where": "at home"}


def _record(x: np.ndarray, objectives: np.ndarray, workspace: CubeWorkspace, generation: int) -> Record:
    l1 = float(link1_length(x[0], workspace))
    values = {"q_max": float(x[0]), "l1": l1, "l2": float(x[1]), "l3": float(x[2])}
    return Record(generation, tuple(float(v) for v in x), values, tuple(float(v) for v in objectives),
                  (l1 + float(x[1]) + float(x[2]),), "", "", 0.0)


def _commands(geometry: RCubeGeometry) -> list[dict]:
    lengths = f"--l1 {geometry.l1!r} --l2 {geometry.l2!r} --l3 {geometry.l3!r}"
    return [{"what": "its metrics at home (seed 001 ch. 4)", "command": f"hapticdesign rcube metrics {lengths}"},
            {"what": "its ply optimization (§6.5, Tables 7.6-7.7)", "command": f"hapticdesign rcube plies {lengths}"}]


def chain_explorer(result: ChainResult, workspace: CubeWorkspace, bound_sets, generations: int) -> dict:
    """The explorer's data of the chain's synthesis: every design of the bound sets' final populations (``generations``
    the runs'), the merged front (Table 7.2's order), the selected design and each front design's card."""
    synthesis, selection = result.synthesis, result.selection
    records = [_record(x, f, workspace, generations) for front in synthesis.per_set for x, f in zip(front.X, front.F)]
    rows = [tuple(float(v) for v in x) for x in synthesis.front.X]
    first = {}
    for k, r in enumerate(records):
        first.setdefault(r.x, k)
    front = [first[row] for row in rows]
    low = [min(b.lower[k] for b in bound_sets) for k in range(3)]
    high = [max(b.upper[k] for b in bound_sets) for k in range(3)]
    l1 = sorted(float(v) for v in link1_length(np.array([low[0], high[0]]), workspace))
    variables = [quantity("q_max", "rad", low=low[0], high=high[0], choices=None),
                 quantity("l1", "m", low=l1[0], high=l1[1], choices=None),
                 quantity("l2", "m", low=low[1], high=high[1], choices=None),
                 quantity("l3", "m", low=low[2], high=high[2], choices=None)]
    objectives = [quantity(name, unit, index=name, reduce="", sense="min", about=f"minimize {about}")
                  for name, (unit, about) in zip(OBJECTIVE_NAMES, OBJECTIVES)]
    constraints = [quantity(TOTAL, "m", at_least=None, at_most=TOTAL_LENGTH_LIMIT)]
    designs = []
    for x in synthesis.front.X:
        geometry = geometry_of(x, workspace)
        designs.append({"file": None, "maps": {}, "picture": picture(geometry), "commands": _commands(geometry),
                        "spec": None})
    rule = (f"least weighted RMS of omega_nn* and mu_vn* (weight {selection.weight:g} on mu_vn*, seed 001 "
            "eq. 7.1-7.4, Table 7.5)")
    return explorer_table(TITLE, "rcube optimize", "the modified R-CUBE (seed 001)", variables, objectives,
                          constraints, records, front, {"position": selection.selected, "rule": rule}, designs,
                          front_file=FRONT_FILE, evaluations_file=None)
