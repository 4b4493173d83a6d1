"""Commands ik, spec and export from the command line: results, and bad input as one line with exit 2.

Oracles: libnifalcon's inverse kinematics at the Falcon's centre (all arms at 14.567 deg, as its
FalconKinematicStamper::IK gives for (0, 0, 0.11) m); the rest are the one-line error contract.
"""

from __future__ import annotations

import json
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


@pytest.mark.parametrize("position, message", [
    ("0.5,0,0", "out of reach"),
    ("0,0", "--position: expected 3 values"),
    ("0,0,nan", "--position"),
])
def test_ik_bad_positions_are_one_line_errors(position, message):
    result = runner.invoke(app, ["ik", "--device", str(EXAMPLES / "falcon.yaml"), "--position", position])
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and message in result.stderr, result.stderr
