"""Bodies that follow a link's geometry (``bodies: - {name: b, link: l}``) and material densities.

Oracles: Pinocchio's solid cylinder (``pin.Inertia.FromCylinder``; a tube is the outer cylinder less the inner
one) moved to the link's axis, and the closed-form mass matrix of a planar two-link arm of uniform links
(``H11 = I1 + I2 + m2 (l1^2 + c2^2 + 2 l1 c2 cos e)``, ``H12 = I2 + m2 (c2^2 + l1 c2 cos e)``, ``H22 = I2 + m2 c2^2``,
``I1`` about the shoulder, ``I2`` about the mass centre, ``c2 = l2 / 2``) plus the motors' ``n^2 J_r``.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.devices.design_space import design_space
from hapticdesign.devices.device_file import device_from_mapping
from hapticdesign.errors import UserError
from hapticdesign.model.inertia import tube_body
from tests.helpers.planar_arm import planar_arm

ALUMINIUM = 2700.0


@pytest.mark.parametrize("axis, D, d", [((0.2, 0.0, 0.0), 0.012, 0.010), ((0.03, -0.1, 0.05), 0.02, 0.0),
                                        ((0.0, 0.0, 0.15), 0.01, 0.004)])
def test_tube_body_is_pinocchios_cylinders(axis, D, d):
    axis = np.array(axis)
    length = np.linalg.norm(axis)
    outer = pin.Inertia.FromCylinder(ALUMINIUM * math.pi * D**2 / 4 * length, D / 2, length)
    inner = pin.Inertia.FromCylinder(ALUMINIUM * math.pi * d**2 / 4 * length, d / 2, length) if d else None
    tube = outer - inner if inner is not None else outer
    z = axis / length
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    placed = pin.SE3(np.column_stack([x, np.cross(z, x), z]), axis / 2).act(tube)
    body = tube_body(axis, D, d, ALUMINIUM)
    assert body.m == pytest.approx(placed.mass, rel=1e-14)
    np.testing.assert_allclose(body.r, placed.lever, atol=1e-15)
    np.testing.assert_allclose(body.inertia_at_com, placed.inertia, rtol=0, atol=1e-12 * placed.inertia.max())


def _arm_mass_matrix(l1, l2, elbow, D1, d1, D2):
    m1 = ALUMINIUM * math.pi * (D1**2 - d1**2) / 4 * l1
    m2 = ALUMINIUM * math.pi * D2**2 / 4 * l2
    i1 = m1 * (3 * (D1**2 + d1**2) / 4 + l1**2) / 12 + m1 * (l1 / 2) ** 2
    i2 = m2 * (3 * D2**2 / 4 + l2**2) / 12
    c2, cos = l2 / 2, math.cos(elbow)
    h = np.array([[i1 + i2 + m2 * (l1**2 + c2**2 + 2 * l1 * c2 * cos), i2 + m2 * (c2**2 + l1 * c2 * cos)],
                  [i2 + m2 * (c2**2 + l1 * c2 * cos), i2 + m2 * c2**2]])
    return h + np.diag([10.0**2 * 1e-6, 8.0**2 * 2e-6])  # the motors of tests/helpers/planar_arm.py


def test_an_arm_of_link_bodies_has_the_closed_form_mass_matrix():
    device = device_from_mapping(planar_arm(0.2, 0.15, 2.0, link_bodies=True))
    for q in ([0.0, 0.0], [0.4, -0.7]):
        expected = _arm_mass_matrix(0.2, 0.15, 2.0 + q[1], 0.012, 0.010, 0.008)
        np.testing.assert_allclose(mass_matrix(device, np.array(q)), expected, rtol=1e-12)


def test_masses_follow_lengths_and_sections():
    space = design_space(planar_arm(link_bodies=True), ["l1", "l2", "links.upper.D", "links.lower.D"])
    device = space.device({"l1": 0.3, "l2": 0.1, "links.upper.D": 0.016, "links.lower.D": 0.006})
    assert device.params["m1"] == pytest.approx(ALUMINIUM * math.pi * (0.016**2 - 0.010**2) / 4 * 0.3, rel=1e-14)
    assert device.params["m2"] == pytest.approx(ALUMINIUM * math.pi * 0.006**2 / 4 * 0.1, rel=1e-14)
    expected = _arm_mass_matrix(0.3, 0.1, 3 * math.pi / 4, 0.016, 0.010, 0.006)
    np.testing.assert_allclose(mass_matrix(device, np.zeros(2)), expected, rtol=1e-12)


def test_a_link_body_is_not_a_design_variable():
    with pytest.raises(UserError, match="follow the link"):
        design_space(planar_arm(link_bodies=True), ["m1"])


@pytest.mark.parametrize("change, message", [
    (lambda a: a["bodies"][0].update(m=1.0), "remove m"),
    (lambda a: a["bodies"][0].update(link="shin"), "unknown link 'shin'"),
    (lambda a: a["links"][0].update(material={"E": 70e9, "G": 26e9}), "has no density"),
    (lambda a: a["links"][0].update(material={"E": 70e9, "G": 26e9, "density": -1}), "density must be positive"),
    (lambda a: a["bodies"][1].update(link="upper"), "already has a body"),
])
def test_bad_link_bodies_are_refused(change, message):
    arm = planar_arm(link_bodies=True)
    change(arm)
    with pytest.raises(UserError, match=message):
        device_from_mapping(arm)


def test_material_densities_in_files():
    arm = planar_arm(link_bodies=True)
    arm["links"][0]["material"] = {"E": 70e9, "G": 26e9, "density": 1000.0}
    arm["links"][1]["material"] = {"laminate": [4, 7, 7, 7]}
    device = device_from_mapping(arm)
    assert device.params["m1"] == pytest.approx(1000.0 * math.pi * (0.012**2 - 0.010**2) / 4 * 0.2, rel=1e-14)
    assert device.params["m2"] == pytest.approx(1790.0 * math.pi * 0.008**2 / 4 * (0.2 / math.sqrt(2)), rel=1e-14)
