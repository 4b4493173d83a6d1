"""Design variables of a device file (:mod:`hapticdesign.devices.design_space`).

Oracles: the file's own values and formulas stated in the device-file format (the reflected inertia
``n^2 J_r``, a tube's axial rigidity ``E pi (D^2 - d^2) / 4``, the handle of a two-link arm at
``l1 + l2 e^(i e)``), and refusals for names the device does not have and values its validation refuses.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.devices.design_space import design_space
from hapticdesign.errors import UserError
from tests.helpers.planar_arm import planar_arm

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
NAMES = ["l1", "l2", "m2", "links.upper.D", "links.upper.d", "links.lower.D", "actuators.q1.gear_ratio",
         "actuators.1.rotor_inertia"]


@pytest.fixture(scope="module")
def space():
    return design_space(planar_arm(), NAMES)


def test_defaults_are_the_files_values(space):
    assert space.defaults() == pytest.approx({"l1": 0.2, "l2": 0.2 / math.sqrt(2), "m2": 0.2, "links.upper.D": 0.012,
                                              "links.upper.d": 0.010, "links.lower.D": 0.008,
                                              "actuators.q1.gear_ratio": 10.0, "actuators.1.rotor_inertia": 2e-6})


def test_geometry_moves_the_handle(space):
    device = space.device({"l1": 0.25, "l2": 0.1})
    handle = configuration_of(device).pose(np.zeros(2))[:3, 3]
    elbow = 3 * math.pi / 4
    np.testing.assert_allclose(handle, [0.25 + 0.1 * math.cos(elbow), 0.0, 0.1 * math.sin(elbow)], atol=1e-15)


def test_motor_and_section_values_follow(space):
    device = space.device({"actuators.q1.gear_ratio": 20.0, "actuators.1.rotor_inertia": 5e-6, "links.upper.D": 0.02,
                           "m2": 0.5})
    np.testing.assert_allclose(np.diag(device.reflected_inertia), [20.0**2 * 1e-6, 8.0**2 * 5e-6], rtol=1e-14)
    upper = device.elasticity.links[0]
    assert upper.axial == pytest.approx(68.9e9 * math.pi * (0.02**2 - 0.010**2) / 4, rel=1e-14)
    assert device.params["m2"] == 0.5


@pytest.mark.parametrize("name, message", [
    ("l9", "unknown design variable 'l9'"),
    ("m7", "unknown design variable 'm7'"),
    ("links.shin.D", "no link 'shin'"),
    ("links.lower.d", "a rod has no inner diameter"),
    ("links.upper.t", "has D and d"),
    ("actuators.q3.gear_ratio", "no actuator 'q3'"),
    ("actuators.q1.colour", "one of rotor_inertia"),
])
def test_names_the_device_does_not_have_are_refused(name, message):
    with pytest.raises(UserError, match=message):
        design_space(planar_arm(), [name])


def test_a_variable_of_a_device_without_links_is_refused():
    with pytest.raises(UserError, match="has no link 'prox1'"):
        design_space(EXAMPLES / "five-bar.yaml", ["links.prox1.D"])


@pytest.mark.parametrize("values, message", [
    ({"m2": -1.0}, "negative mass"),
    ({"links.upper.d": 0.02}, "below the outer diameter"),
    ({"actuators.q1.gear_ratio": 0.0}, "gear_ratio"),
    ({"l1": float("nan")}, "finite"),
    ({"l1": "long"}, "not a number"),
    ({"l3": 0.1}, "not a design variable"),
])
def test_invalid_designs_are_refused(space, values, message):
    with pytest.raises(UserError, match=message):
        space.device(values)


def test_a_five_bar_whose_loops_cannot_close_at_home_is_refused():
    space = design_space(EXAMPLES / "five-bar.yaml", ["l1", "l2"])
    with pytest.raises(UserError, match="cannot close"):
        space.device({"l1": 0.02, "l2": 0.03})


def test_a_home_given_as_a_handle_position_follows_the_geometry(tmp_path):
    """``home: {position: ...}``: a design whose loops do not close at the file's joint home keeps its handle at
    the position (issue 35), where the file's joint home would refuse it."""
    text = (EXAMPLES / "five-bar.yaml").read_text().replace(
        "home: {q1: 2.0, q2: 1.1}", "home: {position: [0.003, 0.0, 0.202]}")
    path = tmp_path / "five-bar-position.yaml"
    path.write_text(text)
    space = design_space(path, ["l1", "l2"])
    values = {"l1": 0.12, "l2": 0.2}
    device = space.device(values)
    handle = configuration_of(device).pose(configuration_of(device).home)[:3, 3]
    assert handle == pytest.approx([0.003, 0.0, 0.202], abs=1e-9)
    fixed = design_space(EXAMPLES / "five-bar.yaml", ["l1", "l2"]).device(values)
    moved = configuration_of(fixed).pose(configuration_of(fixed).home)[:3, 3]
    assert np.linalg.norm(moved - [0.003, 0.0, 0.202]) > 1e-3
