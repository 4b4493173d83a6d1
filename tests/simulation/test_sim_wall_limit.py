"""One renderable wall (issue 35): the same number from impedance-range and spec, the simulated limit equal to the
exact one where the loop is linear, and the seed's growth check taken where the wall holds the device."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq
from typer.testing import CliRunner

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.sampled_loop import SampledLoop, compensated_boundary
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.interface.cli import app
from hapticdesign.simulation.impedance import impedance_range, simulated_limit, stability_limit

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
GRID = 0.5
DEVICES = ["haply-2diy", "five-bar", "delta", "phantom-premium", "phantom-3dof"]


def _device(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_device_file(EXAMPLES / f"{name}.yaml")


@pytest.mark.parametrize("name", DEVICES)
def test_impedance_range_and_spec_give_the_same_wall(name):
    """Default method and settings of both commands: impedance-range along spec's worst direction reports the
    largest grid stiffness at or below spec's exact limit."""
    runner = CliRunner()
    path = str(EXAMPLES / f"{name}.yaml")
    spec = runner.invoke(app, ["spec", "--device", path, "--no-workspace", "--json"])
    assert spec.exit_code == 0, spec.output
    walls = json.loads(spec.stdout)["renderable_stiffness"]
    direction = ",".join(f"{v:.17g}" for v in walls["direction"])
    found = runner.invoke(app, ["impedance-range", "--device", path, "--wall-direction", direction, "--resolution",
                                str(GRID), "--k-limit", "100000", "--json"])
    assert found.exit_code == 0, found.output
    out = json.loads(found.stdout)
    assert out["settings"] == walls["settings"] and out["method"] == "limit"
    assert out["k_max"] <= walls["exact"] < out["k_max"] + GRID


@pytest.mark.parametrize("name", DEVICES)
def test_simulated_limit_is_the_exact_one_where_the_loop_is_linear(name):
    """No dry friction, no quantization, gravity compensated one sample late (its gradient, the plant's and the
    compensator's on the late pose, is in the exact loop: without it the five-bar's limit is 1.2 % high): the
    simulated growth boundary (bisected to 1e-3) is the exact limit of the n-joint loop, every joint free (a wall
    along joint 1's motion, resting 10 um from the start so the free handle's drift is negligible)."""
    device = _device(name)
    home = configuration_of(device).home
    walls = stability_limit(device, SampledLoop(), direction=None, equilibrium=0.0)  # a joint wall on joint 1
    jv = configuration_of(device).jacobian(home)[:3]
    u = jv[:, 0] / np.linalg.norm(jv[:, 0])  # the handle's motion under joint 1
    exact = stability_limit(device, SampledLoop(), direction=u, equilibrium=1e-5).stiffness
    simulated = simulated_limit(device, SampledLoop(), direction=u, equilibrium=1e-5, rel_tol=1e-3, duration=4.0,
                                friction=False)
    assert simulated == pytest.approx(exact, rel=1e-3)
    assert walls.stiffness > 0


def test_the_delta_wall_of_issue_35_is_at_or_below_its_boundary_at_the_equilibrium():
    """The seed's search (type 1: joints 1 and 2 held, full compensation, no delay) of a Cartesian wall on the
    delta: the reported k_max is stable where the wall holds joint 3, the exact 1-DOF limit there of
    ``H_33 / J_n,3^2`` and ``b_3 / J_n,3^2`` (the pose found here by SciPy's brentq on the handle's travel)."""
    device = _device("delta")
    n = np.array([-0.38583121, 0.79896853, -0.46128470])
    n /= np.linalg.norm(n)
    rest, space = configuration_of(device).home, configuration_of(device)
    x0 = n @ space.pose(rest)[:3, 3]
    step = 0.000635605

    def travel(q3):
        return n @ space.pose(np.array([rest[0], rest[1], q3]))[:3, 3] - x0 - step

    q3 = brentq(travel, rest[2] - 0.2, rest[2] + 0.2, xtol=1e-14) if travel(rest[2] - 0.2) * travel(rest[2] + 0.2) < 0 \
        else None
    assert q3 is not None
    pose = np.array([rest[0], rest[1], q3])
    reach = float(n @ space.jacobian(pose)[:3, 2])
    j, b = mass_matrix(device, pose)[2, 2] / reach ** 2, device.damping[2] / reach ** 2
    boundary = compensated_boundary(j, b, 1e-3)
    found = impedance_range(device, 1, "analytic", 20, wall_joint=2, equilibrium=step, resolution=0.27434824,
                            wall_direction=n)
    assert math.isfinite(boundary) and found.k_max <= boundary < found.k_max + 0.27434824


def test_each_output_states_its_settings_and_verdict():
    """The seed's Phantom preset keeps the seed's settings and criteria by default (its number unchanged: 6 N m/rad
    of the analytic method, Table 4.4's scale); a device file gets practice's settings and the stability limit;
    each says so."""
    runner = CliRunner()
    seed = json.loads(runner.invoke(app, ["impedance-range", "--method", "analytic", "--json"]).stdout)
    assert seed["settings"]["compensation"] == "full" and seed["settings"]["delay"] == 0
    assert seed["verdict"].startswith("seed performance criteria") and seed["k_max"] == 6.0
    path = str(EXAMPLES / "five-bar.yaml")
    practice = json.loads(runner.invoke(app, ["impedance-range", "--device", path, "--json"]).stdout)
    assert practice["settings"] == SampledLoop().as_dict() and practice["method"] == "limit"
    assert practice["verdict"].startswith("stability limit")
    asked = json.loads(runner.invoke(app, ["impedance-range", "--device", path, "--settings", "seed", "--method",
                                           "analytic", "--json"]).stdout)
    assert asked["settings"] == SampledLoop.seed().as_dict()


def test_a_wall_gravity_pulls_away_from_is_stable_only_above_gravitys_pull():
    """The five-bar stands up, so without compensation gravity pulls joint 1 away from a joint wall (joint 2 held):
    springs softer than ``-dG_1/dq_1`` cannot hold it. A real pole leaves the unit circle at z = 1 exactly where the
    static stiffness ``K + dG_1/dq_1`` vanishes, so the interval's lower end is gravity's stiffness at the pose the
    wall holds (central differences of ``G``), and the command says so; the grid starts above it."""
    from hapticdesign.analysis.dynamics.device import gravity

    path = str(EXAMPLES / "five-bar.yaml")
    found = CliRunner().invoke(app, ["impedance-range", "--device", path, "--compensation", "none", "--joint", "1",
                                     "--hold", "2", "--resolution", "0.01", "--json"])
    assert found.exit_code == 0, found.output
    out = json.loads(found.stdout)
    device, pose = _device("five-bar"), np.array(out["pose"])
    step = 1e-5
    k_g = (gravity(device, pose + [step, 0.0])[0] - gravity(device, pose - [step, 0.0])[0]) / (2 * step)
    assert k_g < 0 and out["k_limit_lower"] == pytest.approx(-k_g, rel=1e-6)
    assert out["k_min"] == pytest.approx(math.ceil(-k_g / 0.01) * 0.01) and out["k_max"] > out["k_min"]
    text = CliRunner().invoke(app, ["impedance-range", "--device", path, "--compensation", "none", "--joint", "1",
                                    "--hold", "2", "--resolution", "0.01"])
    assert f"springs below {-k_g:.6g} N m/rad are unstable too" in text.stdout
