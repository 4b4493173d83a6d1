"""Design indices (:mod:`hapticdesign.analysis.metrics.indices`) against independent computations.

Oracles: the closed form of a planar two-link arm (``J^T J`` has trace ``l1^2 + 2 l2^2 + 2 l1 l2 cos e`` and
determinant ``(l1 l2 sin e)^2`` at elbow angle ``e``; isotropic at ``l2 / l1 = 1 / sqrt(2)``, ``e = 135 deg``), central
differences of the closed loops' handle positions (the loop solver's forward kinematics), and the kinetic energy
``1/2 qd^T H qd`` of handle velocities ``v`` whose joint rates come from differences of the inverse kinematics
(``v^T Lambda v``, with H of :func:`~hapticdesign.analysis.dynamics.device.mass_matrix`, checked against
Pinocchio in tests/dynamics).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.metrics.indices import evaluate, handle_jacobians, reduce
from hapticdesign.analysis.workspace import Workspace, reach_workspace
from hapticdesign.devices.device_file import device_from_mapping, load_device_file
from hapticdesign.errors import UserError
from tests.helpers.handle_energy import cartesian_mass
from tests.helpers.planar_arm import planar_arm

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
LOOPS = {"five-bar": ((0.0, 0.0, 0.18), (0.06, 0.0, 0.06)), "delta": ((-0.10, 0.0, 0.0), (0.03, 0.03, 0.03))}


def _isotropy_closed_form(l1: float, l2: float, elbow: float) -> float:
    """sqrt(lambda_min / lambda_max) of ``J^T J = [[a, b], [b, c]]``, ``a = l1^2 + l2^2 + 2 l1 l2 cos e``,
    ``b = l2^2 + l1 l2 cos e``, ``c = l2^2``: eigenvalues ``(a + c) / 2 +- sqrt(((a - c) / 2)^2 + b^2)``."""
    half_trace = (l1**2 + 2 * l2**2 + 2 * l1 * l2 * math.cos(elbow)) / 2
    root = math.hypot((l1**2 + 2 * l1 * l2 * math.cos(elbow)) / 2, l2**2 + l1 * l2 * math.cos(elbow))
    return math.sqrt((half_trace - root) / (half_trace + root))


def _points_at_reach(l1: float, radii: list[float]) -> np.ndarray:
    """Points of the arm's plane (x-z) at distances ``radii`` from the shoulder, on a ray at 40 degrees."""
    return np.array([[r * math.cos(0.7), 0.0, r * math.sin(0.7)] for r in radii])


@pytest.mark.parametrize("ratio", [1 / math.sqrt(2), 0.8])
def test_two_link_isotropy_is_the_closed_form(ratio):
    l1, l2 = 0.2, 0.2 * ratio
    device = device_from_mapping(planar_arm(l1, l2))
    radii = [l1 / math.sqrt(2), 0.12, 0.16, 0.19, 0.22]
    result = evaluate(device, _points_at_reach(l1, radii), ["isotropy", "condition"])
    assert result.reason is None
    elbows = [math.acos((r**2 - l1**2 - l2**2) / (2 * l1 * l2)) for r in radii]
    expected = [_isotropy_closed_form(l1, l2, e) for e in elbows]
    np.testing.assert_allclose(result.values["isotropy"], expected, rtol=1e-10)
    np.testing.assert_allclose(result.values["condition"], 1 / np.array(expected), rtol=1e-10)
    if ratio == 1 / math.sqrt(2):  # r = l1 / sqrt(2) is the elbow at 135 degrees: isotropic
        assert elbows[0] == pytest.approx(3 * math.pi / 4)
        assert result.values["isotropy"][0] == pytest.approx(1.0, abs=1e-10)
    else:
        assert reduce(result.values["isotropy"], "max") < 0.99


@pytest.mark.parametrize("name", sorted(LOOPS))
def test_closed_loop_jacobian_is_the_derivative_of_the_handle_position(name):
    device = load_device_file(EXAMPLES / f"{name}.yaml")
    space = configuration_of(device)
    poses = reach_workspace(device, Workspace(*LOOPS[name], 2).points())
    jacobians = handle_jacobians(device, poses.full)
    h = 1e-6
    for q_a, jac in zip(poses.q, jacobians):
        numeric = np.column_stack([(space.pose(q_a + h * e)[:3, 3] - space.pose(q_a - h * e)[:3, 3]) / (2 * h)
                                   for e in np.eye(len(q_a))])
        np.testing.assert_allclose(jac, numeric, rtol=0, atol=1e-8)


@pytest.mark.parametrize("name", ["five-bar", "delta", "phantom-3dof-motors"])
def test_apparent_mass_is_the_kinetic_energy_of_handle_velocities(name):
    device = load_device_file(EXAMPLES / f"{name}.yaml")
    space = configuration_of(device)
    home = space.pose(space.home)[:3, 3]
    basis = np.eye(3)[:, [0, 2]] if name == "five-bar" else np.eye(3)  # the five-bar moves in its x-z plane
    point = home + basis @ np.full(basis.shape[1], 0.01)
    result = evaluate(device, point[None], ["apparent_mass", "inertia_uniformity"])
    assert result.reason is None
    eig = np.linalg.eigvalsh(cartesian_mass(device, point, basis))
    assert result.values["apparent_mass"][0] == pytest.approx(eig[-1], rel=1e-6)
    assert result.values["inertia_uniformity"][0] == pytest.approx(eig[0] / eig[-1], rel=1e-6)


def test_a_point_out_of_reach_is_the_reason():
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    result = evaluate(device, np.array([[0.0, 0.0, 0.18], [0.3, 0.0, 0.4]]), ["isotropy"])
    assert result.values == {}
    assert "(0.3, 0, 0.4)" in result.reason


def test_unknown_index_is_refused():
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    with pytest.raises(UserError, match="unknown index 'stiffnes'"):
        evaluate(device, np.zeros((1, 3)), ["stiffnes"])
