"""The rendering loop on closed-loop devices (the five-bar and the delta of examples/devices).

References, none of which imports the numba loop: the plain SciPy loop (:mod:`tests.helpers.reference`,
``solve_ivp`` RK45 with H, C, G from the closed-loop model's slow exact path); the 1-DOF limit
``b^2 / H_ww`` of full inertial compensation (seed 000 §4.1.2, :mod:`hapticdesign.analysis.sampled_loop`)
with ``H_ww`` from :func:`hapticdesign.mass_matrix`; the kinetic energy ``qd^T H qd / 2`` of a free,
undamped motion without gravity, which must stay constant.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import cumulative_simpson
from typer.testing import CliRunner

import hapticdesign as hd
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.interface.cli import app
from hapticdesign.simulation.boundary import envelope_grows
from hapticdesign.analysis.sampled_loop import SampledLoop
from hapticdesign.simulation.config import Compensator, LoopConfig, Wall, rest_pose
from hapticdesign.simulation.loop import simulate
from hapticdesign.simulation.paths import Held, Sine
from tests.helpers.reference import simulate_adaptive

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
WALL_JOINT = {"five-bar": 1, "delta": 2}


@pytest.fixture(scope="module", params=["five-bar", "delta"])
def device(request):
    return load_device_file(EXAMPLES / f"{request.param}.yaml")


def _paths(device, sim_type: int, amplitude: float = 0.1) -> dict:
    """The other joints held at home (type 1) or driven about it (type 2, a smaller sine than the seed's)."""
    home, w = rest_pose(device), WALL_JOINT[device.name]
    return {j: (Held(home[j]) if sim_type == 1 else Sine(amplitude, 3 * np.pi, home[j]))
            for j in range(device.n_dof) if j != w}


@pytest.mark.parametrize("sim_type, control", [(1, "auto"), (2, "auto"), (1, "fixed")])
def test_kernel_matches_the_scipy_reference_loop(device, sim_type, control):
    """RK4 (error-controlled steps, the default for closed loops, or every 1e-4-s plant step) against
    RK45 at rtol 1e-8, with a model error, a delay and a damped wall: the two integrators agree to their
    own accuracy (the closure's Newton tolerance is far below it)."""
    home, w = rest_pose(device), WALL_JOINT[device.name]
    config = LoopConfig(duration=0.2, wall=Wall(w, 0.05, equilibrium=home[w] + 0.01), step_control=control,
                        loop=SampledLoop.seed(error_percent=20, delay=1, wall_damping=0.001),
                        compensator=Compensator(error_seed=3))
    paths = _paths(device, sim_type)
    fast = simulate(device, config, paths)
    slow = simulate_adaptive(device, config, paths, q0=home)
    assert fast.status == slow.status == 0
    assert fast.steps == 2000 if control == "fixed" else fast.steps < 400  # 200 sample periods of 10 plant steps
    assert fast.q.shape == slow.q.shape
    assert np.abs(fast.q[:, w] - home[w]).max() > 1e-3  # the wall joint moved
    assert np.abs(fast.q - slow.q).max() < 1e-8
    assert np.abs(fast.u - slow.u).max() < 1e-6 * np.abs(slow.u).max()
    assert np.abs(fast.tau_c - slow.tau_c).max() < 1e-6 * max(np.abs(slow.tau_c).max(), 1e-9)


def test_stable_and_unstable_stiffness_bracket_the_limit(device):
    """Type 1, full compensation, no delay: the wall oscillation decays at 0.9 b^2 / H_ww and grows at
    1.1 b^2 / H_ww; the search's k_max (overshoot criterion, stricter) lies below the growing one."""
    home, w = rest_pose(device), WALL_JOINT[device.name]
    b = device.damping[w]
    limit = b * b / hd.mass_matrix(device, home)[w, w]
    base = LoopConfig(duration=4.0)
    grows = []
    for k in (0.9 * limit, 1.1 * limit):
        trace = simulate(device, LoopConfig(duration=4.0, wall=Wall(w, k, equilibrium=home[w] + 0.01)), _paths(device, 1))
        assert trace.status == 0
        grows.append(envelope_grows(trace.q[:, w] - (home[w] + 0.01)))
    assert grows == [False, True]
    found = hd.impedance_range(device, 1, wall_joint=w, resolution=limit / 20, k_limit=1, config=base)
    assert 0 < found.k_max < 1.1 * limit
    assert found.first_unstable is not None and not found.first_unstable.stable


def test_analytic_search_equals_the_simulated_one(device):
    """Type 1: the wall joint's loop linearized at home (H and G of the closed loop at home) gives the
    simulated search's k_max on the same grid (the 0.01-rad step keeps the loop near its linearization)."""
    w = WALL_JOINT[device.name]
    limit = device.damping[w] ** 2 / hd.mass_matrix(device, rest_pose(device))[w, w]
    found = {method: hd.impedance_range(device, 1, method=method, wall_joint=w, resolution=limit / 10, k_limit=1)
             for method in ("fast", "analytic")}
    assert found["fast"].k_max > 0
    assert found["fast"].k_max == found["analytic"].k_max


def test_free_undamped_motion_conserves_energy(device):
    """Every joint free from home, no damping, wall or compensation: the device falls under gravity (for
    0.1 s, before it reaches a singular pose) and
    ``qd^T H qd / 2 + integral of G . qd dt`` stays at 0 (H and G from the slow exact path; the integral by
    Simpson's rule at 0.5 ms, whose error is far below the bound, as is RK4's drift at 1e-4 s)."""
    home = rest_pose(device)
    config = LoopConfig(duration=0.1, wall=Wall(0, 0.0, equilibrium=0.0), damping=np.zeros(device.n_dof),
                        compensator=Compensator(False, False, False), safety_limit=None, record_stride=5)
    trace = simulate(device, config)
    assert trace.status == 0
    assert np.abs(trace.q[-1] - home).max() > 0.05  # it fell
    h, g = hd.mass_matrix(device, trace.q), hd.gravity(device, trace.q)
    kinetic = 0.5 * np.einsum("pi,pij,pj->p", trace.qd, h, trace.qd)
    work = cumulative_simpson(np.einsum("pi,pi->p", g, trace.qd), x=trace.t, initial=0.0)
    assert np.abs(kinetic + work).max() < 1e-6 * kinetic.max()


def test_a_run_that_leaves_the_branch_ends_with_its_status():
    """The delta's first joint swung by 2 rad leaves the assembly branch: status 'loop lost', no crash."""
    delta = load_device_file(EXAMPLES / "delta.yaml")
    home = rest_pose(delta)
    paths = {0: Sine(2.0, 2 * np.pi, home[0]), 1: Held(home[1]), 2: Held(home[2])}
    trace = simulate(delta, LoopConfig(duration=1.0, wall=Wall(0, 0.0, equilibrium=home[0])), paths)
    assert trace.loop_lost and 0 < trace.end_time < 1.0
    assert np.all(np.isfinite(trace.q))


def test_cli_one_line_error_when_the_chirp_leaves_the_branch():
    result = CliRunner().invoke(app, ["transparency", "--device", str(EXAMPLES / "delta.yaml"), "--joint", "1",
                                      "--stiffness", "0.005", "--amplitude", "2", "--sweep", "2", "--f1", "10"])
    assert result.exit_code == 2
    assert "assembly branch" in result.output and len(result.output.strip().splitlines()) == 1


@pytest.mark.parametrize("joint", ["1", "2"])
def test_cli_impedance_range_and_transparency_on_the_five_bar(joint):
    runner = CliRunner()
    five_bar = str(EXAMPLES / "five-bar.yaml")
    result = runner.invoke(app, ["impedance-range", "--device", five_bar, "--joint", joint, "--resolution", "0.01",
                                 "--k-limit", "1", "--json"])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["transparency", "--device", five_bar, "--joint", joint, "--stiffness", "0.1",
                                 "--sweep", "2", "--f1", "10", "--json"])
    assert result.exit_code == 0, result.output
