"""``study device`` on a device file of one's own: every step runs and reports the engines' numbers."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.linearity.form import device_form
from hapticdesign.devices.loading import load_device
from hapticdesign.studies import device as study

pytestmark = pytest.mark.slow  # end to end: deselect with -m "not slow"

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"


def test_device_file_study(tmp_path, cli):
    path = EXAMPLES / "arm-3r.toml"
    done = cli("study", "device", "--device", str(path), "--out", str(tmp_path), "--json")
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout)
    assert {k: v["status"] for k, v in summary["steps"].items()} == {s.key: "done" for s in study.steps()}
    device = load_device(path)
    numbers = summary["numbers"]
    assert numbers["ln"]["ln"] == pytest.approx(float(device_form(device).ln(device.standard_parameters())), rel=1e-12)
    assert np.allclose(numbers["eom"]["H_at_zero"], mass_matrix(device, np.zeros(device.n_dof)), rtol=1e-12, atol=0)
    assert numbers["eom"]["max_symbolic_vs_compiled"] < 1e-9
    # a 3R arm with gravity is not linear: its LN is positive and the linear designs found have LN ~ 0
    assert numbers["ln"]["ln"] > 1e-6
    with open(tmp_path / "tables" / "linearization_found.csv") as handle:
        rows = [line.split(",") for line in handle.read().splitlines()[1:]]
    assert rows and all(float(r[1]) < 1e-12 and r[2] == "True" for r in rows)
    report = (tmp_path / "report.html").read_text()
    assert report.count("<img ") == len(list((tmp_path / "figures").glob("*.png")))
    # the interactive device view sits beside the report, linked from it, with the file's frames in its data
    assert 'href="pages/device_device.html"' in report
    page = (tmp_path / "pages" / "device_device.html").read_text()
    assert all(f'"name":"{frame.name}"' in page for frame in device.mechanism.frames)
    assert numbers["device"] == {"frames": len(device.mechanism.frames), "bodies": len(device.mechanism.bodies),
                                 "actuated": device.n_dof}


def test_device_study_needs_a_device(tmp_path, cli):
    done = cli("study", "device", "--preset", "phantom-9dof", "--out", str(tmp_path / "x"))
    assert done.returncode == 2 and done.stderr.startswith("error: unknown preset")
    done = cli("study", "device", "--device", str(tmp_path / "missing.yaml"), "--out", str(tmp_path / "x"))
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
