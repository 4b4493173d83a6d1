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
    assert len(space.names) == len(space.home) == device.n_dof
    loops = device.mechanism.loops
    np.testing.assert_array_equal(space.home, loops.home if loops.closures else np.zeros(device.n_dof))  # a tree's: 0
    assert np.abs(space.solver.residual(space.full(space.home))).max(initial=0.0) < 1e-10


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


def test_a_redundant_arm_moves_by_the_least_norm_joint_motion():
    """The Phantom with its gimbal (6 joints, a 3-D handle position) is redundant: the one IK takes least-norm steps,
    so a small move ``dp`` from home moves the joints by ``pinv(J_v) dp`` to first order (``J_v`` by central
    differences of the forward kinematics, the pseudo-inverse NumPy's): the relative difference shrinks with the move
    (a second-order term), where another choice among the joint motions (the gimbal held, say: 1e-2) would not."""
    space = configuration_of(preset("phantom-6dof"))
    start = space.pose(space.home)[:3, 3]
    eps = 1e-6
    jac = np.column_stack([(space.pose(space.home + eps * e)[:3, 3] - space.pose(space.home - eps * e)[:3, 3])
                           / (2 * eps) for e in np.eye(6)])
    errors = []
    for size in (1e-5, 1e-6):
        move = size * np.array([2.0, -1.0, 1.5])
        q = space.inverse_kinematics(start + move)
        np.testing.assert_allclose(space.pose(q)[:3, 3], start + move, rtol=0, atol=1e-12)
        expected = np.linalg.pinv(jac) @ move
        errors.append(np.abs(q - space.home - expected).max() / np.abs(expected).max())
    assert errors[1] < 0.2 * errors[0] and errors[1] < 1e-3
