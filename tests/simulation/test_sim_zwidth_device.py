"""A device's Z-width along a Cartesian wall, every actuated joint free (issue 44 item 2).

Against python-control's interconnection of a two-joint plant discretized with ``control.c2d`` and the digital side
written here (no code of the package's loop), against the exact n-joint limit that ``impedance-range
--wall-direction`` and the spec sheet's worst direction take, and the held view (``--one-dof``) against the 1-DOF
Z-width of the joint's ``J / J_n^2`` and ``b / J_n^2``.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import control
import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics.device import gravity_gradient, mass_matrix
from hapticdesign.analysis.sampled_loop import SampledLoop
from hapticdesign.analysis.wall_stiffness import worst_direction
from hapticdesign.devices.loading import resolve_device
from hapticdesign.interface.cli import app
from hapticdesign.simulation.config import handle_jacobian, loop_model
from hapticdesign.simulation.impedance import stability_limit
from hapticdesign.simulation.zwidth import along_wall, wall_zwidth, zwidth

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
runner = CliRunner()

# Two prismatic joints in the horizontal plane (gravity does no work on them): H = diag(0.7, 0.2) kg,
# b = diag(2, 1) N s/m, J_v = [I; 0]; a wall along (1, 2) couples both joints, neither principal for H nor for b.
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
SLANT = np.array([1.0, 2.0, 0.0]) / np.sqrt(5.0)


@pytest.fixture(scope="module")
def gantry(tmp_path_factory):
    path = tmp_path_factory.mktemp("gantry") / "gantry.yaml"
    path.write_text(GANTRY)
    return path


def _oracle_radius(mass, damping, w, period, k, damper) -> float:
    """The loop of practice's settings (one sample of delay, the damper on the backward difference) built with
    python-control: the plant ``H qdd + b qd = u`` with output q discretized by ``c2d`` (zero-order hold), the
    controller ``u_k = -(K w w^T) q_(k-1) - B w w^T (q_(k-1) - q_(k-2)) / T`` a discrete state-space system (state:
    the last two positions), joined by ``control.feedback``; the largest pole modulus but the neutral drift along the
    wall (the pose change ``w^T q = 0`` nothing resists, a pole at 1 whatever K)."""
    n = len(w)
    hinv = np.linalg.inv(mass)
    a = np.block([[np.zeros((n, n)), np.eye(n)], [np.zeros((n, n)), -hinv @ damping]])
    plant = control.c2d(control.ss(a, np.vstack([np.zeros((n, n)), hinv]), np.hstack([np.eye(n), np.zeros((n, n))]),
                                   np.zeros((n, n))), period, method="zoh")
    ww = np.outer(w, w)
    # controller state z = (q_(k-1), q_(k-2)), input q_k
    ac = np.block([[np.zeros((n, n)), np.zeros((n, n))], [np.eye(n), np.zeros((n, n))]])
    bc = np.vstack([np.eye(n), np.zeros((n, n))])
    cc = np.hstack([-k * ww - damper / period * ww, damper / period * ww])
    closed = control.feedback(plant, control.ss(ac, bc, cc, np.zeros((n, n)), period), sign=1)
    poles = control.poles(closed)
    return float(np.max(np.abs(poles[np.abs(poles - 1.0) > 1e-7])))


def _oracle_limit(mass, damping, w, period, damper) -> float:
    lo, hi = 1e-3, 1.0
    assert _oracle_radius(mass, damping, w, period, lo, damper) < 1.0
    while _oracle_radius(mass, damping, w, period, hi, damper) < 1.0:
        lo, hi = hi, 2.0 * hi
    while hi - lo > 1e-10 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _oracle_radius(mass, damping, w, period, mid, damper) < 1.0 else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("damper", [0.0, 0.5, 3.0])
def test_every_joint_free_is_python_controls_two_joint_loop(gantry, damper):
    device = resolve_device(None, gantry, None)
    pose = np.zeros(2)
    mass, w = mass_matrix(device, pose), SLANT @ handle_jacobian(device, pose)[:3]
    assert mass == pytest.approx(np.diag([0.7, 0.2])) and w == pytest.approx(SLANT[:2])
    expected = _oracle_limit(mass, np.diag(device.damping), w, 1e-3, damper)
    found = wall_zwidth(device, pose, SLANT, SampledLoop(), [damper]).K[0]
    assert found == pytest.approx(expected, rel=1e-7)
    held = zwidth(*along_wall(mass[0, 0], device.damping[0], w[0]), SampledLoop(), [damper]).K[0]
    assert abs(held - found) > 0.05 * found  # the held view is another question here


def _devices():
    return [(resolve_device(None, EXAMPLES / "five-bar.yaml", None), (1.0, 0.0, 1.0)),
            (resolve_device(None, EXAMPLES / "delta.yaml", None), (0.0, 0.3, 1.0))]


@pytest.mark.parametrize("index", [0, 1])
@pytest.mark.parametrize("loop", [SampledLoop(), SampledLoop.seed(), SampledLoop(velocity="sampled", delay=2)])
def test_the_device_wall_is_impedance_ranges_limit(index, loop):
    """At home, every joint free: the Z-width's K at each damper is ``impedance-range``'s exact limit at the wall's
    equilibrium 0 (the closed-loop five-bar and delta, gravity's gradient in the loop)."""
    device, direction = _devices()[index]
    home = configuration_of(device).home
    dampers = [0.0, 0.7]
    result = wall_zwidth(device, home, direction, loop, dampers)
    for b, k in zip(dampers, result.K):
        assert k == pytest.approx(stability_limit(device, replace(loop, wall_damping=b), equilibrium=0.0,
                                                  direction=direction).stiffness, rel=1e-12)
    assert result.passivity is None and result.as_dict()["units"] == {"B": "N s/m", "K": "N/m"}


def test_along_the_spec_sheets_worst_direction_it_is_the_sheets_limit():
    device, _ = _devices()[0]
    home = configuration_of(device).home
    loop = SampledLoop()
    limit, direction, _ = worst_direction(handle_jacobian(device, home)[:3], mass_matrix(device, home),
                                          device.damping_matrix, loop, gravity_gradient(device, home),
                                          loop_model(device, loop, home), device.transmission)
    assert wall_zwidth(device, home, direction, loop, [0.0]).K[0] == pytest.approx(limit, rel=1e-9)


def test_cli_every_joint_free_by_default_and_the_held_view_by_name(gantry):
    """``zwidth --device ... --wall-direction``: impedance-range's limit (its ``k_limit_exact``) at each damper, the
    settings holding no joint; ``--one-dof`` the 1-DOF view of --joint with the other joint held, as before."""
    args = ["--device", str(EXAMPLES / "five-bar.yaml"), "--wall-direction", "1,0,1"]
    free = runner.invoke(app, ["zwidth", *args, "--b-values", "0,0.7", "--json"])
    assert free.exit_code == 0, free.output
    out = json.loads(free.stdout)
    assert out["settings"]["held_joints"] == [] and out["units"] == {"B": "N s/m", "K": "N/m"}
    assert out["loop"]["wall_direction"] == pytest.approx([2 ** -0.5, 0.0, 2 ** -0.5])
    for b, k in zip(out["B"], out["K"]):
        ranged = runner.invoke(app, ["impedance-range", *args, "--wall-damping", str(b), "--k-limit", "1", "--json"])
        assert ranged.exit_code == 0, ranged.output
        assert k == pytest.approx(json.loads(ranged.stdout)["k_limit_exact"], rel=1e-12)
    device = resolve_device(None, gantry, None)
    held = json.loads(runner.invoke(app, ["zwidth", "--device", str(gantry), "--wall-direction", "1,2,0", "--one-dof",
                                          "--b-values", "0", "--json"]).stdout)
    assert held["settings"]["held_joints"] == [2]
    assert held["K"][0] == pytest.approx(zwidth(*along_wall(0.7, 2.0, SLANT[0]), SampledLoop(), [0.0]).K[0], rel=1e-12)
    free = json.loads(runner.invoke(app, ["zwidth", "--device", str(gantry), "--wall-direction", "1,2,0",
                                          "--b-values", "0", "--json"]).stdout)
    assert free["K"][0] == pytest.approx(_oracle_limit(np.diag([0.7, 0.2]), np.diag(device.damping), SLANT[:2], 1e-3,
                                                       0.0), rel=1e-7)


@pytest.mark.parametrize("args, fragment", [
    (["--wall-direction", "0,0,1"], "does not move along the wall"),
    (["--one-dof"], "--one-dof views a Cartesian wall"),
])
def test_cli_refusals_are_one_line(gantry, args, fragment):
    result = runner.invoke(app, ["zwidth", "--device", str(gantry), *args, "--b-values", "0"])
    assert result.exit_code == 2 and fragment in result.output and len(result.output.strip().splitlines()) == 1
