"""The Cartesian virtual wall: F = -(K (x.n - x_eq) + B v.n) n at the handle, tau = J^T F."""

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.kinematics import forward_kinematics
from hapticdesign.devices.loading import resolve_device
from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError
from hapticdesign.simulation.analytic import AnalyticProblem
from hapticdesign.analysis.sampled_loop import SampledLoop
from hapticdesign.simulation.config import Compensator, LoopConfig, Wall
from hapticdesign.simulation.criteria import Criteria
from hapticdesign.simulation.impedance import ImpedanceProblem, grid_search, impedance_range
from hapticdesign.simulation.loop import simulate
from hapticdesign.simulation.paths import Held, Sine
from tests.helpers.reference import simulate_adaptive

GANTRY = """\
name: gantry
joints:
  - {name: x, type: prismatic, damping: 2.0}
  - {name: y, type: prismatic, damping: 1.0}
frames:
  - {name: carriage, parent: base, transforms: [tx: x]}
  - {name: handle, parent: carriage, transforms: [ty: y, tz: 0.05]}
end_effector: handle
bodies:
  - {name: c, frame: carriage, m: 0.5}
  - {name: h, frame: handle, m: 0.2}
"""
SLANT = (1.0, 0.0, 1.0)  # at 45 degrees to the x joint: J_n,x = 1/sqrt(2)


@pytest.fixture(scope="module")
def gantry(tmp_path_factory):
    path = tmp_path_factory.mktemp("gantry") / "gantry.yaml"
    path.write_text(GANTRY)
    return resolve_device(None, path, None)


def test_a_slanted_wall_on_a_prismatic_joint_is_the_joint_wall(gantry):
    """``x.n = x / sqrt 2`` and ``J_n = (1/sqrt 2, 0)``: the Cartesian wall (K, B, x_eq) is the joint wall
    (K/2, B/2, sqrt(2) x_eq) on x, to rounding; the driven y joint does not move the handle along n."""
    k, b, x_eq = 30.0, 0.4, 0.01
    paths = {1: Sine(0.52, 3 * np.pi)}
    loop = SampledLoop.seed(error_percent=10, delay=1)
    cart = simulate(gantry, LoopConfig(duration=1.0, loop=replace(loop, wall_damping=b),
                                       wall=Wall(0, k, equilibrium=x_eq, direction=SLANT)), paths)
    joint = simulate(gantry, LoopConfig(duration=1.0, loop=replace(loop, wall_damping=b / 2),
                                        wall=Wall(0, k / 2, equilibrium=np.sqrt(2) * x_eq)), paths)
    assert np.abs(cart.q - joint.q).max() < 1e-12
    assert np.abs(cart.tau_imp[:, 0] - joint.tau_imp[:, 0]).max() < 1e-10
    assert np.allclose(cart.tau_imp[:, 1], 0.0, atol=1e-12)
    x_n = (cart.q[:, 0] + 0.05) / np.sqrt(2)  # the handle sits 0.05 m up z
    assert np.abs(cart.wall_position - x_n).max() < 1e-14
    assert cart.peak == pytest.approx(joint.peak / np.sqrt(2), rel=1e-9)


