"""``home: {position: [x, y, z]}``: a closed-loop device's home given by its handle position, resolved by the
configuration space's inverse kinematics. Oracle: the five-bar's closed form (each motor's angle from the law
of cosines in the triangle of its pivot, its elbow and the handle), on the branch of the file's assembly."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
import yaml

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.devices.device_file import device_from_mapping
from hapticdesign.errors import UserError

FIVE_BAR = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"
D, L1, L2 = 0.08, 0.10, 0.14  # five-bar.yaml: motor spacing, proximal and distal links (m)


def _five_bar(home) -> dict:
    data = yaml.safe_load(FIVE_BAR.read_text())
    data["home"] = home
    return data


def _motor_angles(x: float, z: float, signs: tuple[int, int]) -> np.ndarray:
    """Each motor's angle that puts its distal link's end at (x, z) in the five-bar's vertical plane: the pivot
    at (-+d/2, 0), the triangle pivot-elbow-handle with sides l1, l2 and the pivot-handle distance rho."""
    out = []
    for pivot, sign in zip((-D / 2, D / 2), signs):
        dx, dz = x - pivot, z
        rho = math.hypot(dx, dz)
        out.append(math.atan2(dz, dx) + sign * math.acos((rho**2 + L1**2 - L2**2) / (2 * rho * L1)))
    return np.array(out)


def test_home_position_from_the_files_joint_home_stays_on_its_branch():
    """From the file's home (q1, q2) = (2.0, 1.1), elbows out (left elbow beyond, right elbow inside the
    pivot-handle line), to the handle at (20, 180) mm: the closed form's roots of that branch."""
    device = device_from_mapping(_five_bar({"q1": 2.0, "q2": 1.1, "position": [0.02, 0.0, 0.18]}))
    space = configuration_of(device)
    assert np.allclose(space.home, _motor_angles(0.02, 0.18, (+1, -1)), atol=1e-9)
    assert np.allclose(_motor_angles(0.003093, 0.2024, (+1, -1)), [2.0, 1.1], atol=2e-4)  # the file's home there
    q = space.full(space.home)
    elbow = np.array([-D / 2 + L1 * math.cos(q[0]), L1 * math.sin(q[0])])
    assert math.atan2(0.18 - elbow[1], 0.02 - elbow[0]) - q[0] == pytest.approx(q[2], abs=1e-9)  # p1, relative


def test_home_position_alone_starts_from_zero_joint_values():
    device = device_from_mapping(_five_bar({"position": [0.01, 0.0, 0.19]}))
    home = configuration_of(device).home
    roots = [_motor_angles(0.01, 0.19, (a, b)) for a in (1, -1) for b in (1, -1)]
    assert min(np.abs(home - r).max() for r in roots) < 1e-9


@pytest.mark.parametrize("home, message", [
    ({"position": [0.0, 0.0, 0.5]}, "home.position: the handle cannot reach"),
    ({"position": [0.0, 0.2]}, "home.position: a handle position is 3 numbers"),
    ({"q1": [0.0, 0.2, 0.1]}, "home.q1: a joint's home value is one number"),
    ({"position": [0.0, "x", 0.1]}, "home.position"),
])
def test_bad_home_positions_are_one_line(home, message):
    with pytest.raises(UserError) as caught:
        device_from_mapping(_five_bar(home))
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_a_tree_has_no_home_of_its_own():
    data = tomllib.loads((FIVE_BAR.parent / "arm-3r.toml").read_text())
    data["home"] = {"position": [0.3, 0.0, 0.3]}
    with pytest.raises(UserError, match="only a device with loops has a home"):
        device_from_mapping(data)


def test_cli_refuses_an_unreachable_home_position_in_one_line(tmp_path):
    from typer.testing import CliRunner

    from hapticdesign.interface.cli import app

    path = tmp_path / "far.yaml"
    path.write_text(yaml.safe_dump(_five_bar({"position": [0.0, 0.0, 0.5]})))
    result = CliRunner().invoke(app, ["ik", "--device", str(path), "--position", "0,0,0.2"])
    lines = result.output.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1 and "home.position" in lines[0]
