"""Issue 45: one shape for an index's inputs on every path, a user index that fails named in one line, one user index
through ``maps``, ``metrics``, ``spec`` and a study with the same values, and an index of all of a design's points.

Oracles: the built-in ``force`` index (the force polytope's inscribed radius, checked against SciPy's ``linprog`` in
tests/design/test_indices_force_stiffness.py), which the user index below computes another way (without the basis
``U``: a planar device's ``J_v`` has its columns in the plane, so ``|A^-T J_v^T U|`` and ``|A^-T J_v^T|`` have the
same row norms); the per-point values of ``apparent_mass`` (for the index over the points).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

import hapticdesign as hd
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.metrics.indices import INDICES, HandleStates, Registry, evaluate, evaluate_designs
from hapticdesign.analysis.workspace import Workspace
from hapticdesign.devices.design_space import design_space
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app
from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import load_study

ROOT = Path(__file__).resolve().parents[2]
DEVICE = ROOT / "examples" / "studies" / "five-bar-tubes.yaml"
@pytest.fixture(autouse=True)
def _global_registry_as_it_was():
    """The user index files these tests run in-process (``--indices``, ``hd.optimize(indices=...)``) register into the
    one registry, as a user's session would; other test modules then see the registry as it was."""
    held = dict(INDICES._own)
    yield
    INDICES._own.clear()
    INDICES._own.update(held)


INDEX_FILE = '''import numpy as np
import hapticdesign as hd


@hd.index(unit="N", needs=("kinematics", "motors"))
def motor_force(pose):
    """min_k n_k tau_k / |(A^-T J_v^T)_k|, written on the documented shapes"""
    assert pose.motor_map.shape == (pose.count, 2, 2) and pose.torque_limits["continuous"].shape == (pose.count, 2)
    assert pose.B.shape == (pose.count, 2, 2) and pose.J_v.shape == (pose.count, 3, 2) and pose.q.shape == (pose.count, 2)
    g = np.einsum("pji,pkj->pik", pose.motor_map, pose.J_v)
    return np.min(pose.torque_limits["continuous"] / np.linalg.norm(g, axis=-1), axis=-1)
'''


def home_of(device) -> tuple[np.ndarray, np.ndarray]:
    space = configuration_of(device)
    return space.home, space.position_and_jacobian(space.full(space.home))[0]


@pytest.fixture(scope="module")
def index_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("indices") / "mine.py"
    path.write_text(INDEX_FILE)
    return path


def study_file(folder: Path, center, grid: int, index: str = "motor_force") -> Path:
    study = {"device": str(DEVICE), "variables": {"l1": [0.08, 0.14]},
             "workspace": {"box": {"center": [float(v) for v in center], "size": [0.02, 0.0, 0.02]}, "grid": grid},
             "objectives": [{"name": how, "index": index, "reduce": how, "sense": "max"}
                            for how in ("center", "min", "max")],
             "algorithm": {"population": 4, "generations": 1}}
    (folder / "study.yaml").write_text(yaml.safe_dump(study, sort_keys=False))
    return folder / "study.yaml"


def test_one_user_index_through_maps_metrics_spec_and_a_study(tmp_path, index_file):
    device = hd.load_device(DEVICE)
    q, home = home_of(device)
    runner = CliRunner()
    q_text = ",".join(repr(float(v)) for v in q)

    done = runner.invoke(app, ["metrics", "--device", str(DEVICE), "--q", q_text, "--index", "motor_force",
                               "--indices", str(index_file), "--json"])
    assert done.exit_code == 0, done.output
    at_metrics = json.loads(done.stdout)["indices"]["motor_force"]

    done = runner.invoke(app, ["spec", "--device", str(DEVICE), "--q", q_text, "--index", "motor_force,force",
                               "--indices", str(index_file), "--no-workspace", "--no-simulate", "--json"])
    assert done.exit_code == 0, done.output
    sheet = json.loads(done.stdout)
    at_spec = sheet["indices"]["motor_force"]
    assert sheet["units"]["indices"]["motor_force"] == "N"

    done = runner.invoke(app, ["maps", "--device", str(DEVICE), "--size", "0.02,0,0.02", "--grid", "3",
                               "--index", "motor_force,force", "--indices", str(index_file), "--out",
                               str(tmp_path / "maps"), "--json"])
    assert done.exit_code == 0, done.output
    spread = json.loads(done.stdout)["spread"]

    from hapticdesign.interface.commands.optimize_adapter import index_module
    own = index_module(index_file)
    bound = bind_study(load_study(study_file(tmp_path, home, 3)), indices=own)
    answer = StudyEvaluator(bound)([{"l1": float(device.params["l1"])}])[0]  # the compiled batch of designs
    assert answer.reason == ""
    centre, low, high = answer.reduced

    assert at_metrics == pytest.approx(at_spec, rel=1e-12)
    assert centre == pytest.approx(at_spec, rel=1e-9)
    assert spread["motor_force"]["center"] == pytest.approx(at_spec, rel=1e-9)
    assert (spread["motor_force"]["min"], spread["motor_force"]["max"]) == pytest.approx((low, high), rel=1e-9)
    assert at_spec == pytest.approx(sheet["indices"]["force"], rel=1e-9)  # the built-in force polytope's radius
    assert spread["motor_force"]["min"] == pytest.approx(spread["force"]["min"], rel=1e-9)
    assert spread["motor_force"]["max"] == pytest.approx(spread["force"]["max"], rel=1e-9)


