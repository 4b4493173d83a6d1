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
