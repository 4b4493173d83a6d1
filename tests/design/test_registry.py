"""The one registry of design indices (:mod:`hapticdesign.analysis.metrics.indices`): every index batched as one
design at a time, isotropy and condition of spatial devices against the SVD of a finite-difference ``J_v``, your own
index from Python (in a study run, in a CLI run), and the discovery of installed packages' indices.

Oracles: one design at a time (:func:`evaluate`, whose indices test_indices.py checks against closed forms, kinetic
energy and finite differences); central differences of the handle position (forward kinematics, the loops closed
by the loop solver) and NumPy's SVD; the built-in index a user's index mirrors (``isotropy ** 2``).
"""

from __future__ import annotations

import importlib.metadata
import json
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

import hapticdesign as hd
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.metrics.indices import (
    INDICES, Registry, Request, evaluate, evaluate_at, evaluate_designs, evaluate_parameters,
)
from hapticdesign.analysis.metrics.indices.registry import ENTRY_POINTS
from hapticdesign.analysis.metrics.indices.states import BATCH_NEEDS
from hapticdesign.analysis.workspace import Workspace
from hapticdesign.devices.design_space import design_space
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app
from hapticdesign.optimization.pymoo_run import NSGA_II
from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import load_study
from hapticdesign.optimization.study_run import run_study

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples" / "devices"


@hd.index(unit="1")
def isotropy_squared(pose):
    """(sigma_min / sigma_max)^2 of J_v"""
    s = np.linalg.svd(pose.J_v, compute_uv=False)
    return (s[..., -1] / s[..., 0]) ** 2


def _first_coordinate(pose, scale=1.0):
    """the first actuated coordinate, scaled"""
    return scale * pose.q[:, 0]


def test_every_batched_index_is_the_same_one_design_at_a_time_and_batched():
    """Every registered index the compiled kernels can serve (and one reading ``q``) on five-bar designs."""
    local = Registry(INDICES)
    hd.index(unit="rad", needs=("kinematics",), registry=local)(_first_coordinate)
    # the five-bar file has no sections and no torque limits (stiffness, frequency and force are compared batched
    # on tube links with motors in test_design_batch.py)
    names = [name for name in local if local[name].needs <= BATCH_NEEDS - {"sections", "motors"}]
    assert {"isotropy", "condition", "apparent_mass", "kmax", "isotropy_squared", "_first_coordinate"} <= set(names)
    requests = [*names, Request("_first_coordinate", {"scale": -2.0}, "scaled")]
    space = design_space(EXAMPLES / "five-bar.yaml", ["l1", "l2", "d"])
    points = Workspace((0.0, 0.0, 0.18), (0.06, 0.0, 0.06), 3).points()
    rng = np.random.default_rng(11)
    designs = [{"l1": rng.uniform(0.08, 0.13), "l2": rng.uniform(0.12, 0.17), "d": rng.uniform(0.05, 0.1)}
               for _ in range(5)]
    batched = evaluate_designs(space, designs, points, requests, local)
    assert space.cache.get("batch"), "the compiled kernels served these indices"
    compared = 0
    for values, fast in zip(designs, batched):
        slow = evaluate(space.device(values), points, requests, registry=local)
        assert (fast.reason is None) == (slow.reason is None), (fast.reason, slow.reason)
        for key in slow.values:
            np.testing.assert_allclose(fast.values[key], slow.values[key], rtol=1e-9, atol=1e-12, err_msg=key)
            compared += 1
    assert compared >= 3 * len(requests)


def test_indices_of_the_parameters_one_design_at_a_time_and_batched():
    """The R-CUBE's indices (registered from R-CUBE code): the batch of parameter sets equals each design alone."""
    names = ["rcube_o1", "rcube_o2", "rcube_o3", "rcube_constraint"]
    assert all(INDICES[n].of_parameters for n in names)
    device = load_device_file(EXAMPLES / "rcube.yaml")
    lengths = [(0.10, 0.11, 0.12), (0.12, 0.10, 0.14), (0.09, 0.13, 0.11)]
    params = {name: np.array([float(device.params[name])] * len(lengths)) for name in device.params}
    for k, name in enumerate(("l1", "l2", "l3")):
        params[name] = np.array([row[k] for row in lengths])
    params["S"] = params["l1"]
    requests = [Request(n) for n in names] + [Request("rcube_constraint", {"point": "B1"}, "b1")]
    batched = evaluate_parameters(params, requests)
    for d in range(len(lengths)):
        one = evaluate_parameters({n: v[d:d + 1] for n, v in params.items()}, requests)
        for key, values in one.items():
            assert batched[key][d] == pytest.approx(values[0], rel=1e-12)


