"""Many designs through the compiled kernels (:mod:`hapticdesign.analysis.design_batch`) against one design at a
time (:func:`hapticdesign.analysis.metrics.indices.evaluate`, whose indices are checked against closed forms,
finite differences and kinetic energy in test_indices.py): same values, same failures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.workspace import Workspace
from hapticdesign.devices.design_space import design_space
from hapticdesign.analysis.metrics.indices import Request
from hapticdesign.analysis.metrics.indices import evaluate, evaluate_designs

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
INDICES = ["isotropy", "apparent_mass", "condition", "manipulability", "inertia_uniformity", "kmax",
           Request("kmax", {"period": 0.0005, "delay": 2, "damping": 0.05}, "kmax_damped")]
KEYS = [r if isinstance(r, str) else r.key for r in INDICES]
CASES = {
    "five-bar": (["l1", "l2", "d"], Workspace((0.0, 0.0, 0.18), (0.06, 0.0, 0.06), 3),
                 {"l1": (0.08, 0.13), "l2": (0.12, 0.17), "d": (0.05, 0.1)}),
    "delta": (["La", "Lb", "R"], Workspace((-0.10, 0.0, 0.0), (0.03, 0.03, 0.03), 2),
              {"La": (0.05, 0.07), "Lb": (0.09, 0.11), "R": (0.03, 0.04)}),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_batched_designs_equal_one_design_at_a_time(name):
    names, workspace, bounds = CASES[name]
    space = design_space(EXAMPLES / f"{name}.yaml", names)
    rng = np.random.default_rng(7)
    designs = [{k: float(rng.uniform(*bounds[k])) for k in names} for _ in range(6)]
    points = workspace.points()
    batched = evaluate_designs(space, designs, points, INDICES)
    assert space.cache.get("batch"), "the compiled path serves these indices (kmax with J_v, H and the file's B)"
    for values, fast in zip(designs, batched):
        slow = evaluate(space.device(values), points, INDICES)
        assert (fast.reason is None) == (slow.reason is None), (fast.reason, slow.reason)
        for key in KEYS if slow.reason is None else ():
            np.testing.assert_allclose(fast.values[key], slow.values[key], rtol=1e-9)


def test_bodies_that_are_links_follow_the_geometry_of_each_design():
    """Link bodies change mass with l1, l2: the batch (which keeps the file's inertial parameters) must not be
    taken for them; each design's apparent mass is that of its own device, not the file's."""
    tubes = Path(__file__).resolve().parents[2] / "examples" / "studies" / "five-bar-tubes.yaml"
    space = design_space(tubes, ["l1", "l2", "d"])
    points = Workspace((0.0, 0.0, 0.16), (0.02, 0.0, 0.02), 2).points()
    designs = [{"l1": 0.13, "l2": 0.16, "d": 0.05}, {"l1": 0.09, "l2": 0.2, "d": 0.07}]
    for values, fast in zip(designs, evaluate_designs(space, designs, points, ["apparent_mass"])):
        slow = evaluate(space.device(values), points, ["apparent_mass"])
        np.testing.assert_allclose(fast.values["apparent_mass"], slow.values["apparent_mass"], rtol=1e-9)
    masses = [evaluate(space.device(v), points, ["mass"]).values["mass"][0] for v in designs]
    assert masses[0] != masses[1]


def test_batched_failures_name_the_point_or_the_design():
    space = design_space(EXAMPLES / "five-bar.yaml", ["l1", "l2"])
    points = np.array([[0.0, 0.0, 0.18], [0.0, 0.0, 0.235], [0.0, 0.0, 0.30]])
    designs = [{"l1": 0.10, "l2": 0.14}, {"l1": 0.02, "l2": 0.03}, {"l1": 0.10, "l2": float("nan")}]
    fast = evaluate_designs(space, designs, points, ["isotropy"])
    slow = evaluate(space.device(designs[0]), points, ["isotropy"])
    assert "(0, 0, 0.3) m" in fast[0].reason and "(0, 0, 0.3) m" in slow.reason
    assert "cannot close" in fast[1].reason
    assert "finite" in fast[2].reason
