"""The frame tree: poses are products of elementary matrices along the path, and bad trees are refused."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from hapticdesign.errors import UserError
from hapticdesign.model.loops import component_indices
from hapticdesign.model.mechanism import BodyAttachment, Frame, JointType, Mechanism
from hapticdesign.model.transforms import Rx, Rz, combination, joint, tx, tz

R = JointType.REVOLUTE


def _arm(**changes) -> Mechanism:
    frames = (
        Frame("f1", None, (Rz(joint(0)), tz(0.1))),
        Frame("f2", "f1", (Rx(joint(1)), tx(0.2))),
        Frame("f3", "f1", (Rx(combination({1: 1.0, 2: -1.0}, 0.3)), tx(0.15))),
    )
    kwargs = dict(coordinates=("a", "b", "c"), joint_types=(R, R, R), frames=frames,
                  bodies=(BodyAttachment("l2", "f2"),), end_effector="f2")
    kwargs.update(changes)
    return Mechanism(**kwargs)


def test_frame_pose_is_the_product_along_the_path():
    q = np.array([0.7, -0.4, 0.9])
    mech = _arm()
    rz = Rotation.from_euler("z", q[0]).as_matrix()
    p1 = np.array([0.0, 0.0, 0.1])
    rx2 = rz @ Rotation.from_euler("x", q[1]).as_matrix()
    np.testing.assert_allclose(mech.frame_pose(q, "f2")[:3, :3], rx2, atol=1e-15)
    np.testing.assert_allclose(mech.frame_pose(q, "f2")[:3, 3], p1 + rx2 @ [0.2, 0, 0], atol=1e-15)
    rx3 = rz @ Rotation.from_euler("x", 0.3 + q[1] - q[2]).as_matrix()
    np.testing.assert_allclose(mech.frame_pose(q, "f3")[:3, 3], p1 + rx3 @ [0.15, 0, 0], atol=1e-15)


@pytest.mark.parametrize("change, message", [
    ({"frames": (Frame("f1", None, ()), Frame("f1", "f1", ()))}, "unique"),
    ({"frames": (Frame("f1", "nowhere", ()),), "bodies": (), "end_effector": None}, "not defined before"),
    ({"frames": (Frame("f1", None, (Rz(joint(5)),)),), "bodies": (), "end_effector": None}, "out of range"),
    ({"bodies": (BodyAttachment("l9", "f9"),)}, "unknown frame"),
    ({"end_effector": "tip"}, "end-effector"),
])
def test_bad_trees_are_refused_in_one_line(change, message):
    with pytest.raises(UserError, match=message) as info:
        _arm(**change)
    assert "\n" not in str(info.value)


def test_closure_components():
    assert component_indices(["x", "z"]) == (0, 2)
    assert component_indices("position") == (0, 1, 2)
    assert component_indices("pose") == (0, 1, 2, 3, 4, 5)
    for bad in (["x", "x"], ["w"], [], "everything"):
        with pytest.raises(ValueError):
            component_indices(bad)
