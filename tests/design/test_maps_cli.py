"""``hapticdesign maps``: design indices over a plane of any device's workspace (issue 28).

Oracles: the indices at each reached point equal :func:`hapticdesign.analysis.metrics.indices.evaluate` at that
point alone (checked against closed forms in test_indices.py); points beyond the five-bar's reach (``l1 + l2``
from both motor axes) carry a reason; bad input is one line with exit status 2.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.devices.device_file import load_device_file
from hapticdesign.interface.cli import app
from hapticdesign.analysis.metrics.indices import evaluate
from tests.helpers.planar_arm import planar_arm

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
runner = CliRunner()


def test_five_bar_maps_match_the_indices_point_by_point(tmp_path):
    args = ["maps", "--device", str(EXAMPLES / "five-bar.yaml"), "--size", "0.2,0,0.16", "--center", "0,0,0.16",
            "--grid", "5", "--index", "isotropy,apparent_mass", "--out", str(tmp_path), "--json"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["points"] == 25 and 0 < summary["reached"] < 25
    assert {Path(f).name for f in summary["files"]} == {"map_isotropy.png", "map_apparent_mass.png", "maps.csv"}
    rows = list(csv.DictReader((tmp_path / "maps.csv").open()))
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    far = 0.10 + 0.14
    for row in rows:
        point = np.array([float(row[k]) for k in ("x (m)", "y (m)", "z (m)")])
        alone = evaluate(device, point[None], ["isotropy", "apparent_mass"])
        if row["reached"] == "True":
            assert alone.reason is None
            assert float(row["isotropy"]) == pytest.approx(alone.values["isotropy"][0], rel=1e-9)
            assert float(row["apparent_mass"]) == pytest.approx(alone.values["apparent_mass"][0], rel=1e-9)
        elif min(np.hypot(point[0] - s, point[2]) for s in (-0.04, 0.04)) > far:
            assert "cannot reach" in row["reason"]
    assert summary["reached"] == sum(row["reached"] == "True" for row in rows)


@pytest.mark.parametrize("extra, message", [
    (["--size", "0.1,0,0"], "exactly two non-zero sizes"),
    (["--size", "0.1,0,0.1", "--index", "isotropi"], "unknown index 'isotropi'"),
    (["--size", "0.1,0,0.1", "--grid", "1"], "at least 2"),
])
def test_bad_maps_input_is_one_line(tmp_path, extra, message):
    result = runner.invoke(app, ["maps", "--device", str(EXAMPLES / "five-bar.yaml"), "--out", str(tmp_path), *extra])
    assert result.exit_code == 2
    assert message in result.output and "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1


def test_the_kmax_map_states_the_loop_settings_it_used(tmp_path):
    """``kmax`` runs with the sampled loop's settings: the map says which (the index's defaults, practice's:
    1 kHz, one sample of delay, backward difference, gravity compensation), as ``spec`` and ``metrics`` do."""
    from hapticdesign.analysis.wall_stiffness import KMAX_OPTIONS

    args = ["maps", "--device", str(EXAMPLES / "five-bar.yaml"), "--size", "0.02,0,0.02", "--grid", "2", "--index",
            "kmax,isotropy", "--out", str(tmp_path), "--json"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["options"] == {"kmax": KMAX_OPTIONS}
    text = runner.invoke(app, args[:-1])
    assert "delay=1" in text.stdout and "compensation=gravity" in text.stdout
    metrics = runner.invoke(app, ["metrics", "--device", str(EXAMPLES / "five-bar.yaml"), "--q", "2.2,0.9", "--index",
                                  "kmax", "--json"])
    assert json.loads(metrics.stdout)["options"] == {"kmax": KMAX_OPTIONS}


def _five_bar(transmissions: bool) -> dict:
    """The example five-bar (no links' sections), with motors whose drives have a transmission_stiffness (3000 N m/rad)
    when ``transmissions``."""
    import yaml

    data = yaml.safe_load((EXAMPLES / "five-bar.yaml").read_text())
    if transmissions:
        data["actuators"] = [{"joint": name, "rotor_inertia": 2e-6, "gear_ratio": 10.0, "damping": 0.004,
                              "transmission_stiffness": 3000.0} for name in ("q1", "q2")]
    return data


DEVICES = {"rigid": lambda: _five_bar(False), "transmissions": lambda: _five_bar(True),
           "links": planar_arm}
"""A device file by the drive it makes, as its fields decide it (the oracle): the five-bar has neither links' sections
nor transmission_stiffness; with its motors' transmission_stiffness, transmissions; the planar arm's links carry
sections (tests/helpers/planar_arm.py) and its motors none."""


@pytest.mark.parametrize("drive", DEVICES)
def test_a_kmax_map_and_metrics_say_which_compliance_the_drive_includes(tmp_path, drive):
    """Issue 41: ``maps --index kmax`` and ``metrics --index kmax`` say once which compliance between the motors and
    the handle kmax took (``compliance`` in --json, ``kmax: drive compliance: ...`` in text); without kmax, nothing."""
    import yaml

    path = tmp_path / "device.yaml"
    path.write_text(yaml.safe_dump(DEVICES[drive]()))
    args = ["maps", "--device", str(path), "--size", "0.02,0,0.02", "--grid", "2", "--index", "kmax,isotropy",
            "--out", str(tmp_path / "maps"), "--json"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["compliance"] == {"kmax": drive}
    text = runner.invoke(app, args[:-1])
    assert text.stdout.splitlines().count(f"kmax: drive compliance: {drive}") == 1, text.output
    plain = runner.invoke(app, [*args[:8], "isotropy", *args[9:]])
    assert plain.exit_code == 0 and "compliance" not in json.loads(plain.stdout), plain.output
    home = "0,0" if drive == "links" else "2.2,0.9"
    metrics = [["metrics", "--device", str(path), "--q", home, "--index", "kmax", *flag] for flag in (["--json"], [])]
    answers = [runner.invoke(app, m) for m in metrics]
    assert all(a.exit_code == 0 for a in answers), [a.output for a in answers]
    assert json.loads(answers[0].stdout)["compliance"] == {"kmax": drive}
    assert answers[1].stdout.splitlines().count(f"kmax: drive compliance: {drive}") == 1, answers[1].output
