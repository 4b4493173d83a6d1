"""The configuration space of a device (:func:`hapticdesign.analysis.configuration.configuration_of`).

Oracles: the loops' closure residual at the poses ``full`` returns (must vanish), the forward kinematics
(checked against Pinocchio in tests/dynamics/test_against_pinocchio.py) for inverse kinematics: the handle
position of a known actuated pose near home, found again from home on the same branch; ``T`` against
central differences of ``full``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"


@pytest.fixture(scope="module", params=["five-bar", "delta", "phantom-3dof"])
def device(request):
    if request.param == "phantom-3dof":
        return preset("phantom-3dof")
    return load_device_file(EXAMPLES / f"{request.param}.yaml")


def test_home_and_names(device):
    space = configuration_of(device)
    assert space is configuration_of(device)
    assert space.is_tree == (device.mechanism.loops is None)
    assert len(space.names) == len(space.home) == device.n_dof
    if not space.is_tree:
        np.testing.assert_array_equal(space.home, device.mechanism.loops.home)
        assert np.abs(space.solver.residual(space.full(space.home))).max() < 1e-10


def test_velocity_transform_is_the_derivative_of_full(device):
    space = configuration_of(device)
    q_a = space.home + 0.05
    eps = 1e-6
    numeric = np.column_stack([(space.full(q_a + eps * e) - space.full(q_a - eps * e)) / (2 * eps)
                               for e in np.eye(len(q_a))])
    np.testing.assert_allclose(space.velocity_transform(space.full(q_a)), numeric, rtol=0, atol=1e-7)


def test_inverse_kinematics_finds_a_known_pose_on_the_home_branch(device):
    space = configuration_of(device)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q_known = space.home + rng.uniform(-0.15, 0.15, len(space.home))
        target = space.pose(q_known)[:3, 3]
        q_found = space.inverse_kinematics(target)
        np.testing.assert_allclose(space.pose(q_found)[:3, 3], target, rtol=0, atol=1e-10)
        if len(space.home) == 3:  # square: the pose itself
            np.testing.assert_allclose(q_found, q_known, rtol=0, atol=1e-8)


def test_inverse_kinematics_refuses_a_target_out_of_reach(device):
    space = configuration_of(device)
    with pytest.raises(UserError, match="cannot reach"):
        space.inverse_kinematics(space.pose(space.home)[:3, 3] + np.array([5.0, 5.0, 5.0]))
