"""Bad device files: one-line UserError naming the problem; files are data, never code."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml

from hapticdesign.analysis.dynamics.device import gravity, mass_matrix
from hapticdesign.devices.loading import resolve_device
from hapticdesign.errors import PhysicalConsistencyWarning, UserError

GOOD = """
name: two-link
parameters: {l1: 0.3, l2: 0.2}
joints:
  - {name: q1}
  - {name: q2, damping: 0.1}
frames:
  - {name: upper, parent: base, transforms: [Rx: pi/2, Rz: q1]}
  - {name: lower, parent: upper, transforms: [tx: l1, Rz: q2]}
  - {name: tip, parent: lower, transforms: [tx: l2]}
end_effector: tip
bodies:
  - {name: 1, frame: upper, m: 1.0, rx: 0.15, Ixx: 0.001, Iyy: 0.008, Izz: 0.008}
  - {name: 2, frame: lower, m: 0.5, rx: 0.1, Ixx: 0.0005, Iyy: 0.002, Izz: 0.002}
"""


def _write(tmp_path: Path, text: str, suffix: str = ".yaml") -> Path:
    path = tmp_path / f"device{suffix}"
    path.write_text(text)
    return path


def test_the_reference_file_is_the_planar_2r_arm_of_the_textbooks(tmp_path):
    """H and G of a planar 2R arm in a vertical plane, in closed form."""
    device = resolve_device(device_file=_write(tmp_path, GOOD))
    assert device.parameter_names()[:3] == ["l1", "l2", "g"]
    assert device.damping == (0.0, 0.1)
    p = device.params
    m1, r1, i1, m2, r2, i2, l1, g = (p[k] for k in ("m1", "r1x", "Izz1", "m2", "r2x", "Izz2", "l1", "g"))
    for q1, q2 in np.random.default_rng(2).uniform(-np.pi, np.pi, (5, 2)):
        c2 = np.cos(q2)
        h11 = i1 + m1 * r1**2 + i2 + m2 * (l1**2 + r2**2 + 2 * l1 * r2 * c2)
        h12 = i2 + m2 * (r2**2 + l1 * r2 * c2)
        mass = np.array([[h11, h12], [h12, i2 + m2 * r2**2]])
        weight = g * np.array(
            [(m1 * r1 + m2 * l1) * np.cos(q1) + m2 * r2 * np.cos(q1 + q2), m2 * r2 * np.cos(q1 + q2)]
        )
        np.testing.assert_allclose(mass_matrix(device, [q1, q2]), mass, rtol=1e-12)
        np.testing.assert_allclose(gravity(device, [q1, q2]), weight, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize(
    "old, new, message",
    [
        ("name: two-link", "name: [two-link", r"malformed YAML"),
        ("m: 0.5,", "mass: 0.5,", r"bodies\[1\]\.mass: unknown key"),
        ("end_effector: tip", "end_effector: tip\ncolour: red", r"^\S+: colour: unknown key$"),
        ("joints:\n  - {name: q1}\n  - {name: q2, damping: 0.1}\n", "", r"joints: missing required field"),
        ("parent: upper", "parent: elbow", r"frames\[1\] \(lower\): unknown parent 'elbow'"),
        ("frame: lower", "frame: forearm", r"bodies\[1\] \(2\): unknown frame 'forearm'"),
        ("Rz: q2]", "Rz: q2 - q3]", r"frames\[1\] \(lower\)\.transforms\[1\]: unknown name 'q3'"),
        ("m: 0.5", "m: -0.5", r"bodies\[1\]: body 2: negative mass m2 = -0.5"),
        ("Ixx: 0.0005", "Ixx: -0.0005", r"body 2: inertia tensor is not positive definite"),
        ("tx: l1", "tx: l1**2", r"frames\[1\]\.transforms\[0\]: 'l1\*\*2' is not an affine expression"),
        ("tx: l1", "tx: q1", r"revolute coordinate q1 cannot drive a translation"),
        ("Rz: q2]", "Rz: 0.1]", r"joints: coordinate q2 drives no transform"),
        ("m: 0.5", "m: yes", r"bodies\[1\]\.m: expected a number or an expression"),
        ("damping: 0.1", "damping: -0.1", r"joints\[1\]\.damping: Input should be greater than or equal to 0"),
        ("{name: q1}", "{name: l1}", r"name 'l1' is used twice"),
        ("{name: q1}", "{name: pi}", r"'pi' is reserved"),
        ("m: 1.0", "m: .inf", r"bodies\[0\]\.m: expected a finite number"),
        ("m: 1.0", "m: 1e400", r"bodies\[0\]\.m: expected a finite number"),
        ("{name: 2, frame: lower", "{name: 1, frame: lower", r"bodies\[1\]: body name '1' is used twice"),
        ("l2: 0.2}", "l2: 0.2, r1y: 0.0}", r"parameter name 'r1y' is ambiguous"),
        ("end_effector: tip", "end_effector: hand", r"end_effector: unknown frame 'hand'"),
        ("name: tip,", "name: lower,", r"frame 'lower' is defined twice"),
        ("Rz: q1]", "Rq: q1]", r"unknown transform 'Rq'"),
        ("l2: 0.2", "l2: 2*l1", r"parameters\.l2: '2\*l1' must be a number \(pi-multiples allowed\), not depend on l1"),
        ("l1: 0.3", "l1: __import__('os').system('true')", r"parameters\.l1: cannot read"),
        ("name: two-link", "name: !!python/object/apply:os.system ['true']", r"malformed YAML"),
    ],
)
def test_bad_file_is_one_line_user_error(tmp_path, old, new, message):
    assert old in GOOD
    path = _write(tmp_path, GOOD.replace(old, new))
    with pytest.raises(UserError, match=message) as info:
        resolve_device(device_file=path)
    text = str(info.value)
    assert "\n" not in text and text.startswith(str(path))


def test_dh_rows_refuse_a_coordinate_in_a_constant_entry(tmp_path):
    text = """
