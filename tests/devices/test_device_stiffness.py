"""VJM stiffness of any device from its file (seed 001 §5.2): elastic links, joint springs, loops.

Oracles: Euler-Bernoulli closed forms of a cantilever (end compliance ``L / E A``, ``L^3 / (3 E I)``,
``L / (G J)``, ``L / (E I)``, ``L^2 / (2 E I)``) with handbook section properties of a tube; a
PyNiteFEA frame of the same beams for a two-link spatial arm; the properties every stiffness matrix
must have (symmetry, positive definiteness).
"""

from __future__ import annotations

from math import cos, pi, sin

import numpy as np
import pytest

from hapticdesign.analysis.stiffness.device import cartesian_stiffness, deflection
from hapticdesign.devices.device_file import device_from_mapping
from hapticdesign.errors import UserError
from tests.helpers.pynite_chain import chain_compliance

# Both the VJM and PyNite's frame are linear Euler-Bernoulli models of the same beams, so they agree to
# round-off: 1e-8 (relative) is far below any modelling difference and far above double-precision noise.
ROUND_OFF = 1e-8
E_AL, G_AL = 68.9e9, 26.0e9  # aluminium 6061-T6 (ASM data sheet), as the file's material name says
D, d = 0.02, 0.016
AREA = pi / 4 * (D**2 - d**2)
I_TUBE = pi / 64 * (D**4 - d**4)
J_TUBE = pi / 32 * (D**4 - d**4)


def _cantilever(L: float = 0.3, **extra) -> dict:
    return {
        "name": "cantilever",
        "parameters": {"L": L},
        "joints": [{"name": "q1"}],
        "frames": [{"name": "arm", "transforms": [{"Rz": "q1"}]},
                   {"name": "tip", "parent": "arm", "transforms": [{"tx": "L"}]}],
        "end_effector": "tip",
        "bodies": [{"name": "arm", "frame": "arm", "m": 0.1, "rx": 0.15}],
        "links": [{"name": "arm", "from": "arm", "to": "tip", "section": {"shape": "tube", "D": D, "d": d},
                   "material": "aluminium_6061"}],
        **extra,
    }


def _local(K: np.ndarray, angle: float) -> np.ndarray:
    """The compliance of K in the link's axes (the link turned by ``angle`` about base z)."""
    c, s = cos(angle), sin(angle)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    T = np.zeros((6, 6))
    T[:3, :3] = T[3:, 3:] = R
    return T.T @ np.linalg.inv(K) @ T


def test_cantilever_link_matches_beam_theory():
    L, angle = 0.3, 0.7
    C = _local(cartesian_stiffness(device_from_mapping(_cantilever(L)), [angle]), angle)
    EA, EI, GJ = E_AL * AREA, E_AL * I_TUBE, G_AL * J_TUBE
    assert 1.0 / C[0, 0] == pytest.approx(EA / L, rel=1e-12)
    assert 1.0 / C[1, 1] == pytest.approx(3 * EI / L**3, rel=1e-12)
    assert 1.0 / C[2, 2] == pytest.approx(3 * EI / L**3, rel=1e-12)
    assert 1.0 / C[3, 3] == pytest.approx(GJ / L, rel=1e-12)
    assert C[4, 4] == pytest.approx(L / EI, rel=1e-12)
    assert C[5, 5] == pytest.approx(L / EI, rel=1e-12)
    assert C[1, 5] == pytest.approx(L**2 / (2 * EI), rel=1e-12)
    assert C[2, 4] == pytest.approx(-L**2 / (2 * EI), rel=1e-12)


def test_joint_spring_adds_its_compliance_in_series():
    L, k = 0.3, 2.0e3
    C = _local(cartesian_stiffness(device_from_mapping(_cantilever(L, joint_stiffness={"q1": k})), [0.0]), 0.0)
    EI = E_AL * I_TUBE
    assert C[1, 1] == pytest.approx(L**3 / (3 * EI) + L**2 / k, rel=1e-12)  # the tip swings on the spring
    assert C[5, 5] == pytest.approx(L / EI + 1.0 / k, rel=1e-12)


