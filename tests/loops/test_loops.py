"""The loops contract of device files: errors, the command line, and LN by quadrature.

Numbers come from independent references: brute-force averaging of the entries H, C, G computed
pose by pose (the midpoint rule, whose error falls as 1/n^2) for LN; the five-bar's closed form
(circle intersection) for the command line.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import coriolis_centrifugal, dynamics_of, gravity, mass_matrix
from hapticdesign.analysis.linearity.form import linearity_form
from hapticdesign.analysis.linearity.region import Region
from hapticdesign.devices.device_file import device_from_mapping, load_device_file
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"


def _five_bar(**changes) -> dict:
    data = yaml.safe_load((EXAMPLES / "five-bar.yaml").read_text())
    data.update(changes)
    return data


# -- errors: one line each ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "changes, message",
    [
        ({"loops": [{"frames": ["tip1", "tip2"], "close": "position"}]}, "redundant loop closures: 3 constraint"),
        ({"loops": [{"frames": ["tip1", "tip2"], "close": ["x"]}]}, "insufficient loop closures: 1 constraint"),
        ({"loops": [{"frames": ["tip1", "nowhere"], "close": ["x", "z"]}]}, "loops[0].frames: unknown frame 'nowhere'"),
        ({"loops": [{"frames": ["tip1", "tip2"], "close": ["x", "w"]}]}, "unknown component 'w'"),
        ({"assembly": {"p1": -1.08}}, "assembly: give a value near the intended branch at home for passive joint p2"),
        ({"assembly": {"p1": -1.08, "p2": 1.1, "q1": 0.0}}, "assembly: 'q1' is not a passive joint"),
        ({"home": {"p1": 0.0}}, "home: 'p1' is not an actuated joint"),
        ({"loops": []}, "passive joint p1 needs loops"),
    ],
)
def test_contract_errors_are_one_line(changes, message):
    with pytest.raises(UserError) as info:
        device_from_mapping(_five_bar(**changes), "five.yaml")
    text = str(info.value)
    assert message in text and "\n" not in text


def test_loops_that_cannot_close_at_home():
    data = _five_bar(parameters={"d": 0.08, "l1": 0.10, "l2": 0.02})  # distal links far too short
    device = device_from_mapping(data, "short.yaml")
    with pytest.raises(UserError, match="cannot close at the home pose"):
        mass_matrix(device, np.array([2.0, 1.1]))


SHORT = {"d": 0.08, "l1": 0.10, "l2": 0.12}  # d + 2 l1 > 2 l2: cranks pointing apart cannot close


def test_leaving_the_workspace_is_a_one_line_error():
    device = device_from_mapping(_five_bar(parameters=SHORT), "short.yaml")
    mass_matrix(device, np.array([2.0, 1.1]))
    with pytest.raises(UserError) as info:
        mass_matrix(device, np.array([3.1, 0.0]))  # proximal links point apart: the distal links cannot meet
    assert "at q = (3.1, 0)" in str(info.value) and "\n" not in str(info.value)


def test_explicit_status_instead_of_an_error():
    device = device_from_mapping(_five_bar(parameters=SHORT), "short.yaml")
    path = np.array([[2.0, 1.1], [2.5, 0.8], [3.1, 0.0], [2.0, 1.1]])
    q, status = dynamics_of(device).solver.solve(path, strict=False)
    assert status[:2].tolist() == [0, 0] and status[2] != 0


def test_branch_is_kept_along_a_motion():
    """Continuation keeps elbows out: the handle stays the upper circle intersection along a long motion."""
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    t = np.linspace(0.0, 1.0, 200)[:, None]
    path = np.array([2.0, 1.1]) + 0.35 * np.hstack([np.sin(6 * t), np.sin(4 * t)])
    q = dynamics_of(device).full_coordinates(path)
    one_by_one = np.array([dynamics_of(device).full_coordinates(p) for p in path[::40]])
    np.testing.assert_allclose(q[::40], one_by_one, atol=1e-12)


# -- command line -------------------------------------------------------------------------------------
def test_dynamics_command_in_actuated_coordinates():
    result = CliRunner().invoke(app, ["dynamics", "--device", str(EXAMPLES / "five-bar.yaml"), "--q", "2.0,1.1",
                                      "--qd", "1,0.5", "--qdd", "0.2,-0.3", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)
    assert set(out) == {"device", "q", "qd", "qdd", "H", "C", "C_cvt", "G", "tau", "units", "handle", "assembly_branch"}
    assert np.shape(out["H"]) == (2, 2) and np.shape(out["C"]) == (2, 3) and np.shape(out["C_cvt"]) == (2, 2)
    # the printed parts assemble the printed torque (seed 000 eq. 2.50)
    tau = np.array(out["tau"])
    h, c, g = np.array(out["H"]), np.array(out["C"]), np.array(out["G"])
    qd, qdd = np.array([1.0, 0.5]), np.array([0.2, -0.3])
    np.testing.assert_allclose(tau, h @ qdd + c @ np.array([qd[0] ** 2, qd[0] * qd[1], qd[1] ** 2]) + g, rtol=1e-12)


def test_dynamics_command_reports_an_unreachable_pose(tmp_path):
    path = tmp_path / "short.yaml"
    path.write_text(yaml.safe_dump(_five_bar(parameters=SHORT)))
    result = CliRunner().invoke(app, ["dynamics", "--device", str(path), "--q", "3.1,0"])
    assert result.exit_code == 2
    assert "error: at q = (3.1, 0)" in result.output


def test_metrics_command_on_the_delta():
    result = CliRunner().invoke(app, ["metrics", "--device", str(EXAMPLES / "delta.yaml"), "--q", "0.35,0.35,0.35",
                                      "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)
    # at the symmetric home pose the handle velocity ellipsoid is a spheroid: two equal radii
    radii = np.sort(out["velocity_ellipsoid_radii"])
    assert min(abs(radii[0] - radii[1]), abs(radii[1] - radii[2])) <= 1e-12 * radii.max()


# -- LN: quadrature against brute-force averaging ----------------------------------------------------
def _brute_force_ln(device, box, n: int) -> float:
    """Midpoint-rule average over an n x n grid: variance of H and G entries plus mean square of C."""
    axes = [lo + (np.arange(n) + 0.5) * (hi - lo) / n for lo, hi in box]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
    h, c, g = [], [], []
    for q in grid:
        h.append(mass_matrix(device, q))
        c.append(coriolis_centrifugal(device, q))
        g.append(gravity(device, q))
    h, c, g = np.array(h), np.array(c), np.array(g)
    return float(h.var(axis=0).sum() + (c**2).mean(axis=0).sum() + g.var(axis=0).sum())


def test_ln_quadrature_agrees_with_brute_force_averaging():
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    box = [(1.8, 2.2), (0.9, 1.3)]
    form = linearity_form(dynamics_of(device), Region({0: box[0], 1: box[1]}))
    assert form.accuracy <= 1e-9
    ln = float(form.ln(device.standard_parameters()))
    errors = [abs(_brute_force_ln(device, box, n) - ln) for n in (8, 16)]
    # the midpoint rule is second order: halving the spacing divides its error by 4 (3 to 5 allowed
    # for the higher-order terms) -- it converges to the quadrature's value, not to another one
    assert 3.0 < errors[0] / errors[1] < 5.0
    assert errors[1] < 1e-2 * ln


def test_ln_is_a_quadratic_form_for_loops():
    device = load_device_file(EXAMPLES / "delta.yaml")
    form = linearity_form(dynamics_of(device), Region({k: (0.25, 0.45) for k in range(3)}))
    pi = device.standard_parameters()
    np.testing.assert_allclose(form.ln(2 * pi), 4 * form.ln(pi), rtol=1e-12)
    assert np.linalg.eigvalsh(form.total).min() >= -1e-12 * np.abs(form.total).max()
