"""Workspace grids and reaching them (:mod:`hapticdesign.analysis.workspace`).

Oracles: the grid's definition (edges included, the centre on axes of size 0, neighbours one spacing apart in
snake order) and the forward kinematics of the poses reached (checked against Pinocchio elsewhere).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.workspace import Workspace, reach_workspace
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.errors import UserError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"


def test_grid_points_edges_and_snake_order():
    space = Workspace((0.1, 0.0, 0.2), (0.04, 0.0, 0.06), 4)
    points = space.points()
    assert points.shape == (16, 3)
    np.testing.assert_allclose(np.unique(points[:, 0].round(12)), [0.08, 0.1 - 0.04 / 6, 0.1 + 0.04 / 6, 0.12])
    np.testing.assert_allclose(np.unique(points[:, 2].round(12)), [0.17, 0.19, 0.21, 0.23])
    assert np.all(points[:, 1] == 0.0)
    steps = np.abs(np.diff(points, axis=0))
    assert np.all(np.isclose(steps, 0.0) | np.isclose(steps, [0.04 / 3, 0.0, 0.02]))
    assert np.all(np.count_nonzero(~np.isclose(steps, 0.0), axis=1) == 1)  # one axis at a time
    assert len(np.unique(points.round(12), axis=0)) == 16


def test_three_axes_and_the_centre_alone():
    assert Workspace((0, 0, 0), (0.1, 0.1, 0.1), 3).points().shape == (27, 3)
    np.testing.assert_array_equal(Workspace((1, 2, 3), (0, 0, 0), 5).points(), [[1.0, 2.0, 3.0]])


@pytest.mark.parametrize("args, message", [
    (((0, 0, 0), (-0.1, 0, 0), 3), "size"),
    (((0, 0, np.nan), (0.1, 0, 0), 3), "centre"),
    (((0, 0, 0), (0.1, 0, 0), 1), "at least 2"),
    (((0, 0, 0), (0.1, 0.1, 0.1), 30), "above the limit"),
])
def test_bad_workspaces_are_refused(args, message):
    with pytest.raises(UserError, match=message):
        Workspace(*args)


@pytest.mark.parametrize("name, centre, size", [
    ("five-bar", (0.0, 0.0, 0.18), (0.06, 0.0, 0.06)),
    ("delta", (-0.10, 0.0, 0.0), (0.03, 0.03, 0.03)),
])
def test_reached_poses_put_the_handle_on_the_points(name, centre, size):
    device = load_device_file(EXAMPLES / f"{name}.yaml")
    points = Workspace(centre, size, 3).points()
    poses = reach_workspace(device, points)
    space = configuration_of(device)
    for q_a, full, point in zip(poses.q, poses.full, points):
        np.testing.assert_allclose(space.pose(q_a)[:3, 3], point, atol=1e-10)
        np.testing.assert_allclose(full[space.solver.closures.actuated], q_a, atol=0)
        assert np.abs(space.solver.residual(full)).max() < 1e-10


def test_a_point_out_of_reach_is_named():
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    with pytest.raises(UserError, match=r"cannot reach \(0, 0, 0.5\) m"):
        reach_workspace(device, np.array([[0.0, 0.0, 0.18], [0.0, 0.0, 0.5]]))