def test_every_field_has_the_leading_axis_one_design_and_batched():
    """The same fields, the same shapes, one design at its points and many designs through the compiled kernels."""
    seen = []

    @hd.index(unit="1", needs=("kinematics", "dynamics", "damping", "motors", "bodies"), registry=Registry(INDICES))
    def shapes(pose):
        n = pose.count
        seen.append((pose.J_v.shape, pose.H.shape, pose.B.shape, pose.q.shape, pose.motor_map.shape,
                     pose.torque_limits["continuous"].shape, pose.moving_mass.shape, pose.cartesian_mass.shape,
                     pose.designs, n))
        return np.zeros(n)

    space = design_space(DEVICE, ["l1"])
    points = Workspace((0.0, 0.0, 0.16), (0.02, 0.0, 0.02), 3).points()
    registry = INDICES.with_indices([shapes])
    one = evaluate(space.device({"l1": 0.11}), points, ["shapes"], registry=registry)
    many = evaluate_designs(space, [{"l1": 0.11}, {"l1": 0.12}], points, ["shapes"], registry)
    assert one.reason is None and all(e.reason is None for e in many)
    (single, batch) = seen
    assert single == ((9, 3, 2), (9, 2, 2), (9, 2, 2), (9, 2), (9, 2, 2), (9, 2), (9,), (9, 2), 1, 9)
    assert batch == ((18, 3, 2), (18, 2, 2), (18, 2, 2), (18, 2), (18, 2, 2), (18, 2), (18,), (18, 2), 2, 18)


def test_an_index_of_all_of_a_designs_points():
    """``over="points"``: one value per design from all its points, the same one design at a time and batched, and
    every reduction of it is that value; here max / min of the apparent mass over the points."""
    @hd.index(unit="1", over="points", registry=Registry(INDICES))
    def mass_spread(pose):
        """largest / smallest apparent mass over the design's points"""
        mass = pose.cartesian_mass[:, -1].reshape(pose.designs, -1)
        return mass.max(axis=1) / mass.min(axis=1)

    space = design_space(DEVICE, ["l1"])
    points = Workspace((0.0, 0.0, 0.16), (0.02, 0.0, 0.02), 3).points()
    registry = INDICES.with_indices([mass_spread])
    designs = [{"l1": 0.10}, {"l1": 0.12}, {"l1": 0.13}]
    many = evaluate_designs(space, designs, points, ["mass_spread", "apparent_mass"], registry)
    for values, found in zip(designs, many):
        one = evaluate(space.device(values), points, ["mass_spread", "apparent_mass"], registry=registry)
        mass = found.values["apparent_mass"]
        assert np.allclose(found.values["mass_spread"], mass.max() / mass.min(), rtol=1e-12)
        assert np.allclose(one.values["mass_spread"], found.values["mass_spread"], rtol=1e-9)
    assert len({round(float(f.values["mass_spread"][0]), 9) for f in many}) == 3
    with pytest.raises(UserError, match="index bad: over is poses .* or points"):
        hd.index(unit="1", over="designs", name="bad", registry=Registry(INDICES))(lambda pose: 0)


@pytest.mark.parametrize("body, message", [
    ("return pose.q[0, 0] + np.linalg.inv(np.zeros((2, 2)))", r"index broken \(.*\) failed: LinAlgError: Singular matrix"),
    ("return np.ones((pose.count, 2))", r"index broken \(.*\) returned shape \(\d+, 2\), not \(\d+,\): one value per pose"),
])
def test_a_user_index_that_raises_or_answers_another_shape_is_one_line_naming_it(tmp_path, body, message):
    (tmp_path / "broken.py").write_text(f"import numpy as np\nimport hapticdesign as hd\n\n\n@hd.index(unit='1')\n"
                                        f"def broken(pose):\n    {body}\n")
    path = study_file(tmp_path, (0.0, 0.0, 0.16), 3, "broken")
    with pytest.raises(UserError, match=message):
        hd.optimize(path, seed=1, indices=tmp_path / "broken.py")
    done = CliRunner().invoke(app, ["optimize", str(path), "--indices", str(tmp_path / "broken.py")])
    assert done.exit_code == 2
    assert done.output.strip().count("\n") == 0 and "index broken" in done.output, done.output
    assert "Traceback" not in done.output
