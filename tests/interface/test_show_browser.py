"""The ``show`` page in headless Chromium: its forward kinematics equal Python's, sliders move the
device, the console stays clean, and a hostile device name stays text.

Like tests/studies/test_study_report_browser.py it needs Debian's chromium and chromedriver, which
``make test`` installs (``make browser``); without them it fails rather than silently passing.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.devices.registry import preset
from hapticdesign.interface.cli import app

pytestmark = pytest.mark.slow  # end to end: deselect with -m "not slow"

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
runner = CliRunner()


def _page(tmp_path: Path, args: list[str]) -> Path:
    result = runner.invoke(app, ["show", "--out", str(tmp_path), "--quiet", *args])
    assert result.exit_code == 0, result.output
    return tmp_path / "device.html"


def _python_origins(device, q_full) -> dict[str, np.ndarray]:
    """Frame origins from the mechanism's own frame_pose (model/mechanism.py), not the page's code."""
    names = [f.name for f in device.mechanism.frames]
    return {name: device.mechanism.frame_pose(np.asarray(q_full, dtype=float), name)[:3, 3] for name in names}


def _python_full(device, q) -> np.ndarray:
    """Every coordinate: passive joints of loops from the Python loop solver (analysis/loops)."""
    q = np.asarray(q, dtype=float)
    return q if device.mechanism.loops.empty else dynamics_of(device).full_coordinates(q)


def _clean_console(driver) -> None:
    problems = [e for e in driver.get_log("browser") if e["level"] in ("SEVERE", "WARNING")]
    assert problems == []


@pytest.mark.parametrize("source", ["phantom-3dof-motors.yaml", "phantom-6dof", "five-bar.yaml"])
def test_page_kinematics_follow_the_sliders(browser, tmp_path, source):
    """Tree devices: the page's and Python's forward kinematics agree to round-off (1e-12 m). Loops: both
    solve the closures by Newton (the page to a residual below 1e-13 m, Python to its solver's tolerance)
    with closure Jacobians of order one, so positions agree to 1e-9 m."""
    if source.endswith(".yaml"):
        device_path = EXAMPLES / source
        device, args = load_device_file(device_path), ["--device", str(device_path)]
    else:
        device, args = preset(source), ["--preset", source]
    loops = device.mechanism.loops
    tolerance = 1e-12 if loops.empty else 1e-9
    browser.get(_page(tmp_path, args).resolve().as_uri())
    assert browser.execute_script("return document.readyState") == "complete"
    assert browser.find_element("tag name", "h1").text == device.name
    rng = np.random.default_rng(11)
    lows = [low for low, _ in device.joint_ranges()]
    highs = [high for _, high in device.joint_ranges()]
    if not loops.empty:  # stay near home, where the loops close on the assembly branch
        lows, highs = np.array(loops.home) - 0.2, np.array(loops.home) + 0.2
    for _ in range(3):
        for k, value in enumerate(rng.uniform(lows, highs)):
            browser.execute_script("window.deviceView.setJoint(arguments[0], arguments[1])", k, float(value))
        q = browser.execute_script("return window.deviceView.pose()")
        q_full = _python_full(device, q)
        page = browser.execute_script("return window.deviceView.frameOrigins()")
        for name, origin in _python_origins(device, q_full).items():
            np.testing.assert_allclose(page[name], origin, rtol=0, atol=tolerance)
        centres = browser.execute_script("return window.deviceView.massCentres()")
        for centre in centres:
            body = device.body(centre["name"])
            frame = next(b.frame for b in device.mechanism.bodies if b.name == centre["name"])
            expected = device.mechanism.frame_pose(q_full, frame) @ np.append(body.r, 1.0)
            np.testing.assert_allclose(centre["p"], expected[:3], rtol=0, atol=tolerance)
    # the canvas was drawn on: not a single colour
    pixels = browser.execute_script(
        "var c = document.getElementById('canvas'); return Array.from(c.getContext('2d')"
        ".getImageData(0, 0, c.width, c.height).data.filter(function (v, i) { return i % 4 === 3 && v > 0; })).length")
    assert pixels > 500
    _clean_console(browser)


def test_hostile_name_does_not_run(browser, tmp_path):
    from selenium.common.exceptions import NoAlertPresentException

    name = '</script><script>alert(1)</script><img src=x onerror=alert(2)>'
    spec = {"name": name, "joints": [{"name": "q1"}],
            "frames": [{"name": "arm", "transforms": [{"Rz": "q1"}, {"tx": 0.1}]}],
            "bodies": [{"name": "tip", "frame": "arm", "m": 0.1}]}
    path = tmp_path / "hostile.json"
    path.write_text(json.dumps(spec))
    browser.get(_page(tmp_path / "view", ["--device", str(path)]).resolve().as_uri())
    with pytest.raises(NoAlertPresentException):
        browser.switch_to.alert.text
    assert browser.find_element("tag name", "h1").text == name
    assert browser.execute_script("return document.images.length") == 0
    assert browser.execute_script("return document.scripts.length") == 2
    _clean_console(browser)
