"""``hapticdesign show``: the PNG is written, the page carries every frame, user strings stay text."""

from __future__ import annotations

import json
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.devices.device_file import load_device_file
from hapticdesign.interface.cli import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
HOSTILE = '</script><script>alert(1)</script><img src=x onerror=alert(2)>&amp;"\''
runner = CliRunner()


class Tags(HTMLParser):
    """Start tags and the text of the data block, as a browser's tokenizer sees them."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[str] = []
        self.data_block: str | None = None
        self._in_data = False

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self._in_data = dict(attrs).get("id") == "device-data"

    def handle_data(self, data):
        if self._in_data:
            self.data_block = (self.data_block or "") + data

    def handle_endtag(self, tag):
        self._in_data = False


def page_data(html: str) -> tuple[list[str], dict]:
    parser = Tags()
    parser.feed(html)
    return parser.tags, json.loads(parser.data_block)


def test_show_writes_png_and_page_with_every_frame(tmp_path):
    device_file = EXAMPLES / "phantom-3dof-motors.yaml"
    result = runner.invoke(app, ["show", "--device", str(device_file), "--out", str(tmp_path), "--q", "0.1,0.2,0.3",
                                 "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    png = Path(out["png"]).read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    import matplotlib.image

    image = matplotlib.image.imread(out["png"])
    assert image.shape[0] > 100 and image.shape[1] > 100 and image[..., :3].std() > 0  # not blank
    html = Path(out["html"]).read_text(encoding="utf-8")
    tags, data = page_data(html)
    device = load_device_file(device_file)
    frames = {f.name for f in device.mechanism.frames} | {"base"}
    assert {f["name"] for f in data["frames"]} == frames
    assert [s["name"] for s in data["sliders"]] == list(device.mechanism.coordinates)
    assert [s["value"] for s in data["sliders"]] == [0.1, 0.2, 0.3]
    assert [(s["low"], s["high"]) for s in data["sliders"]] == [tuple(span) for span in device.joint_limits()]
    assert tags.count("script") == 2 and "link" not in tags and "img" not in tags  # no external resources
    assert not re.search(r"(src|href)\s*=\s*[\"']?(https?:)?//", html)


def test_hostile_device_name_stays_text(tmp_path):
    spec = {"name": HOSTILE, "joints": [{"name": "q1"}],
            "frames": [{"name": "arm", "transforms": [{"Rz": "q1"}, {"tx": 0.1}]}],
            "bodies": [{"name": "tip", "frame": "arm", "m": 0.1}]}
    path = tmp_path / "hostile.json"
    path.write_text(json.dumps(spec))
    result = runner.invoke(app, ["show", "--device", str(path), "--out", str(tmp_path / "view")])
    assert result.exit_code == 0, result.output
    html = (tmp_path / "view" / "device.html").read_text(encoding="utf-8")
    tags, data = page_data(html)
    assert tags.count("script") == 2 and "img" not in tags
    assert data["name"] == HOSTILE  # the data block round-trips the exact string
    assert HOSTILE not in html and "<img" not in html


@pytest.mark.parametrize("args, message", [
    (["--q", "0.1,0.2"], "--q: expected 3 values"),
    (["--q", "0.1,x,0"], "--q: expected comma-separated numbers"),
    (["--q", "0.1,nan,0"], "--q: values must be finite"),
    (["--preset", "nope"], "nope"),
])
def test_show_bad_input_is_one_line(tmp_path, args, message):
    result = runner.invoke(app, ["show", "--out", str(tmp_path), *args])
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and message in result.stderr, result.stderr


def test_show_out_is_a_file_is_one_line(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    result = runner.invoke(app, ["show", "--out", str(blocker)])
    assert result.exit_code == 2 and result.stderr.count("\n") == 1 and "is a file" in result.stderr


def test_show_pose_outside_limits_warns(tmp_path):
    result = runner.invoke(app, ["show", "--device", str(EXAMPLES / "phantom-3dof-motors.yaml"), "--out", str(tmp_path),
                                 "--q", "2,0,0"])
    assert result.exit_code == 0
    assert "warning: theta1 = 2 is outside its limits" in result.stderr
    _, data = page_data((tmp_path / "device.html").read_text(encoding="utf-8"))
    assert data["sliders"][0]["high"] == 2.0 and data["sliders"][0]["low"] == pytest.approx(-np.pi / 2)


def test_loop_device_page_starts_closed(tmp_path):
    """A five-bar: sliders for the actuated joints only, and the exported pose closes the loop (tip1 = tip2 in x, z)."""
    device_file = EXAMPLES / "five-bar.yaml"
    if not device_file.exists():
        pytest.skip("five-bar.yaml is part of the closed-loop work")
    result = runner.invoke(app, ["show", "--device", str(device_file), "--out", str(tmp_path), "--quiet"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "device.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    _, data = page_data((tmp_path / "device.html").read_text(encoding="utf-8"))
    device = load_device_file(device_file)
    assert [s["name"] for s in data["sliders"]] == list(device.mechanism.actuated_coordinates)
    assert data["closures"] == [["tip1", "tip2", [0, 2]]]
    mech = device.mechanism
    tip1, tip2 = (mech.frame_pose(np.array(data["full"]), f)[:3, 3] for f in ("tip1", "tip2"))
    assert abs(tip1[0] - tip2[0]) < 1e-9 and abs(tip1[2] - tip2[2]) < 1e-9
