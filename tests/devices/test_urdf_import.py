"""URDF import against Pinocchio loading the same document (pin.buildModelFromXML)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from hapticdesign.analysis.dynamics.device import gravity, inverse_dynamics, mass_matrix
from hapticdesign.devices.loading import resolve_device
from hapticdesign.devices.urdf import device_from_urdf
from hapticdesign.errors import UserError

ARM = """<?xml version="1.0"?>
<robot name="test-arm">
  <link name="base_link">
    <inertial><mass value="2.0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base_link"/><child link="link1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/><dynamics damping="0.4"/>
  </joint>
  <link name="link1">
    <inertial>
      <origin xyz="0.01 0.02 0.05" rpy="0.1 -0.2 0.3"/><mass value="0.9"/>
      <inertia ixx="0.004" ixy="0.0002" ixz="-0.0001" iyy="0.005" iyz="0.0003" izz="0.003"/>
    </inertial>
  </link>
  <joint name="j2" type="revolute">
    <parent link="link1"/><child link="link2"/>
    <origin xyz="0.05 0 0.2" rpy="1.2 0 0.4"/><axis xyz="0 0.6 0.8"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/>
  </joint>
  <link name="link2">
    <inertial>
      <origin xyz="0.15 -0.01 0.02" rpy="0 0.3 0"/><mass value="1.1"/>
      <inertia ixx="0.002" ixy="-0.0003" ixz="0.0001" iyy="0.011" iyz="0.0002" izz="0.012"/>
    </inertial>
  </link>
  <joint name="j3" type="continuous">
    <parent link="link2"/><child link="link3"/>
    <origin xyz="0.3 0 0" rpy="0 0.2 -0.5"/><axis xyz="-1 0 0"/>
  </joint>
  <link name="link3">
    <inertial>
      <origin xyz="0.1 0.01 0" rpy="0.5 0 0"/><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0.0001" ixz="0" iyy="0.004" iyz="0" izz="0.0045"/>
    </inertial>
  </link>
  <joint name="j4" type="prismatic">
    <parent link="link3"/><child link="link4"/>
    <origin xyz="0.2 0 0.03"/><axis xyz="0.48 0.6 0.64"/>
    <limit lower="-0.1" upper="0.1" effort="10" velocity="1"/>
  </joint>
  <link name="link4">
    <inertial>
      <origin xyz="0 0 0.02"/><mass value="0.3"/>
      <inertia ixx="0.0003" ixy="0" ixz="0.00002" iyy="0.0002" iyz="0" izz="0.00015"/>
    </inertial>
  </link>
  <joint name="tool_joint" type="fixed">
    <parent link="link4"/><child link="tool"/><origin xyz="0 0.05 0.04" rpy="0.3 0.2 0.1"/>
  </joint>
  <link name="tool">
    <inertial>
      <origin xyz="0.01 0 0.01"/><mass value="0.2"/>
      <inertia ixx="0.0001" ixy="0.00001" ixz="0" iyy="0.00012" iyz="0" izz="0.00008"/>
    </inertial>
  </link>
</robot>
"""


def _pin_q(model: pin.Model, q: np.ndarray) -> np.ndarray:
    """Pinocchio's configuration: continuous joints use (cos q, sin q)."""
    out = []
    for joint in list(model.joints)[1:]:
        value = q[joint.idx_v]
        out += [np.cos(value), np.sin(value)] if joint.nq == 2 else [value]
    return np.array(out)


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


@pytest.fixture(scope="module")
def pair():
    device = device_from_urdf(ARM, "arm.urdf")
    model = pin.buildModelFromXML(ARM)
    return device, model, model.createData()


def test_structure(pair):
    device, model, _ = pair
    assert device.n_dof == model.nv == 4
    assert device.mechanism.coordinates == ("j1", "j2", "j3", "j4")
    assert device.damping == (0.4, 0.0, 0.0, 0.0)
    assert device.body_names == ("link1", "link2", "link3", "link4", "tool")
    assert device.mechanism.end_effector == "tool"


def test_mass_matrix_gravity_and_inverse_dynamics_match_pinocchio(pair):
    device, model, data = pair
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = rng.uniform(-np.pi, np.pi, 4)
        q[3] = rng.uniform(-0.1, 0.1)
        qd, qdd = rng.normal(size=4), rng.normal(size=4)
        qp = _pin_q(model, q)
        mass = pin.crba(model, data, qp)
        mass = np.triu(mass) + np.triu(mass, 1).T
        assert _relative(mass_matrix(device, q), mass) < 1e-9
        assert _relative(gravity(device, q), pin.computeGeneralizedGravity(model, data, qp)) < 1e-9
        assert _relative(inverse_dynamics(device, q, qd, qdd), pin.rnea(model, data, qp, qd, qdd)) < 1e-9


def test_end_effector_pose_matches_pinocchio(pair):
    device, model, data = pair
    q = np.array([0.3, -1.1, 2.0, 0.05])
    pin.framesForwardKinematics(model, data, _pin_q(model, q))
    expected = data.oMf[model.getFrameId("tool")].homogeneous
    np.testing.assert_allclose(device.mechanism.frame_pose(q, "tool"), expected, atol=1e-12)


def test_mimic_joint_is_a_coupling():
    """A mimic joint q2 = 0.5 + 2 q1: H = J^T H_full J and G = J^T G_full with the full chain from Pinocchio."""
    free = ARM.replace('<joint name="j2" type="revolute">', '<joint name="j2" type="revolute">'
                       '<mimic joint="j1" multiplier="2" offset="0.5"/>')
    device = device_from_urdf(free, "mimic.urdf")
    assert device.mechanism.coordinates == ("j1", "j3", "j4")
    model = pin.buildModelFromXML(ARM)
    data = model.createData()
    jac = np.array([[1, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    q = np.array([0.4, -0.7, 0.03])
    full = np.array([q[0], 0.5 + 2 * q[0], q[1], q[2]])
    qp = _pin_q(model, full)
    mass = pin.crba(model, data, qp)
    mass = np.triu(mass) + np.triu(mass, 1).T
    assert _relative(mass_matrix(device, q), jac.T @ mass @ jac) < 1e-9
    assert _relative(gravity(device, q), jac.T @ pin.computeGeneralizedGravity(model, data, qp)) < 1e-9


def test_device_flag_accepts_urdf_files(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM)
    device = resolve_device(device_file=path)
    assert device.name == "test-arm"
    assert device.params["mlink2"] == 1.1


@pytest.mark.parametrize(
    "text, message",
    [
        ("<robot name='x'><link name='a'/>", "malformed URDF"),
        ("<model/>", "root element must be <robot>"),
        (ARM.replace('type="continuous"', 'type="floating"'), "type 'floating' is not supported"),
        (ARM.replace('<child link="link3"/>', '<child link="link9"/>'), "unknown child link 'link9'"),
        (ARM.replace('<mass value="1.1"/>', '<mass value="-1.1"/>'), "negative mass"),
        (ARM.replace('ixx="0.002"', 'ixx="-0.002"'), "not positive definite"),
        (ARM.replace('<axis xyz="0 0.6 0.8"/>', '<axis xyz="0 0 0"/>'), "axis must be a non-zero vector"),
        (ARM.replace('xyz="0.3 0 0"', 'xyz="0.3 0"'), "is not 3 finite numbers"),
        ("<robot><link name='a'/><link name='b'/></robot>", "expected one root link, found 2"),
    ],
)
def test_bad_urdf_is_one_line_user_error(text, message):
    with pytest.raises(UserError, match=message) as info:
        device_from_urdf(text, "bad.urdf")
    assert "\n" not in str(info.value)
