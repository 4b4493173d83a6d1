"""The reference devices of examples/devices against their published models.

- ``phantom-premium.yaml`` against Cavusoglu & Feygin's (2001) closed-form mass matrix and gravity vector
  of the Phantom 1.5 (UC Berkeley ERL memo M01/15; the formulas written out in tests/helpers/phantom_premium_mass.py
  and below from the memo's transcription in github.com/mahilab/Phantom, ``step_dynamics_cavusoglu``), plus the reflected rotor
  inertia ``n^2 J_r`` of its motors, and the memo's own test vectors at g = 9.81.
- ``falcon.yaml`` against the closed-form inverse kinematics of Stamper's delta as libnifalcon states
  it (``FalconKinematicStamper::IK``, the geometry of ``FalconGeometry.h``), re-derived below.
- ``haply-2diy.yaml`` against the closed-form inverse kinematics of a five-bar (two circles' intersection).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.dynamics.device import gravity, mass_matrix
from hapticdesign.analysis.configuration import handle_pose
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.devices.loading import resolve_device
from hapticdesign.errors import PhysicalConsistencyWarning, UserError
from tests.helpers.phantom_premium_mass import (
    IBE, IDF, L1, L2, L3, L5, L6, MA, MBE, MC, MDF, ROTOR, cavusoglu_mass_matrix,
)

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"


def cavusoglu_gravity(q, g: float) -> np.ndarray:
    """The memo's N(q) at rest: the gradient of its potential energy."""
    _, q2, q3 = q
    return g * np.array([0.0, (L1 * MA + 0.5 * L1 * MC + L5 * MBE) * math.cos(q2),
                         (0.5 * L2 * MA + L3 * MC - L6 * MDF) * math.sin(q3)])


@pytest.fixture(scope="module")
def phantom():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_device_file(EXAMPLES / "phantom-premium.yaml")


def test_phantom_h_and_g_equal_the_closed_form_plus_reflected_rotor_inertia(phantom):
    rng = np.random.default_rng(22)
    poses = [np.zeros(3), np.array([0, 0.5, 0.5])] + [rng.uniform(-1.5, 1.5, 3) for _ in range(6)]
    for q in poses:
        assert np.allclose(mass_matrix(phantom, q), cavusoglu_mass_matrix(q) + np.diag(ROTOR), rtol=1e-9, atol=1e-12)
        assert np.allclose(gravity(phantom, q), cavusoglu_gravity(q, 9.80665), rtol=1e-9, atol=1e-12)


def test_phantom_reproduces_the_memos_test_vectors(phantom):
    """M(0,0,0) and N at g = 9.81 as published; the file's g is 9.80665 and G is linear in g."""
    published = np.diag([3.5735e-3, 2.4264e-3, 9.3189e-4])
    assert np.allclose(mass_matrix(phantom, np.zeros(3)) - np.diag(ROTOR), published, atol=5e-8)
    scale = 9.81 / 9.80665
    assert np.allclose(gravity(phantom, np.zeros(3)) * scale, [0, -0.016298, 0], atol=5e-7)
    assert np.allclose(gravity(phantom, np.array([0, 0.5, 0.5])) * scale, [0, -0.014303, -0.035360], atol=5e-7)


def test_phantom_file_holds_rigid_bodies_where_the_published_split_does_not():
    """The memo's be and df break the triangle inequality about their axes; the file moves a moment about
    the vertical from the base to them (H unchanged, checked above) and loads without a warning, while the
    same file with the published split warns for both bodies."""
    for xx, yy, zz in (IBE, IDF):
        assert xx > yy + zz
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        resolve_device(device_file=EXAMPLES / "phantom-premium.yaml")


def test_phantom_with_the_published_split_warns_for_be_and_df(tmp_path):
    text = (EXAMPLES / "phantom-premium.yaml").read_text()
    published = {"Ixx: 11.47e-4, Iyy: 11.47e-4, Izz: 11.47e-4": "Ixx: 11.87e-4, Iyy: 11.87e-4, Izz: 11.87e-4",
                 "Iyy: 7.11534784e-4, Izz: 0.841e-4": "Iyy: 6.86534784e-4, Izz: 0.591e-4",
                 "Iyy: 0.779e-4, Izz: 1.10248526e-4": "Iyy: 0.629e-4, Izz: 0.95248526e-4"}
    for ours, theirs in published.items():
        assert text.count(ours) == 1
        text = text.replace(ours, theirs)
    path = tmp_path / "published.yaml"
    path.write_text(text)
    with pytest.warns(PhysicalConsistencyWarning) as caught:
        device = resolve_device(device_file=path)
    message = " ".join(str(w.message) for w in caught)
    assert "body be" in message and "body df" in message and "triangle inequality" in message
    for q in (np.zeros(3), np.array([0.3, -0.4, 0.9])):
        assert np.allclose(mass_matrix(device, q), cavusoglu_mass_matrix(q) + np.diag(ROTOR), rtol=1e-9, atol=1e-12)