name: dh
joints: [{name: q1}]
dh: [{a: 0.1, alpha: q1, theta: q1}]
bodies: [{name: 1, frame: body1, m: 1, Ixx: 1e-3, Iyy: 1e-3, Izz: 1e-3}]
"""
    with pytest.raises(UserError, match=r"dh\[0\]\.alpha: must be constant, it cannot depend on coordinate q1"):
        resolve_device(device_file=_write(tmp_path, text))


def test_json_and_toml_files_describe_the_same_device(tmp_path):
    data = yaml.safe_load(GOOD)
    from_yaml = resolve_device(device_file=_write(tmp_path, GOOD))
    from_json = resolve_device(device_file=_write(tmp_path, json.dumps(data), ".json"))
    toml = tmp_path / "device.toml"
    toml.write_text((Path(__file__).parent / "two_link.toml").read_text())
    from_toml = resolve_device(device_file=toml)
    q = np.array([0.4, -0.9])
    for other in (from_json, from_toml):
        assert dict(other.params) == dict(from_yaml.params)
        np.testing.assert_array_equal(mass_matrix(other, q), mass_matrix(from_yaml, q))
        np.testing.assert_array_equal(gravity(other, q), gravity(from_yaml, q))


def test_malformed_toml_and_unknown_suffix(tmp_path):
    with pytest.raises(UserError, match="malformed TOML"):
        resolve_device(device_file=_write(tmp_path, "name = [", ".toml"))
    with pytest.raises(UserError, match="unknown file type"):
        resolve_device(device_file=_write(tmp_path, GOOD, ".txt"))
    with pytest.raises(UserError, match="cannot read"):
        resolve_device(device_file=tmp_path / "missing.yaml")


def test_triangle_inequality_warns_and_strict_refuses(tmp_path):
    path = _write(tmp_path, GOOD.replace("Ixx: 0.001, Iyy: 0.008", "Ixx: 0.02, Iyy: 0.008"))
    with pytest.warns(PhysicalConsistencyWarning, match="body 1"):
        resolve_device(device_file=path)
    with pytest.raises(UserError, match="triangle inequality.*the strict check refuses it"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            resolve_device(device_file=path, strict=True)


def test_more_problems_are_counted(tmp_path):
    path = _write(tmp_path, GOOD.replace("m: 0.5,", "mass: 0.5,").replace("rx: 0.15,", "rxx: 0.15,"))
    with pytest.raises(UserError, match=r"unknown key \(and 1 more problem\)"):
        resolve_device(device_file=path)