def _finite_difference_jacobian(device, q_a: np.ndarray, step: float = 1e-6) -> np.ndarray:
    space = configuration_of(device)
    return np.column_stack([(space.pose(q_a + step * e)[:3, 3] - space.pose(q_a - step * e)[:3, 3]) / (2 * step)
                            for e in np.eye(len(q_a))])


@pytest.mark.parametrize("name", ["delta", "phantom-3dof"])
def test_isotropy_and_condition_of_spatial_devices_are_the_svd_of_the_handle_jacobian(name):
    """At poses near home whose three singular values are distinct, so the middle one is not the smallest."""
    device = load_device_file(EXAMPLES / f"{name}.yaml")
    space = configuration_of(device)
    rng = np.random.default_rng(5)
    poses = space.home + rng.uniform(-0.15, 0.15, (6, len(space.home)))
    full = np.array([space.full(q) for q in poses])
    found = evaluate_at(device, full, [Request("isotropy"), Request("condition")])
    for k, q in enumerate(poses):
        s = np.linalg.svd(_finite_difference_jacobian(device, q), compute_uv=False)
        assert s[1] > s[2] * 1.02, "the test needs distinct singular values"
        assert found.values["isotropy"][k] == pytest.approx(s[2] / s[0], rel=1e-6)
        assert found.values["condition"][k] == pytest.approx(s[0] / s[2], rel=1e-6)


def _five_bar_study(folder: Path, objectives: list) -> Path:
    study = {"device": str(EXAMPLES / "five-bar.yaml"), "variables": {"l1": [0.09, 0.12], "l2": [0.13, 0.16]},
             "workspace": {"box": {"center": [0.0, 0.0, 0.18], "size": [0.04, 0.0, 0.04]}, "grid": 2},
             "objectives": objectives, "algorithm": {"method": "nsga2", "population": 8, "generations": 3}}
    (folder / "study.yaml").write_text(yaml.safe_dump(study, sort_keys=False))
    return folder / "study.yaml"


SQUARED = {"name": "squared", "index": "isotropy_squared", "reduce": "min", "sense": "max"}
BUILT_IN = {"name": "iso", "index": "isotropy", "reduce": "min", "sense": "max"}


def test_your_own_index_in_a_study_equals_the_built_in_it_mirrors(tmp_path):
    study = load_study(_five_bar_study(tmp_path, [SQUARED, BUILT_IN]))
    bound = bind_study(study, indices=[isotropy_squared])
    run = run_study(study, 2, StudyEvaluator(bound), algorithm=NSGA_II)
    evaluated = [r for r in run.records if not r.invalid]
    assert len(evaluated) >= 16
    for record in evaluated:
        assert record.objectives[0] == pytest.approx(record.objectives[1] ** 2, rel=1e-12)


