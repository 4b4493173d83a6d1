"""``kmax_simulated``: the simulated wall (dry friction, quantization, a hand) as a design index a study can ask for
(issue 35). Oracles: where the loop is linear it is the exact limit ``kmax`` (spectral radius) to the bisection's
tolerance; a study that asks for it runs through the package's own entry point; its cost counts in the workload."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import hapticdesign as hd
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.metrics.indices import INDICES, Request, evaluate
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.errors import UserError
from hapticdesign.optimization.study_evaluation import STUDY_LIMIT, require_study_workload
from hapticdesign.optimization.study_file import load_study

ROOT = Path(__file__).resolve().parents[2]
FIVE_BAR = ROOT / "examples" / "devices" / "five-bar.yaml"


def _home_point(device) -> np.ndarray:
    space = configuration_of(device)
    return space.position_and_jacobian(space.full(space.home))[0]


def test_where_the_loop_is_linear_the_simulated_wall_is_the_exact_one():
    """Friction and quantization off: the simulated growth boundary (bisected to 1e-3, the wall resting 1 mm from the
    pose) equals ``kmax`` along its worst direction, at home and 15 mm beside it; with the grasp it is far higher."""
    device = load_device_file(FIVE_BAR)
    points = _home_point(device) + np.array([[0.0, 0.0, 0.0], [0.015, 0.0, 0.0]])
    linear = Request("kmax_simulated", {"friction": False, "quantization": False, "rel_tol": 1e-3}, "linear")
    found = evaluate(device, points, ["kmax", linear, Request("kmax_simulated", {"hand": "light"}, "hand")])
    assert found.reason is None, found.reason
    np.testing.assert_allclose(found.values["linear"], found.values["kmax"], rtol=2e-3)
    assert np.all(found.values["hand"] > 2.0 * found.values["kmax"])
    assert INDICES["kmax_simulated"].cost > 1.0 and INDICES["kmax_simulated"].needs == {"device"}


def test_a_study_can_ask_for_a_wall_with_a_hand_and_friction(tmp_path):
    """Four five-bar designs at one point, a 1000-N/m wall with the grasp and the device's friction as a constraint:
    the study runs (the index loaded through the ``simulation`` entry point) and each evaluated design's value is
    the index's own at the point; a study whose points x designs x the index's cost is too large is refused."""
    study = {"device": str(FIVE_BAR), "variables": {"l1": [0.09, 0.11]},
             "workspace": {"box": {"center": [0.0, 0.0, 0.18], "size": [0.0, 0.0, 0.0]}, "grid": 1},
             "objectives": [{"name": "isotropy", "index": "isotropy", "reduce": "min", "sense": "max"}],
             "constraints": [{"index": "kmax_simulated", "options": {"hand": "light"}, "reduce": "min",
                              ">=": 1000}],
             "algorithm": {"method": "nsga2", "population": 4, "generations": 1, "polish": "none"}}
    path = tmp_path / "wall.yaml"
    path.write_text(yaml.safe_dump(study, sort_keys=False))
    result = hd.optimize(path, seed=4)
    assert len(result.records) == 4
    for record in result.records:
        device = load_device_file(FIVE_BAR).with_params({"l1": record.values["l1"]})
        alone = evaluate(device, np.array([[0.0, 0.0, 0.18]]), [Request("kmax_simulated", {"hand": "light"})])
        assert record.invalid == "" and alone.values["kmax_simulated"][0] > 1000
        assert record.constraints[0] == pytest.approx(alone.values["kmax_simulated"][0], rel=1e-12)
    study["algorithm"] = {"method": "nsga2", "population": 20, "generations": 6}  # 120 designs x 1000 > 1e5
    path.write_text(yaml.safe_dump(study, sort_keys=False))
    with pytest.raises(UserError, match=r"each costing 1000 evaluations \(index kmax_simulated\).*above the limit"):
        require_study_workload(load_study(path))


def test_the_simulated_wall_takes_the_loops_wall_damping():
    """The wall's damper is the loop's ``wall_damping`` in both indices: friction and quantization off, the simulated
    limit with a 2 N s/m damper on the sampled velocity is ``kmax``'s with the same damper (the damper raises both
    above the undamped wall's); a damper on the backward difference is analysed exactly only (one line)."""
    device = load_device_file(FIVE_BAR)
    point = _home_point(device)[None]
    damped = {"wall_damping": 2.0, "velocity": "sampled"}
    linear = Request("kmax_simulated", {"friction": False, "quantization": False, "rel_tol": 1e-3, **damped})
    found = evaluate(device, point, [Request("kmax", damped, "exact"), linear, "kmax"])
    assert found.reason is None, found.reason
    np.testing.assert_allclose(found.values["kmax_simulated"], found.values["exact"], rtol=2e-3)
    assert found.values["exact"][0] > found.values["kmax"][0]
    refused = evaluate(device, point, [Request("kmax_simulated", {"wall_damping": 2.0})])
    assert refused.reason is not None and "backward-difference damper is analysed exactly only" in refused.reason


@pytest.mark.parametrize("options, message", [({"friction": "yes"}, "friction is true or false"),
                                              ({"rel_tol": 0.0}, "rel_tol is a number from 1e-4 to 0.5"),
                                              ({"delay": -1}, "the delay is a whole number")])
def test_bad_options_are_one_line(options, message):
    device = load_device_file(FIVE_BAR)
    found = evaluate(device, _home_point(device)[None], [Request("kmax_simulated", options)])
    assert found.reason is not None and message in found.reason


def test_a_map_of_the_simulated_wall_is_estimated_first(tmp_path):
    """121 points of ``kmax_simulated`` count as 121,000 evaluations: refused in one line, exit 2, nothing written."""
    from typer.testing import CliRunner

    from hapticdesign.interface.cli import app

    out = tmp_path / "map"
    done = CliRunner().invoke(app, ["maps", "--device", str(FIVE_BAR), "--size", "0.02,0,0.02", "--grid", "11",
                                    "--index", "kmax_simulated", "--out", str(out)])
    assert done.exit_code == 2 and len(done.output.strip().splitlines()) == 1
    assert "121,000 design-point evaluations" in done.output and not out.exists()
