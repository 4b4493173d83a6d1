"""``transparency`` says when its stiffness is above the wall joint's stable limit, and why a bandwidth is null.

Oracle: the growth boundary of the simulated (nonlinear, RK4) loop of the five-bar's joint 1 under the seed's
settings (full inertial compensation, no delay), the spring resting 0.01 rad from home (2.0, 1.1)
(:func:`hapticdesign.simulation.impedance.growth_boundary`, 10-s runs bisected to 1e-4). Seed 000 §4.1.2's 1-DOF
closed form ``b^2 / H_ww`` at (2.01, 1.1) leaves gravity's stiffness out and is 0.8 % higher.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.interface.cli import app

FIVE_BAR = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"
runner = CliRunner()


@pytest.fixture(scope="module")
def simulated_limit() -> float:
    from hapticdesign.simulation.config import LoopConfig
    from hapticdesign.simulation.impedance import ImpedanceProblem, growth_boundary

    device = load_device_file(FIVE_BAR)
    limit = growth_boundary(ImpedanceProblem(device, 1, 0, config=LoopConfig(duration=10.0)), rel_tol=1e-4)
    closed_form = 0.01 ** 2 / mass_matrix(device, np.array([2.0 + 0.01, 1.1]))[0, 0]
    assert abs(closed_form / limit - 1.0) > 5e-3  # gravity's stiffness matters here
    return limit


def _run(stiffness: float):
    return runner.invoke(app, ["transparency", "--device", str(FIVE_BAR), "--joint", "1", "--method", "analytic",
                               "--stiffness", repr(float(stiffness)), "--json"])


def test_stiffness_above_the_limit_is_said(simulated_limit):
    done = _run(4.0)
    assert done.exit_code == 0, done.output
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: K = 4 N m/rad is above joint 1's stable limit")
    out = json.loads(done.stdout)
    assert out["stable_limit"] == pytest.approx(simulated_limit, rel=2e-4)
    assert out["units"]["stable_limit"] == "N m/rad"
    if out["bandwidth_hz"] is None:
        assert "above the wall joint's stable limit" in out["bandwidth_note"]


def test_stiffness_below_the_limit_gives_no_warning(simulated_limit):
    done = _run(0.5 * simulated_limit)
    assert done.exit_code == 0, done.output
    assert done.stderr == ""
    out = json.loads(done.stdout)
    assert out["stable_limit"] == pytest.approx(simulated_limit, rel=2e-4)
    assert (out["bandwidth_hz"] is None) == ("bandwidth_note" in out)


def test_the_docs_quote_the_five_bar_limit(simulated_limit):
    """docs/simulation.md quotes joint 1's limit of the five-bar; it is the simulated loop's, to 4 digits."""
    docs = (Path(__file__).resolve().parents[2] / "docs" / "simulation.md").read_text()
    assert f"five-bar's {simulated_limit:.4g} N m/rad on joint 1" in docs


def test_the_engine_gives_the_limit_and_says_where_the_linearization_does_not_decide(simulated_limit):
    """The search is the engine's (:func:`hapticdesign.simulation.transparency.stable_limit`), the command only
    reports it: the same limit from the API, None with encoder counts (a quantized loop is not linear)."""
    from hapticdesign.simulation.config import LoopConfig
    from hapticdesign.simulation.transparency import stable_limit

    device = load_device_file(FIVE_BAR)
    assert stable_limit(device, 1, 0, LoopConfig()) == pytest.approx(simulated_limit, rel=2e-4)
    assert stable_limit(device, 1, 0, LoopConfig(counts=4096)) is None


def test_transparency_builds_the_one_loop_record_from_its_flags():
    """``--compensation gravity`` is the loop's gravity-only compensation: the same run as the full compensation with
    its inertial and Coriolis terms dropped (``--no-inertial --no-coriolis``); the hand's flags put the hand in the
    loop as the Python API's ``SampledLoop.seed(hand=...)`` does (the analytic method, type 1, joint 1)."""
    import hapticdesign as hd
    from hapticdesign.analysis.sampled_loop import Hand, SampledLoop
    from hapticdesign.simulation.config import LoopConfig
    from hapticdesign.simulation.paths import Chirp

    base = ["transparency", "--device", str(FIVE_BAR), "--method", "analytic", "--json"]
    runs = [runner.invoke(app, [*base, *extra]) for extra in
            (["--compensation", "gravity"], ["--no-inertial", "--no-coriolis"],
             ["--hand-mass", "0.2", "--hand-damping", "2", "--hand-stiffness", "50"])]
    assert [r.exit_code for r in runs] == [0, 0, 0], [r.output for r in runs]
    gravity, dropped, hand = (json.loads(r.stdout) for r in runs)
    assert gravity == dropped
    api = hd.transparency(load_device_file(FIVE_BAR), 1, 4.0, Chirp(0.3, 0.1, 15.0, 10.0),
                          LoopConfig(duration=10.0, loop=SampledLoop.seed(hand=Hand(0.2, 2.0, 50.0))), method="analytic")
    assert hand["bandwidth_hz"] == api.bandwidth_hz is not None and hand["bandwidth_hz"] != gravity["bandwidth_hz"]