def test_a_study_of_a_study_local_index_and_the_cli_flag_that_runs_a_file(tmp_path):
    """An index given to ``bind_study`` alone (not in the one registry) serves that study only; ``optimize
    --indices FILE`` runs the file and its indices serve the study; a file that fails is one line."""
    local = hd.index(unit="1", name="isotropy_local", registry=Registry(INDICES))(isotropy_squared.function)
    assert "isotropy_local" not in INDICES
    study = load_study(_five_bar_study(tmp_path, [{**SQUARED, "index": "isotropy_local"}, BUILT_IN]))
    answers = StudyEvaluator(bind_study(study, indices=[local]))([{"l1": 0.1, "l2": 0.15}])
    assert answers[0].reduced[0] == pytest.approx(answers[0].reduced[1] ** 2, rel=1e-12)
    with pytest.raises(UserError, match="unknown index 'isotropy_local'"):
        bind_study(study)

    (tmp_path / "mine.py").write_text("import numpy as np\nimport hapticdesign as hd\n\n\n@hd.index(unit='1')\n"
                                      "def isotropy_fourth(pose):\n"
                                      "    s = np.linalg.svd(pose.J_v, compute_uv=False)\n"
                                      "    return (s[..., -1] / s[..., 0]) ** 4\n")
    path = _five_bar_study(tmp_path, [{**SQUARED, "name": "fourth", "index": "isotropy_fourth"}, BUILT_IN])
    result = CliRunner().invoke(app, ["optimize", str(path), "--indices", str(tmp_path / "mine.py"), "--json",
                                      "--quiet"])
    assert result.exit_code == 0, result.output
    front = json.loads(result.stdout)["front"]
    assert front and all(d["objectives"]["fourth"] == pytest.approx(d["objectives"]["iso"] ** 4, rel=1e-9)
                         for d in front)
    (tmp_path / "broken.py").write_text("raise RuntimeError('no such thing')\n")
    result = CliRunner().invoke(app, ["optimize", str(path), "--indices", str(tmp_path / "broken.py")])
    assert result.exit_code == 2
    assert result.output.strip().count("\n") == 0 and "RuntimeError: no such thing" in result.output


def test_the_python_door_runs_a_study_with_your_own_index(tmp_path):
    """``hapticdesign.optimize(study, indices=[...])`` (issue 36's example): an index outside the one registry
    serves the run; the front's objectives are the built-in's squares; a scheduler with your own indices is refused
    (its workers would not have them)."""
    local = hd.index(unit="1", name="isotropy_door", registry=Registry(INDICES))(isotropy_squared.function)
    path = _five_bar_study(tmp_path, [{**SQUARED, "index": "isotropy_door"}, BUILT_IN])
    result = hd.optimize(path, seed=3, indices=[local])
    assert result.front and result.files == []
    for design in result.front:
        assert design["objectives"]["squared"] == pytest.approx(design["objectives"]["iso"] ** 2, rel=1e-12)
    with pytest.raises(UserError, match="scheduler"):
        hd.optimize(path, seed=3, indices=[local], scheduler="tcp://127.0.0.1:1")


def test_registering_a_name_twice_or_a_bad_index_is_one_line():
    local = Registry(INDICES)
    with pytest.raises(UserError, match="'isotropy' is registered already"):
        hd.index(unit="1", name="isotropy", registry=local)(lambda pose: pose.J_v[:, 0, 0])
    with pytest.raises(UserError, match="needs is some of"):
        hd.index(unit="1", needs=("kinematics", "parameters"), registry=local)(_first_coordinate)
    with pytest.raises(UserError, match="keyword parameter with a default"):
        hd.index(unit="1", name="scaled", registry=local)(lambda pose, scale: pose.q[:, 0])
    with pytest.raises(UserError, match="Python identifier"):
        hd.index(unit="1", name="no spaces", registry=local)(_first_coordinate)
    assert hd.index(unit="1", registry=local)(isotropy_squared.function) is not None  # the same function again


class _Point:
    """An entry point of the ``hapticdesign.indices`` group (importlib.metadata's interface: name, value, load)."""

    def __init__(self, name: str, value: str):
        self.name, self.value = name, value

    def load(self):
        return importlib.import_module(self.value)




def test_an_installed_packages_indices_are_found_on_the_first_unknown_name(tmp_path, monkeypatch):
    (tmp_path / "plugin_indices.py").write_text(
        "import hapticdesign as hd\n\n\n@hd.index(unit='1')\ndef plugin_isotropy(pose):\n"
        "    return 1.0 / pose.J_v[:, 0, 0] ** 0\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    asked = []

    def entry_points(group):
        asked.append(group)
        return [_Point("plugin", "plugin_indices")]

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)
    monkeypatch.setattr(INDICES, "_own", dict(INDICES._own))  # restored after the test, with the flag below
    monkeypatch.setattr(INDICES, "_discovered", False)
    assert "isotropy" in INDICES and not asked, "a registered name does not load the plugins"
    assert "plugin_isotropy" in INDICES and asked == [ENTRY_POINTS] and "plugin_indices" in sys.modules
    assert "no_such_index" not in INDICES and asked == [ENTRY_POINTS], "the plugins load once"
    monkeypatch.delitem(sys.modules, "plugin_indices")

    monkeypatch.setattr(INDICES, "_discovered", False)
    monkeypatch.setattr(importlib.metadata, "entry_points", lambda group: [_Point("broken", "no_module_of_that_name")])
    with pytest.raises(UserError, match="indices of 'broken' \\(no_module_of_that_name\\) failed to load"):
        INDICES["another_unknown_name"]


