"""Commands ik, spec and export from the command line: results, and bad input as one line with exit 2.

Oracles: libnifalcon's inverse kinematics at the Falcon's centre (all arms at 14.567 deg, as its
FalconKinematicStamper::IK gives for (0, 0, 0.11) m); the rest are the one-line error contract.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
runner = CliRunner()


def test_ik_json_puts_the_falcons_arms_at_14_567_degrees():
    result = runner.invoke(app, ["ik", "--device", str(EXAMPLES / "falcon.yaml"), "--position", "0,0,0.11", "--json"])
    assert result.exit_code == 0, result.stderr
    out = json.loads(result.stdout)
    assert [math.degrees(v) for v in out["q"]] == pytest.approx([14.567] * 3, abs=5e-4)
    assert len(out["passive"]) == 6


def test_ik_text_states_each_coordinates_unit():
    """Every coordinate line carries its unit: the Falcon's revolute joints in rad, with degrees beside."""
    result = runner.invoke(app, ["ik", "--device", str(EXAMPLES / "falcon.yaml"), "--position", "0,0,0.11"])
    assert result.exit_code == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == "falcon: handle at (0, 0, 0.11) m"
    assert lines[1] == "  t1 = 0.254234872 rad (14.5666 deg)"
    assert len(lines) == 10 and all(" rad (" in line and line.endswith("deg)" if k < 3 else "deg), passive")
                                    for k, line in enumerate(lines[1:]))


def test_ik_text_gives_a_prismatic_coordinate_in_metres(tmp_path):
    slider = tmp_path / "slider.yaml"
    slider.write_text("name: slider\njoints: [{name: x, type: prismatic}, {name: y, type: prismatic}]\n"
                      "frames: [{name: a, transforms: [tx: x]}, {name: b, parent: a, transforms: [ty: y]}]\n"
                      "bodies: [{name: b, frame: b, m: 0.1, Ixx: 1e-5, Iyy: 1e-5, Izz: 1e-5}]\nend_effector: b\n")
    result = runner.invoke(app, ["ik", "--device", str(slider), "--position", "0.02,0.03,0"])
    assert result.exit_code == 0, result.stderr
    assert result.stdout.splitlines()[1:] == ["  x = 0.02 m", "  y = 0.03 m"]


@pytest.mark.parametrize("position, message", [
    ("0.5,0,0", "out of reach"),
    ("0,0", "--position: expected 3 values"),
    ("0,0,nan", "--position"),
])
def test_ik_bad_positions_are_one_line_errors(position, message):
    result = runner.invoke(app, ["ik", "--device", str(EXAMPLES / "falcon.yaml"), "--position", position])
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and message in result.stderr, result.stderr


def test_export_writes_mjcf_that_mujoco_loads_and_escapes_the_device_name(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    source = (EXAMPLES / "five-bar.yaml").read_text().replace("name: five-bar", "name: 'five\"bar <&> </mujoco>'")
    device = tmp_path / "odd.yaml"
    device.write_text(source)
    out = tmp_path / "five-bar.xml"
    result = runner.invoke(app, ["export", "--device", str(device), "--format", "mjcf", "--out", str(out)])
    assert result.exit_code == 0, result.stderr
    assert ET.parse(out).getroot().get("model") == 'five"bar <&> </mujoco>'
    model = mujoco.MjModel.from_xml_path(str(out))
    assert (model.nv, model.neq) == (4, 1)


def test_export_urdf_of_a_tree_loads_in_pinocchio(tmp_path):
    pin = pytest.importorskip("pinocchio")
    out = tmp_path / "arm.urdf"
    result = runner.invoke(app, ["export", "--device", str(EXAMPLES / "arm-3r.toml"), "--format", "urdf", "--out",
                                 str(out)])
    assert result.exit_code == 0, result.stderr
    assert pin.buildModelFromUrdf(str(out)).nv == 3


@pytest.mark.parametrize("args, message", [
    (["--device", str(EXAMPLES / "five-bar.yaml"), "--format", "urdf"], "closed loops"),
    (["--device", str(EXAMPLES / "phantom-premium.yaml"), "--format", "urdf"], "combination of coordinates"),
    (["--device", str(EXAMPLES / "five-bar.yaml"), "--format", "sdf"], "--format: unknown format 'sdf'"),
])
def test_export_refusals_are_one_line_errors_and_write_nothing(tmp_path, args, message):
    out = tmp_path / "x.out"
    result = runner.invoke(app, ["export", *args, "--out", str(out), "--quiet"])
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and message in result.stderr, result.stderr
    assert not out.exists()


def test_export_to_an_unwritable_place_is_one_line(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    result = runner.invoke(app, ["export", "--device", str(EXAMPLES / "five-bar.yaml"), "--out",
                                 str(blocker / "sub" / "m.xml")])
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and "cannot write" in result.stderr, result.stderr


def test_spec_json_and_html_of_the_phantom(tmp_path):
    """Continuous force at home: motor 2's 11.2 x 28.6 mN m over the 0.215 m upper arm (tests/studies/test_spec.py
    derives every number by hand); the page puts the vendor's 1.4 N beside it."""
    result = runner.invoke(app, ["spec", "--device", str(EXAMPLES / "phantom-premium.yaml"), "--no-workspace",
                                 "--out", str(tmp_path), "--json", "--quiet"])
    assert result.exit_code == 0, result.stderr
    sheet = json.loads(result.stdout)
    assert sheet["force_continuous"] == pytest.approx(11.2 * 0.0286 / 0.215, rel=1e-9)
    page = (tmp_path / "spec.html").read_text()
    assert "1.4 N" in page and "800 N/m" in page and "8.5 N" in page
    assert json.loads((tmp_path / "spec.json").read_text())["force_peak"] == pytest.approx(11.2 * 0.129 / 0.215)


def test_spec_page_of_a_closed_loop_device_shows_its_workspace_section(tmp_path):
    result = runner.invoke(app, ["spec", "--device", str(EXAMPLES / "five-bar.yaml"), "--out", str(tmp_path),
                                 "--quiet"])
    assert result.exit_code == 0, result.stderr
    page = (tmp_path / "spec.html").read_text()
    assert "<h2>Workspace sections</h2>" in page and "<h2>Quantities over the workspace</h2>" in page
    assert page.count('src="data:image/png;base64,') == 2


def test_spec_page_escapes_the_device_name(tmp_path):
    source = (EXAMPLES / "haply-2diy.yaml").read_text().replace("name: haply-2diy", "name: '<script>x</script>'")
    device = tmp_path / "odd.yaml"
    device.write_text(source)
    result = runner.invoke(app, ["spec", "--device", str(device), "--no-workspace", "--out", str(tmp_path / "o"),
                                 "--quiet"])
    assert result.exit_code == 0, result.stderr
    page = (tmp_path / "o" / "spec.html").read_text()
    assert "<script>" not in page and "&lt;script&gt;" in page


@pytest.mark.parametrize("args, message", [
    (["--device", str(EXAMPLES / "pantograph-2dof.yaml")], "singular"),
    (["--device", str(EXAMPLES / "haply-2diy.yaml"), "--q", "1,2,3"], "--q: expected 2 values"),
])
def test_spec_bad_poses_are_one_line_errors(args, message):
    result = runner.invoke(app, ["spec", *args, "--no-workspace"])
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and message in result.stderr, result.stderr
