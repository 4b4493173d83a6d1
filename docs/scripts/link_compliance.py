"""Regenerates the links' compliance numbers of docs/simulation.md ("A compliant transmission").

For the R-CUBE and the five-bar of aluminium tubes at home, the wall's spring at the limit with the links' compliance
and rigid, and the stiffness the handle then feels (the spring in series with the drive along the wall). For the
five-bar of aluminium tubes (examples/studies/five-bar-tubes.yaml) at its home pose: the drive's joint-space
stiffness (the links' compliance carried to the joints, no transmission), and the weakest wall with the light hand
(``kmax``, worst direction, practice's loop) with the links' compliance and with the rigid model, for the file's
proximal tubes (12 mm) and thinner ones (9 mm). Then the cost in a study: ``kmax`` (light hand) of 20 designs of the
five-bar study's variables at its 25 points through the batched path, the tubes' compliance included, against the same
designs with the links' compliance left out (the batched path told the device has no elastic links: the same masses,
the rigid plant).

Run: ``PYTHONPATH=src .venv/bin/python docs/scripts/link_compliance.py`` (about a minute).
"""

from __future__ import annotations

import time
from pathlib import Path
from unittest import mock

import numpy as np
import yaml

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics.device import gravity_gradient_at
from hapticdesign.analysis.metrics.indices import Request, evaluate_designs
from hapticdesign.analysis.metrics.indices import evaluation
from hapticdesign.analysis.metrics.indices.states import HandleStates
from hapticdesign.analysis.sampled_loop import GRASP, SampledLoop
from hapticdesign.analysis.wall_stiffness import wall_limit, worst_direction
from hapticdesign.analysis.workspace import Workspace
from hapticdesign.devices.design_space import design_space
from hapticdesign.devices.device_file import device_from_mapping, load_device_file

ROOT = Path(__file__).resolve().parents[2]
TUBES = ROOT / "examples" / "studies" / "five-bar-tubes.yaml"
STUDY_VARIABLES = ["l1", "l2", "d"]
DESIGNS = 20


def walls(data: dict) -> tuple[np.ndarray, float, float]:
    """The drive's stiffness at home and the weakest wall with the light hand, with the links and rigid."""
    device = device_from_mapping(data)
    home = np.array([data["home"]["q1"], data["home"]["q2"]])
    states = HandleStates(device, configuration_of(device).full(home)[None])
    loop = SampledLoop(hand=GRASP)
    args = (states.J_v[0], states.H[0], states.B[0], loop)
    gravity = gravity_gradient_at(device, states.full)[0]
    return (states.drive.stiffness[0], wall_limit(*args, gravity=gravity, transmission=states.drive),
            wall_limit(*args, gravity=gravity))


def study_seconds(data: dict, designs: list[dict], points: np.ndarray) -> tuple[float, list[float]]:
    space = design_space(data, STUDY_VARIABLES)
    request = [Request("kmax", {"hand": "light"}, "kmax")]
    evaluate_designs(space, designs[:2], points, request)  # compile and warm up
    start = time.perf_counter()
    got = evaluate_designs(space, designs, points, request)
    return time.perf_counter() - start, [float(np.min(g.values["kmax"])) if g.values else float("nan") for g in got]


def felt(name: str, path: Path) -> None:
    """A device at home, light hand, worst direction: the controller's spring at the limit with the links and rigid,
    and the stiffness the handle feels with the links, the spring in series with the drive along the wall
    (``1 / (1 / K + u^T J_v K_d^-1 J_v^T u)``)."""
    device = load_device_file(path)
    states = HandleStates(device, configuration_of(device).full(configuration_of(device).home.copy())[None])
    loop = SampledLoop(hand=GRASP)
    args = (states.J_v[0], states.H[0], states.B[0], loop, gravity_gradient_at(device, states.full)[0])
    limit, direction, _ = worst_direction(*args, transmission=states.drive)
    rigid, _, _ = worst_direction(*args)
    jv = states.J_v[0]
    drive = direction @ jv @ np.linalg.inv(states.drive.stiffness[0]) @ jv.T @ direction
    print(f"{name} at home, light hand: the wall's spring at the limit {limit:.1f} N/m with the links "
          f"({states.drive.inertia.any() and 'rotors' or 'massless motor side'}), {rigid:.1f} N/m rigid; the drive "
          f"along the wall {1 / drive:.0f} N/m, so the handle feels {1 / (1 / limit + drive):.0f} N/m")


def main() -> None:
    felt("R-CUBE (examples/devices/rcube.yaml)", ROOT / "examples" / "devices" / "rcube.yaml")
    felt("five-bar tubes", TUBES)
    data = yaml.safe_load(TUBES.read_text())
    for name, diameter in (("the file's 12 mm proximal tubes", None), ("9 mm proximal tubes", 0.009)):
        variant = yaml.safe_load(yaml.safe_dump(data))
        if diameter is not None:
            for link in variant["links"]:
                if link["name"].startswith("prox"):
                    link["section"]["D"] = diameter
                    link["section"]["d"] = 0.007
        stiffness, compliant, rigid = walls(variant)
        print(f"{name}: drive stiffness diag {np.round(np.diag(stiffness), 1).tolist()} N m/rad, off-diagonal "
              f"{stiffness[0, 1]:.3g}; weakest wall, light hand: {compliant:.1f} N/m with the links, {rigid:.1f} N/m "
              "rigid")
    rng = np.random.default_rng(1)
    bounds = {"l1": (0.09, 0.12), "l2": (0.12, 0.16), "d": (0.04, 0.1)}
    designs = [{k: float(rng.uniform(*b)) for k, b in bounds.items()} for _ in range(DESIGNS)]
    points = Workspace((0.0, 0.0, 0.16), (0.06, 0.0, 0.06), 5).points()
    with_links, values = study_seconds(data, designs, points)
    with mock.patch.object(evaluation, "elastic", lambda device: False):
        rigid, rigid_values = study_seconds(data, designs, points)
    print(f"study cost, kmax (light hand) at {len(points)} points: {1000 * with_links / DESIGNS:.0f} ms per design "
          f"with the links' compliance, {1000 * rigid / DESIGNS:.0f} ms rigid ({with_links / rigid:.1f} times)")
    print("worst wall per design, with links / rigid:",
          [f"{a:.0f}/{b:.0f}" for a, b in zip(values[:5], rigid_values[:5])])


if __name__ == "__main__":
    main()
