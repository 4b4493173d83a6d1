"""The phantom study's campaign in the design explorer (seed 000 §3.2.2, §4.1.4, §4.2.4): every design of the design
sets with its LN and its rendering results, LN against the maximum stable impedance K_max (type 1) as the two
objectives (LN the least, K_max the largest), their front, and per front design its picture at home, its spec
summary, its parameters as a file (``designs/design-N.json``, the seed's names, as ``--params`` reads them) and the
commands that reproduce its numbers."""

from __future__ import annotations

import json
import warnings

import numpy as np

from hapticdesign.analysis.view.skeleton import home_pose, snapshot
from hapticdesign.devices.registry import preset
from hapticdesign.errors import PhysicalConsistencyWarning, UserError
from hapticdesign.optimization.pymoo_run import pareto_filter
from hapticdesign.optimization.study_explorer import explorer_table, quantity
from hapticdesign.optimization.study_run import Record
from hapticdesign.simulation.campaign import Design
from hapticdesign.studies.spec import spec_summary
from hapticdesign.studies.steps import Explorer

TITLE = "Phantom design sets: LN against the maximum stable impedance (seed 000 §3.2.2, §4.1.4)"
RESULTS = (("impedance", 2, "K_max type 2", "N m/rad"), ("transparency", 1, "bandwidth type 1", "Hz"),
           ("transparency", 2, "bandwidth type 2", "Hz"))
"""The campaign's other results shown beside the objectives: (criterion, type, name, unit)."""


def _unit(name: str) -> str:
    """The unit of a seed inertial parameter: a mass, a mass centre's coordinate or an inertia."""
    return "kg" if name.startswith("m") else "m" if name.startswith("r") else "kg m^2"


def _value(case: dict) -> float:
    return float("nan") if case["value"] is None else float(case["value"])


def campaign_explorer(designs: list[Design], cases: dict, preset_name: str) -> Explorer:
    """The explorer of a campaign over ``designs`` (:func:`~hapticdesign.simulation.campaign.read_designs`) with its
    ``cases`` (:func:`~hapticdesign.simulation.campaign.load_cases`) on the preset ``preset_name``: the parameters
    that differ between the designs and the LN level as variables, LN and K_max (type 1) as objectives, the other
    results (K_max type 2, the transparency bandwidths; a bandwidth above the chirp's 15 Hz has no number) beside
    them; the front (the least LN for the largest K_max) in order of LN, the design of the largest K_max on it
    selected."""
    names = [n for n in designs[0].params if len({d.params[n] for d in designs}) > 1]
    records = []
    for d in designs:
        values = {"level": float(d.level), **{n: float(d.params[n]) for n in names}}
        objectives = (float(d.meta["ln"]), _value(cases[(d.name, "impedance", 1)]))
        results = tuple(_value(cases[(d.name, c, t)]) for c, t, _, _ in RESULTS)
        records.append(Record(1, tuple(values.values()), values, objectives, results, "", "", 0.0))
    F = np.array([[r.objectives[0], -r.objectives[1]] for r in records])
    finite = np.flatnonzero(np.isfinite(F).all(axis=1))
    front = sorted((int(finite[k]) for k in pareto_filter(np.array([r.x for r in records])[finite], F[finite])),
                   key=lambda k: (records[k].objectives[0], k))
    if not front:
        raise UserError("no design of the campaign has a maximum stable impedance: nothing to explore")
    position = max(range(len(front)), key=lambda n: (records[front[n]].objectives[1], -n))
    variables = [quantity("level", "1", low=min(d.level for d in designs), high=max(d.level for d in designs),
                          choices=None)]
    variables += [quantity(n, _unit(n), low=min(d.params[n] for d in designs), high=max(d.params[n] for d in designs),
                           choices=None) for n in names]
    objectives = [quantity("LN", "1", index="ln", reduce="", sense="min", about="minimize the Linearity Number (eq. 3.1-3.4)"),
                  quantity("K_max type 1", "N m/rad", index="impedance", reduce="", sense="max",
                           about="maximize the maximum stable impedance, type 1 (§4.1)")]
    results = [quantity(name, unit, at_least=None, at_most=None, role="result") for _, _, name, unit in RESULTS]
    files, cards = {}, []
    for n, k in enumerate(front, start=1):
        design = designs[k]
        file = f"designs/design-{n}.json"
        files[file] = json.dumps(design.params, indent=1) + "\n"
        cards.append(_card(preset_name, design, file))
    data = explorer_table(TITLE, "study phantom", preset_name, variables, objectives, results, records, front,
                          {"position": position, "rule": "largest K_max (type 1) on the front"}, cards,
                          front_file="the front below", evaluations_file=None)
    paragraphs = [f"{len(designs)} designs of the design sets, each simulated in types 1 and 2 for the maximum stable "
                  "impedance and the transparency bandwidth. The objective space is LN against K_max (type 1); the "
                  "front holds the designs no other beats in both (a lower LN and a larger K_max). Variables: the "
                  "LN level the design was drawn for and the inertial parameters that differ between the designs "
                  "(the seed's names). A bandwidth above the chirp's 15 Hz has no number."]
    return Explorer(TITLE, data, files, paragraphs)


def _card(preset_name: str, design: Design, file: str) -> dict:
    """A front design's card: its picture at home, its spec summary there and the commands that reproduce it."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicalConsistencyWarning)
        device = preset(preset_name).with_params(design.params)
        q = home_pose(device)
        try:
            spec = spec_summary(device, q)
        except UserError:
            spec = None
    given = f"--preset {preset_name} --params {file}"
    commands = [{"what": "the spec sheet at its home pose", "command": f"hapticdesign spec {given}"},
                {"what": "its maximum stable impedance, type 1 (the campaign's search)",
                 "command": f"hapticdesign impedance-range {given} --type 1"}]
    return {"file": file, "maps": {}, "picture": {**snapshot(device, q), "where": "at home"}, "commands": commands,
            "spec": spec}