@pytest.mark.parametrize("paths", [{1: Held(0.0), 2: Held(0.0)}, {1: Sine(0.52, 3 * np.pi), 2: Sine(0.52, 3 * np.pi)}])
def test_phantom_cartesian_wall_matches_the_scipy_loop(paths):
    """The numba loop (compiled frame tree) against solve_ivp with the Python kinematics."""
    device = preset("phantom-3dof").with_params({"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05})
    config = LoopConfig(duration=0.3, wall=Wall(0, 150.0, equilibrium=0.005, direction=(0.3, 1.0, 0.2)),
                        loop=SampledLoop.seed(error_percent=20, delay=1, wall_damping=2.0))
    fast, slow = simulate(device, config, paths), simulate_adaptive(device, config, paths)
    assert np.abs(fast.q - slow.q).max() < 1e-9
    assert np.abs(fast.tau_imp - slow.tau_imp).max() < 1e-6 * max(1.0, np.abs(slow.tau_imp).max())
    assert np.abs(fast.wall_position - slow.wall_position).max() < 1e-9
    assert fast.peak == pytest.approx(slow.peak, rel=1e-6) and fast.peak > 1e-4


def test_the_handle_settles_where_the_spring_rests():
    """One link of 0.15 m turning about z, wall along y: the handle rests at y = x_eq, i.e. at
    ``q = asin(x_eq / 0.15)`` (the torque ``J_n K (0.15 sin q - x_eq)`` vanishes there only)."""
    device = resolve_device(None, Path(__file__).with_name("one_link.yaml"), None)
    trace = simulate(device, LoopConfig(duration=4.0, wall=Wall(0, 100.0, equilibrium=0.01, direction=(0.0, 1.0, 0.0)),
                                        loop=SampledLoop.seed(wall_damping=1.0)))
    assert trace.q[-1, 0] == pytest.approx(np.arcsin(0.01 / 0.15), rel=1e-6)
    y = forward_kinematics(device.mechanism, trace.q[-1])[1, 3]
    assert trace.wall_position[-1] == pytest.approx(y, abs=1e-15) and y == pytest.approx(0.01, rel=1e-6)


def test_the_wall_dissipates_without_a_compensator():
    """Energy sanity: from rest with only physical damping and the wall, the mechanical energy
    ``1/2 J qd^2 + 1/2 K (x.n - x_eq)^2`` at the end is below the spring's energy at the start."""
    device = resolve_device(None, Path(__file__).with_name("one_link.yaml"), None)
    k = 20.0
    config = LoopConfig(duration=4.0, wall=Wall(0, k, equilibrium=0.01, direction=(0.0, 1.0, 0.0)),
                        compensator=Compensator(inertial=False, coriolis=False, gravity=False))
    trace = simulate(device, config)
    energy = 0.5 * 0.007 * trace.qd[:, 0] ** 2 + 0.5 * k * (trace.wall_position - 0.01) ** 2
    assert energy[0] == pytest.approx(0.5 * k * 0.01 ** 2, rel=1e-12)
    assert energy[-1] < 1e-3 * energy[0]


def test_analytic_cartesian_boundary_equals_the_simulated_one(gantry):
    """Constant H (LN = 0), handle linear along n: the analytic grid answer is exact, type 1 and 2."""
    for sim_type in (1, 2):
        config = LoopConfig(wall=Wall(direction=SLANT), compensator=Compensator(gravity=False))
        criteria = Criteria()
        analytic = AnalyticProblem(gantry, sim_type, 0, 0.01, criteria, config)
        assert analytic.exact
        simulated = ImpedanceProblem(gantry, sim_type, 0, 0.01, criteria, config)
        a, s = grid_search(analytic, 0.25, 40.0), grid_search(simulated, 0.25, 40.0)
        assert a.k_max == s.k_max and a.k_min == s.k_min
        assert a.k_max > 0 and s.first_unstable.criterion == a.first_unstable.criterion


def test_analytic_cartesian_stiffness_is_the_joint_one_over_j_n_squared(gantry):
    """``K_joint = K J_n,w^2``: the same verdicts at K along n as at K / 2 on the joint (J_n,w^2 = 1/2)."""
    base = LoopConfig(compensator=Compensator(gravity=False))
    cart = AnalyticProblem(gantry, 1, 0, 0.01, Criteria(), replace(base, wall=Wall(direction=SLANT)))
    joint = AnalyticProblem(gantry, 1, 0, np.sqrt(2) * 0.01, Criteria(), base)
    for k in (2.0, 8.0, 11.0, 13.0, 30.0):
        along, on_joint = cart.response(k), joint.response(k / 2) / np.sqrt(2)
        assert np.abs(along - on_joint).max() <= 1e-9 * np.abs(on_joint).max()


def test_api_direction_and_refusals(gantry):
    found = impedance_range(gantry, 1, method="analytic", resolution=0.25, k_limit=40.0, wall_direction=(2, 0, 2))
    assert found.exact and found.k_max > 0
    with pytest.raises(UserError, match="direction"):
        impedance_range(gantry, 1, method="analytic", wall_direction=(0, 0, 0))
    with pytest.raises(UserError, match="does not move the handle"):
        impedance_range(gantry, 1, method="analytic", wall_direction=(0, 1, 0))


SLIDER = Path(__file__).with_name("slider.yaml")


def test_cli_cartesian_wall(tmp_path):
    """``--wall-direction``: the Z-width along n is the joint's with J / J_n^2 and b / J_n^2 (compensated,
    b^2 / (m J_n^2) = 16 N/m at J_n = 1/sqrt 2, the closed form of :mod:`.boundary`), and the analytic
    impedance range is reported in N/m."""
    from typer.testing import CliRunner

    from hapticdesign.interface.cli import app
    from hapticdesign.analysis.sampled_loop import compensated_boundary

    runner = CliRunner()
    path = SLIDER
    zw = runner.invoke(app, ["zwidth", "--device", str(path), "--wall-direction", "1,0,1", "--compensation", "full",
                             "--delay", "0", "--b-values", "0", "--json"])
    assert zw.exit_code == 0, zw.output
    out = json.loads(zw.stdout)
    assert out["units"] == {"B": "N s/m", "K": "N/m"}
    assert out["K"][0] == pytest.approx(compensated_boundary(0.5 * 2, 2.0 * 2, 1e-3), rel=1e-8)
    assert out["K"][0] == pytest.approx(16.0, rel=1e-8)
    result = runner.invoke(app, ["impedance-range", "--device", str(path), "--settings", "seed", "--method", "analytic",
                                 "--resolution", "0.25", "--wall-direction", "1,0,1", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["units"]["k_max"] == "N/m" and out["wall_direction"] == pytest.approx([2 ** -0.5, 0, 2 ** -0.5])
    api = impedance_range(resolve_device(None, path, None), 1, "analytic", resolution=0.25, wall_direction=(1, 0, 1))
    assert out["k_max"] == api.k_max
    bad = runner.invoke(app, ["impedance-range", "--device", str(path), "--wall-direction", "0,1,0", "--method",
                              "analytic"])
    assert bad.exit_code == 2 and "does not move the handle" in bad.output
    bad = runner.invoke(app, ["zwidth", "--inertia", "1", "--damping", "1", "--wall-direction", "1,0,0"])
    assert bad.exit_code == 2 and "--wall-direction needs a device" in bad.output
