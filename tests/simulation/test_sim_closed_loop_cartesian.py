"""A Cartesian virtual wall and a hand on closed-loop devices (the five-bar and the delta of examples/devices).

The wall acts along n at the handle, ``tau = J_n^T F`` with ``J_n = n^T J_v T`` in actuated coordinates. References,
none of which imports the numba loop: the plain SciPy loop (:mod:`tests.helpers.reference`, the handle's
position and Jacobian from :meth:`~hapticdesign.analysis.configuration.Configuration.pose` / ``jacobian`` at the pose
the loop solver closes); central differences of the handle's closed position; the 1-DOF limit ``b^2 / H_ww`` of full
inertial compensation (seed 000 §4.1.2), which a Cartesian stiffness K meets at ``K J_n,w^2 = b^2 / H_ww``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import hapticdesign as hd
from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.interface.cli import app
from hapticdesign.simulation.boundary import envelope_grows
from hapticdesign.analysis.sampled_loop import SampledLoop
from hapticdesign.simulation.config import Compensator, Hand, LoopConfig, Wall, normal_jacobian, rest_pose
from hapticdesign.simulation.loop import simulate
from hapticdesign.simulation.paths import Held, Sine
from tests.helpers.reference import simulate_adaptive

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
WALL_JOINT = {"five-bar": 1, "delta": 2}


@pytest.fixture(scope="module", params=["five-bar", "delta"])
def device(request):
    return load_device_file(EXAMPLES / f"{request.param}.yaml")


def _direction(device) -> np.ndarray:
    """The direction the handle moves in when the wall joint turns: the wall acts on that joint's motion."""
    v = configuration_of(device).jacobian(rest_pose(device))[:3, WALL_JOINT[device.name]]
    return v / np.linalg.norm(v)


def _paths(device, sim_type: int) -> dict:
    home, w = rest_pose(device), WALL_JOINT[device.name]
    return {j: (Held(home[j]) if sim_type == 1 else Sine(0.05, 3 * np.pi, home[j]))
            for j in range(device.n_dof) if j != w}


def test_normal_jacobian_is_the_derivative_of_the_closed_handle_position(device):
    """``J_n`` from ``J T`` equals central differences of ``n . p`` with the loops closed at each pose."""
    home, n = rest_pose(device), _direction(device)
    wall = Wall(0, 1.0, equilibrium=0.0, direction=tuple(n))
    eps = 1e-6
    numeric = [(n @ configuration_of(device).pose(home + eps * e)[:3, 3]
                - n @ configuration_of(device).pose(home - eps * e)[:3, 3]) / (2 * eps) for e in np.eye(device.n_dof)]
    assert np.allclose(normal_jacobian(device, wall, home), numeric, rtol=1e-7, atol=1e-10)


@pytest.mark.parametrize("sim_type", [1, 2])
def test_cartesian_wall_kernel_matches_the_scipy_reference_loop(device, sim_type):
    """RK4 at 1e-4 s against RK45 at rtol 1e-8: a damped Cartesian wall, 20 % model error, one sample of
    delay and (type 2) a hand at the handle."""
    home, w, n = rest_pose(device), WALL_JOINT[device.name], _direction(device)
    hand = Hand(mass=0.05, damping=0.5, stiffness=20.0) if sim_type == 2 else None
    config = LoopConfig(duration=0.2, wall=Wall(w, 50.0, equilibrium=0.002, direction=tuple(n)),
                        loop=SampledLoop.seed(hand=hand, error_percent=20, delay=1, wall_damping=0.2),
                        compensator=Compensator(error_seed=3))
    paths = _paths(device, sim_type)
    fast = simulate(device, config, paths)
    slow = simulate_adaptive(device, config, paths, q0=home)
    assert fast.status == slow.status == 0
    assert fast.q.shape == slow.q.shape
    assert np.abs(fast.q[:, w] - home[w]).max() > 1e-3  # the wall joint moved
    assert np.abs(fast.q - slow.q).max() < 1e-8
    assert np.abs(fast.u - slow.u).max() < 1e-6 * np.abs(slow.u).max()
    assert np.abs(fast.tau_imp).max() > 0.01 * np.abs(fast.u).max()  # the wall pushed


def test_cartesian_stiffness_brackets_the_joint_limit_over_j_n_squared(device):
    """Type 1, full compensation, no delay: the Cartesian wall's oscillation decays at 0.9 and grows at
    1.1 times ``b^2 / (H_ww J_n,w^2)`` (H_ww from :func:`hapticdesign.mass_matrix`)."""
    home, w, n = rest_pose(device), WALL_JOINT[device.name], _direction(device)
    wall = Wall(w, 1.0, equilibrium=0.0, direction=tuple(n))
    j_nw = normal_jacobian(device, wall, home)[w]
    limit = device.damping[w] ** 2 / hd.mass_matrix(device, home)[w, w] / j_nw ** 2
    rest = 0.01 * j_nw
    grows = []
    for k in (0.9 * limit, 1.1 * limit):
        config = LoopConfig(duration=4.0, wall=Wall(w, k, equilibrium=rest, direction=tuple(n)))
        trace = simulate(device, config, _paths(device, 1))
        assert trace.status == 0
        grows.append(envelope_grows(trace.wall_position - trace.wall_position[0] - rest))
    assert grows == [False, True]


def test_analytic_search_equals_the_simulated_one_for_a_cartesian_wall(device):
    """Type 1 with the wall's rest 0.01 J_n,w m from the start (the wall joint moves about 0.01 rad, as in the
    joint-wall searches): the loop linearized at home gives the simulated search's K_max on the same grid, and that
    K_max is at most the 1-DOF limit ``b^2 / (H_ww J_n,w^2)`` of full compensation, above which the wall grows (the
    previous test). Before the criteria scaled with the step, the delta's 0.64-mm step passed 1.2 times that limit
    (3.29 N/m, growing)."""
    home, w, n = rest_pose(device), WALL_JOINT[device.name], _direction(device)
    j_nw = normal_jacobian(device, Wall(w, 1.0, equilibrium=0.0, direction=tuple(n)), home)[w]
    limit = device.damping[w] ** 2 / hd.mass_matrix(device, home)[w, w] / j_nw ** 2
    found = {method: hd.impedance_range(device, 1, method=method, wall_joint=w, resolution=limit / 10, k_limit=20,
                                        equilibrium=0.01 * j_nw, wall_direction=n)
             for method in ("fast", "analytic")}
    assert found["fast"].k_max > 0
    assert found["fast"].k_max == found["analytic"].k_max
    assert found["fast"].k_max <= limit * (1 + 1e-12)


def test_cli_cartesian_wall_on_the_five_bar():
    """``impedance-range --wall-direction`` on a closed-loop device answers in N/m (it was refused before)."""
    n = _direction(load_device_file(EXAMPLES / "five-bar.yaml"))
    result = CliRunner().invoke(app, ["impedance-range", "--device", str(EXAMPLES / "five-bar.yaml"), "--joint", "2",
                                      "--method", "analytic", "--wall-direction", ",".join(f"{v:.12g}" for v in n),
                                      "--resolution", "1", "--k-limit", "100", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)
    assert out["k_max"] > 0 and out["wall_direction"] == pytest.approx(n)