FALCON = {"a": 0.060, "b": 0.1025, "c": 0.014, "d": 0.01125, "e": 0.01125, "f": -0.025, "r": 0.037233758,
          "s": -0.027330909}
PHY = (math.pi / 2 + math.pi / 12, -math.pi / 6 + math.pi / 12, -5 * math.pi / 6 + math.pi / 12)


def stamper_arm_angles(position) -> np.ndarray:
    """libnifalcon's inverse kinematics (Stamper's delta), re-derived: in leg i's frame (the base turned by
    phy_i, moved by (r, s)), v = b cos theta3 - f fixes theta3; the knee circle
    (u + c - a cos theta1)^2 + (w - a sin theta1)^2 = (d + e + b sin theta3)^2 fixes theta1: with
    t = tan(theta1 / 2) it is the quadratic l2 t^2 + l1 t + l0 = 0, of which libnifalcon takes the root
    (-l1 - sqrt(l1^2 - 4 l0 l2)) / (2 l2)."""
    g = FALCON
    out = []
    for phy in PHY:
        c, s = math.cos(phy), math.sin(phy)
        x, y, z = position
        u, v, w = c * x + s * y - g["r"], -s * x + c * y - g["s"], z
        theta3 = math.acos((v + g["f"]) / g["b"])
        reach = g["d"] + g["e"] + g["b"] * math.sin(theta3)
        k = (u + g["c"]) ** 2 + w**2 + g["a"] ** 2 - reach**2
        l2, l1, l0 = k + 2 * g["a"] * (u + g["c"]), -4 * g["a"] * w, k - 2 * g["a"] * (u + g["c"])
        out.append(2 * math.atan((-l1 - math.sqrt(l1**2 - 4 * l0 * l2)) / (2 * l2)))
    return np.array(out)


@pytest.fixture(scope="module")
def falcon():
    return load_device_file(EXAMPLES / "falcon.yaml")


def test_falcon_ik_at_the_centre_puts_every_arm_at_14_567_degrees(falcon):
    pose = handle_pose(falcon, [0.0, 0.0, 0.11])
    assert np.degrees(pose.q) == pytest.approx([14.567] * 3, abs=5e-4)
    assert np.allclose(pose.q, stamper_arm_angles([0.0, 0.0, 0.11]), atol=1e-9)


@pytest.mark.parametrize("position", [(0.03, -0.02, 0.13), (-0.04, 0.03, 0.09), (0.0, 0.045, 0.14), (0.02, 0.0, 0.16)])
def test_falcon_ik_equals_libnifalcons_closed_form(falcon, position):
    pose = handle_pose(falcon, position)
    assert np.allclose(pose.q, stamper_arm_angles(position), atol=1e-9)
    assert np.allclose(pose.position, position, atol=1e-9)


def test_phantom_ik_equals_the_closed_form(phantom):
    """Elbow-down branch of the arm l1, l2: the triangle of the shoulder, elbow and handle (law of cosines)."""
    for x, y, z in [(0.2, 0.0, -0.1), (0.1, 0.05, -0.05), (0.15, -0.1, 0.05)]:
        pose = handle_pose(phantom, [x, y, z])
        rho, h = math.hypot(x, y), math.hypot(math.hypot(x, y), z)
        q2 = math.atan2(z, rho) + math.acos((L1**2 + h**2 - L2**2) / (2 * L1 * h))
        q3 = q2 - math.pi / 2 + math.acos((L1**2 + L2**2 - h**2) / (2 * L1 * L2))
        assert np.allclose(pose.q, [math.atan2(y, x), q2, q3], atol=1e-9)


def test_haply_ik_equals_two_circles_intersection():
    device = load_device_file(EXAMPLES / "haply-2diy.yaml")
    d, l1, l2 = 0.038, 0.07, 0.09
    for x, y in [(0.0, 0.12), (0.03, 0.1), (-0.05, 0.08)]:
        pose = handle_pose(device, [x, y, 0.0])
        expected = []
        for base, side in ((-d / 2, 1.0), (d / 2, -1.0)):
            reach = math.hypot(x - base, y)
            expected.append(math.atan2(y, x - base) + side * math.acos((l1**2 + reach**2 - l2**2) / (2 * l1 * reach)))
        assert np.allclose(pose.q, expected, atol=1e-9)


@pytest.mark.parametrize("position, message", [((0.5, 0.0, 0.0), "out of reach"), ((0.0, 0.12, 0.01), "out of reach")])
def test_haply_ik_refuses_points_out_of_reach_and_off_its_plane(position, message):
    with pytest.raises(UserError, match=message):
        handle_pose(load_device_file(EXAMPLES / "haply-2diy.yaml"), position)