def test_the_r_cube_indices_are_an_entry_point_of_the_installed_package():
    """pyproject.toml names the R-CUBE's module in the group (the installed metadata: ``pip install -e .``)."""
    points = {p.name: p.value for p in importlib.metadata.entry_points(group=ENTRY_POINTS)}
    assert points.get("rcube") == "hapticdesign.optimization.rcube.parameter_indices"


def test_the_kmax_index_takes_the_sampled_loops_options_and_defaults():
    """The ``kmax`` index's options and defaults are those docs/indices.md states (written here from its row: 1 kHz,
    one sample of delay, no wall damper, the worst direction, backward-difference velocity, gravity compensation, no
    model error, no hand), and :class:`SampledLoop`'s defaults, the loop every command uses, are the same loop under
    the same names (``damping``, the wall damper's former name, taken for one release)."""
    from dataclasses import fields

    from hapticdesign.analysis.sampled_loop import SampledLoop

    documented = {"period": 0.001, "delay": 1, "wall_damping": 0.0, "direction": None, "velocity": "difference",
                  "compensation": "gravity", "error_percent": 0.0, "hand": None}
    assert dict(INDICES["kmax"].options) == documented
    assert INDICES["kmax"].renamed == {"damping": "wall_damping"}
    settings = set(documented) - {"direction"}
    assert settings <= {f.name for f in fields(SampledLoop)}
    assert settings - {"hand"} <= set(SampledLoop().as_dict())
    loop = SampledLoop()
    assert (loop.period, loop.delay, loop.wall_damping, loop.velocity, loop.compensation, loop.error_percent,
            loop.hand, loop.held) == (0.001, 1, 0.0, "difference", "gravity", 0.0, None, ())


def test_kmax_with_a_modelling_error_takes_the_compensators_model_batched_and_one_at_a_time():
    """``kmax`` with full compensation and a 20 % modelling error on the horizontal pantograph: the batched designs
    take the compensator's ``H`` from the closed form of the scaled masses, mass centres and inertias on standard
    parameters, one design at a time from the model device the simulation builds (the seed's "error %" on each
    parameter); the two agree, and the uniform share ``0.8 H`` would give a softer wall (about 18 against 25 N/m)."""
    from hapticdesign.analysis.metrics.indices import HandleStates
    from hapticdesign.analysis.sampled_loop import SampledLoop
    from hapticdesign.analysis.wall_stiffness import wall_limit
    from hapticdesign.analysis.workspace import reach_workspace

    space = design_space(EXAMPLES / "haply-2diy.yaml", ["l1", "l2", "d"])
    points = Workspace((0.0, 0.12, 0.0), (0.03, 0.03, 0.0), 2).points()
    designs = [{"l1": 0.07, "l2": 0.09, "d": 0.038}, {"l1": 0.075, "l2": 0.095, "d": 0.04}]
    request = Request("kmax", {"compensation": "full", "error_percent": 20.0}, "kmax")
    batched = evaluate_designs(space, designs, points, [request])
    assert space.cache.get("batch"), "the compiled kernels served kmax"
    for values, fast in zip(designs, batched):
        slow = evaluate(space.device(values), points, [request])
        assert np.all(slow.values["kmax"] > 0)
        np.testing.assert_allclose(fast.values["kmax"], slow.values["kmax"], rtol=1e-8)
    device = space.device(designs[-1])
    states = HandleStates(device, reach_workspace(device, points[:1]).full)
    uniform = wall_limit(states.J_v[0], states.H[0], states.B, SampledLoop(compensation="full", error_percent=20.0),
                         gravity=states.gravity[0])
    assert uniform < 0.9 * slow.values["kmax"][0]
