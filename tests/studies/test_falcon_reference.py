"""A Falcon you can redesign (issue 45 item 7): the reference device states only what is published, a derived file
carries labelled assumptions and keeps the published numbers beside its sheet through ``reference: falcon``.

Oracles: libnifalcon's geometry (the derived file must put the arms where the reference does), Novint's published
figures (> 2 lb = 8.9 N, 4 in = 101.6 mm, > 400 dpi) and CHAI3D's 3000 N/m in the page, the one-line error contract."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from hapticdesign.analysis.configuration import handle_pose
from hapticdesign.devices.loading import load_device
from hapticdesign.interface.cli import app
from hapticdesign.interface.report.spec_page import spec_page
from hapticdesign.studies.spec import spec_sheet

DEVICES = Path(__file__).resolve().parents[2] / "examples" / "devices"
REFERENCE, DERIVED = DEVICES / "falcon.yaml", DEVICES / "falcon-assumed-motors.yaml"


def test_the_reference_device_states_only_what_libnifalcon_publishes():
    data = yaml.safe_load(REFERENCE.read_text())
    assert "reference" not in data
    assert all(set(a) == {"joint", "gear_ratio", "encoder_cpr"} for a in data["actuators"])


def test_the_derived_file_is_the_reference_with_labelled_motors():
    reference, derived = yaml.safe_load(REFERENCE.read_text()), yaml.safe_load(DERIVED.read_text())
    assert derived["reference"] == "falcon"
    for key in ("parameters", "g", "joints", "frames", "end_effector", "loops", "assembly", "bodies"):
        assert derived[key] == reference[key], key
    text = DERIVED.read_text()
    assert text.count("ASSUMED") >= 4 and "not measured" in text
    a, b = load_device(REFERENCE), load_device(DERIVED)
    for target in ([0.0, 0.0, 0.11], [0.02, -0.015, 0.125]):
        np.testing.assert_allclose(handle_pose(b, np.array(target)).q, handle_pose(a, np.array(target)).q, atol=1e-10)


def test_the_derived_sheet_has_the_published_numbers_beside_its_own():
    sheet = spec_sheet(load_device(DERIVED), workspace=False, simulate=False)
    assert sheet["reference"] == "falcon" and sheet["force_peak"] == pytest.approx(8.994, abs=5e-3)  # > 8.9 N
    page = spec_page(sheet)
    heads = re.findall(r"<th>(.*?)</th>", page)
    assert heads[-2:] == ["vendor (falcon, the published device)", "why they differ"]
    for published in ("3000 N/m", "8.9 N", "101.6 mm", "0.0635 mm"):
        assert published in page
    own = spec_page(spec_sheet(load_device(REFERENCE), workspace=False, simulate=False))
    assert re.findall(r"<th>(.*?)</th>", own)[-2] == "vendor" and "3000 N/m" in own


def test_a_reference_without_published_numbers_is_one_line(tmp_path):
    odd = tmp_path / "odd.yaml"
    odd.write_text(DERIVED.read_text().replace("reference: falcon", "reference: omega7"))
    done = CliRunner().invoke(app, ["spec", "--device", str(odd), "--no-workspace", "--no-simulate"])
    assert done.exit_code == 2 and done.stderr.count("\n") == 1, done.output
    assert done.stderr.startswith("error: reference: no published numbers of a device named 'omega7'")
