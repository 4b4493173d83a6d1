"""``dynamics``, ``metrics`` and ``show`` say where the handle is and which assembly branch a closed loop is on.

Oracle: the five-bar's planar geometry by hand (its file: motors at x = -+d/2, proximal links l1, distal l2, the
plane upright so the plane's y is the base z): the elbows at ``A_i + l1 (cos q_i, sin q_i)``, the handle the
upper intersection of the circles of radius l2 about them; the passive angles ``p_i = atan2(handle - elbow_i) -
q_i``; and the closure's Jacobian over (p1, p2) in rows (x, z), ``[[-l2 sin a1, l2 sin a2], [l2 cos a1,
-l2 cos a2]]`` with ``a_i = q_i + p_i``, whose determinant is ``l2^2 sin(a1 - a2)`` (the same for tip1 - tip2
and tip2 - tip1).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app

FIVE_BAR = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"
D, L1, L2 = 0.08, 0.10, 0.14
runner = CliRunner()


def _five_bar_by_hand(q1: float, q2: float) -> tuple[np.ndarray, tuple[float, float], float]:
    e1 = np.array([-D / 2 + L1 * math.cos(q1), L1 * math.sin(q1)])
    e2 = np.array([D / 2 + L1 * math.cos(q2), L1 * math.sin(q2)])
    mid, gap = 0.5 * (e1 + e2), np.linalg.norm(e2 - e1)
    height = math.sqrt(L2 ** 2 - (gap / 2) ** 2)
    normal = np.array([-(e2 - e1)[1], (e2 - e1)[0]]) / gap
    handle = mid + height * normal if (mid + height * normal)[1] > (mid - height * normal)[1] else mid - height * normal
    a1 = math.atan2(*(handle - e1)[::-1])
    a2 = math.atan2(*(handle - e2)[::-1])
    wrap = lambda x: (x + math.pi) % (2 * math.pi) - math.pi  # noqa: E731
    det = L2 ** 2 * math.sin(a1 - a2)
    return handle, (wrap(a1 - q1), wrap(a2 - q2)), det


@pytest.mark.parametrize("command", ["dynamics", "metrics"])
def test_five_bar_handle_and_branch(command):
    done = runner.invoke(app, [command, "--device", str(FIVE_BAR), "--q", "2.0,1.1", "--json"])
    assert done.exit_code == 0, done.output
    out = json.loads(done.stdout)
    handle, passive, det = _five_bar_by_hand(2.0, 1.1)
    assert out["handle"]["frame"] == "tip1"
    x, y, z = out["handle"]["position"]
    assert (x, z) == pytest.approx(tuple(handle), abs=1e-12) and y == 0.0  # the plane's y is round-off: 0
    if command == "dynamics":
        branch = out["assembly_branch"]
        assert list(branch["passive_at_home"].values()) == pytest.approx(passive, abs=1e-9)
        assert branch["det_phi_p_sign"] == int(np.sign(det))
        assert branch["assembly_guess"] == {"p1": -1.08, "p2": 1.10}
    else:
        assert out["units"]["manipulability"] == "m^2/rad^2" and out["units"]["handle"] == "m"


def test_five_bar_text_names_the_branch(tmp_path):
    done = runner.invoke(app, ["dynamics", "--device", str(FIVE_BAR), "--q", "2.0,1.1"])
    assert done.exit_code == 0
    lines = [line for line in done.stdout.splitlines() if line.startswith("assembly branch:")]
    assert len(lines) == 1 and "det Phi_p < 0 at home" in lines[0] and "p1 = -1.079" in lines[0]
    shown = runner.invoke(app, ["show", "--device", str(FIVE_BAR), "--out", str(tmp_path / "v"), "--json"])
    assert shown.exit_code == 0 and json.loads(shown.stdout)["assembly_branch"]["det_phi_p_sign"] == -1


def test_tree_handle_is_the_end_effector_origin():
    """A 3R tree: the Phantom's handle at q = 0 lies on the base x-z plane (its links are in that plane at 0)
    and a tree names no assembly branch."""
    done = runner.invoke(app, ["dynamics", "--q", "0,0,0", "--json"])
    out = json.loads(done.stdout)
    assert "assembly_branch" not in out and out["handle"]["position"][1] == 0.0


def test_the_docs_quote_the_five_bar_by_hand():
    """docs/device-files.md quotes the five-bar's branch and handle at home: they are the hand geometry's."""
    docs = (Path(__file__).resolve().parents[2] / "docs" / "device-files.md").read_text()
    handle, (p1, p2), det = _five_bar_by_hand(2.0, 1.1)
    assert det < 0
    assert f"passive joints at home p1 = {p1:.6g},\n  p2 = {p2:.6g}`" in docs
    assert f"x = {1000 * handle[0]:.3g} mm, z = {1000 * handle[1]:.4g} mm" in docs
