"""Elementary transforms (seed 000 eq. 2.1-2.6) against SciPy's rotations and plain translations."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from hapticdesign.model.transforms import Axis, Rx, Ry, Rz, combination, elementary_matrix, joint, tx, ty, tz


@pytest.mark.parametrize("axis, name", [(Axis.RX, "x"), (Axis.RY, "y"), (Axis.RZ, "z")])
def test_rotations_equal_scipy(axis, name):
    for v in np.linspace(-3.0, 3.0, 7):
        t = elementary_matrix(axis, v)
        np.testing.assert_allclose(t[:3, :3], Rotation.from_euler(name, v).as_matrix(), atol=1e-15)
        np.testing.assert_array_equal(t[:3, 3], 0.0)
        np.testing.assert_array_equal(t[3], [0, 0, 0, 1])


@pytest.mark.parametrize("axis, unit", [(Axis.TX, 0), (Axis.TY, 1), (Axis.TZ, 2)])
def test_translations_move_along_their_axis(axis, unit):
    t = elementary_matrix(axis, 0.37)
    np.testing.assert_array_equal(t[:3, :3], np.eye(3))
    np.testing.assert_array_equal(t[:3, 3], 0.37 * np.eye(3)[unit])


def test_joint_values_are_affine_in_the_coordinates():
    """A coupled value (the Phantom's parallelogram, eq. 2.38-2.43) is offset + sum c_k q_k."""
    q = np.array([0.2, -0.5, 1.1])
    coupled = Rz(combination({1: 1.0, 2: -1.0}, offset=0.25))
    np.testing.assert_allclose(coupled.matrix(q), elementary_matrix(Axis.RZ, 0.25 + q[1] - q[2]), atol=0)
    np.testing.assert_allclose(tx(joint(0, 2.0, 0.1)).matrix(q), elementary_matrix(Axis.TX, 0.1 + 2 * q[0]), atol=0)
    assert Rx(0.3).value.is_constant and not Ry(joint(1)).value.is_constant
    np.testing.assert_array_equal(combination({2: 3.0, 0: 1.0}).dense(3), [1.0, 0.0, 3.0])


def test_a_sequence_composes_like_scipy():
    """Rz(a) Ry(b) Rx(c) is the intrinsic z-y-x Euler rotation."""
    a, b, c = 0.4, -0.9, 1.3
    t = Rz(a).matrix(np.zeros(0)) @ Ry(b).matrix(np.zeros(0)) @ Rx(c).matrix(np.zeros(0)) @ tz(0.2).matrix(np.zeros(0))
    expected = Rotation.from_euler("ZYX", [a, b, c]).as_matrix()
    np.testing.assert_allclose(t[:3, :3], expected, atol=1e-15)
    np.testing.assert_allclose(t[:3, 3], expected @ [0, 0, 0.2], atol=1e-15)
    assert ty(0.0).axis is Axis.TY