def _two_link_arm() -> dict:
    """A spatial arm: q1 about z at the base, a horizontal aluminium upper arm, q2 about the elbow's y axis,
    a steel rod forearm, the end effector at its tip."""
    return {
        "name": "arm-2r",
        "parameters": {"h": 0.05, "l1": 0.25, "l2": 0.2},
        "joints": [{"name": "q1"}, {"name": "q2"}],
        "frames": [{"name": "shoulder", "transforms": [{"tz": "h"}, {"Rz": "q1"}]},
                   {"name": "elbow", "parent": "shoulder", "transforms": [{"tx": "l1"}]},
                   {"name": "forearm", "parent": "elbow", "transforms": [{"Ry": "q2"}]},
                   {"name": "tip", "parent": "forearm", "transforms": [{"tx": "l2"}]}],
        "end_effector": "tip",
        "bodies": [{"name": "upper", "frame": "shoulder", "m": 0.2, "rx": 0.125}],
        "links": [
            {"name": "upper", "from": "shoulder", "to": "elbow", "section": {"shape": "tube", "D": D, "d": d},
             "material": "aluminium_6061"},
            {"name": "fore", "from": "forearm", "to": "tip", "section": {"shape": "rod", "D": 0.008},
             "material": "steel"},
        ],
    }


def test_two_link_arm_matches_a_pynite_frame():
    q1, q2, h, l1, l2 = 0.4, -0.6, 0.05, 0.25, 0.2
    K = cartesian_stiffness(device_from_mapping(_two_link_arm()), [q1, q2])
    shoulder = np.array([0.0, 0.0, h])
    elbow = shoulder + l1 * np.array([cos(q1), sin(q1), 0.0])
    # the forearm turns by q2 about the elbow's y axis: x' = cos q2 x - sin q2 z in the upper arm's axes
    tip = elbow + l2 * np.array([cos(q2) * cos(q1), cos(q2) * sin(q1), -sin(q2)])
    rod = 0.008
    sections = [(AREA, I_TUBE, J_TUBE), (pi / 4 * rod**2, pi / 64 * rod**4, pi / 32 * rod**4)]
    K_fe = np.linalg.inv(chain_compliance([shoulder, elbow, tip], sections, [(E_AL, G_AL), (200e9, 200e9 / 2.6)]))
    scale = np.sqrt(np.outer(np.diag(K_fe), np.diag(K_fe)))
    assert np.max(np.abs(K - K_fe) / scale) < ROUND_OFF


def test_deflection_is_the_compliance_times_the_force():
    device = device_from_mapping(_cantilever())
    K = cartesian_stiffness(device, [0.0])
    assert np.allclose(K, K.T, rtol=0, atol=1e-9 * np.abs(K).max())
    assert np.all(np.linalg.eigvalsh(K) > 0)
    d = deflection(K, [0.0, -5.0, 0.0])
    assert d[1] == pytest.approx(-5.0 * 0.3**3 / (3 * E_AL * I_TUBE), rel=1e-12)


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"material": "unobtainium"}, "links[0].material: unknown material 'unobtainium'"),
        ({"material": {"E": -1.0}}, "links[0].material: E must be positive"),
        ({"material": {"laminate": [1, 2, 3]}}, "expected four ply counts"),
        ({"section": {"shape": "box", "D": 0.02}}, "links[0].section: unknown section shape 'box'"),
        ({"section": {"shape": "tube", "D": 0.02}}, "missing 'd': a tube section takes D, d"),
        ({"section": {"shape": "rod", "D": 0.02, "t": 1}}, "unknown key 't'"),
        ({"section": {"shape": "tube", "D": 0.02, "d": 0.03}}, "must be below the outer diameter"),
        ({"to": "nowhere"}, "links[0].to: unknown frame 'nowhere'"),
        ({"colour": "red"}, "links[0].colour: unknown key"),
        ({"from": "base"}, "link arm: frame 'tip' must follow 'base' with no joint between them"),
        ({"from": "tip", "to": "arm"}, "must follow 'tip' with no joint"),
    ],
)
def test_link_errors_are_one_line(changes, message):
    data = _cantilever()
    data["links"][0].update(changes)
    with pytest.raises(UserError) as info:
        device_from_mapping(data, "arm.yaml")
    text = str(info.value)
    assert message in text and "\n" not in text and text.startswith("arm.yaml: ")


@pytest.mark.parametrize(
    "stiffness, message",
    [({"q9": 1.0}, "joint_stiffness: 'q9' is not an actuated joint"), ({"q1": -2.0}, "joint_stiffness.q1")],
)
def test_joint_stiffness_errors_are_one_line(stiffness, message):
    with pytest.raises(UserError) as info:
        device_from_mapping(_cantilever(joint_stiffness=stiffness), "arm.yaml")
    assert message in str(info.value) and "\n" not in str(info.value)


def test_a_device_without_elastic_links_has_no_stiffness():
    data = _cantilever()
    del data["links"]
    with pytest.raises(UserError, match="has no elastic links or joint springs"):
        cartesian_stiffness(device_from_mapping(data), [0.0])


def test_a_frame_no_link_reaches_is_rigid_and_refused():
    with pytest.raises(UserError, match="rigid in some direction"):
        cartesian_stiffness(device_from_mapping(_cantilever()), [0.0], frame="arm")  # the link's root
