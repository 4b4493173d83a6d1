"""Long work says so: its size and an estimate of the time left first, then progress with the time left."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from hapticdesign.interface.common import TimeLeft, duration_text, progress_bar
from tests.helpers.sim_designs import write_designs

ROOT = Path(__file__).resolve().parents[2]


class Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_time_left_is_the_pace_since_the_first_item_times_the_items_to_do():
    """A first item that takes 30 s (a compile) and 2 s for each one after: the estimate is 2 s per item left."""
    clock = Clock()
    left = TimeLeft(clock, min_seconds=5.0)
    clock.now = 30.0
    assert left("cases", 1, 100) is None  # no pace yet
    clock.now = 32.0
    assert left("cases", 2, 100) is None  # under 5 s and under a tenth: too early to say
    clock.now = 30.0 + 2 * 5
    assert left("cases", 6, 100) == pytest.approx(2.0 * 94)
    assert left("other", 3, None) is None  # an unknown total has no time left


def test_durations_read_as_seconds_minutes_or_hours():
    assert [duration_text(s) for s in (40, 210, 7560)] == ["40 s", "3.5 min", "2.1 h"]


def test_progress_in_a_log_states_the_estimate_once_then_each_tenth_with_the_time_left(capsys, monkeypatch):
    """One item a second: nothing in the first 2 s (short work needs no log), then the estimate, then a line at
    each tenth with the time left."""
    clock = Clock()
    monkeypatch.setattr("time.monotonic", clock)
    with progress_bar(True) as report:  # stderr is captured: not a terminal
        for done in range(1, 101):
            clock.now = 1.0 * done
            report("cases", done, 100)
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[0] == "cases: 100 in all; at the pace so far, about 1.6 min left"  # 98 s: 2 of 100 after 2 s
    assert lines[1] == "cases: 2 of 100, about 1.6 min left"
    assert lines[2] == "cases: 10 of 100, about 1.5 min left"
    assert lines[-1] == "cases: 100 of 100" and len(lines) == 12
    with progress_bar(False) as report:
        assert report is None


def test_work_that_ends_within_two_seconds_writes_no_progress_to_a_log(capsys, monkeypatch):
    clock = Clock()
    monkeypatch.setattr("time.monotonic", clock)
    with progress_bar(True) as report:
        for done in range(1, 11):
            clock.now = 0.1 * done
            report("cases", done, 10)
    assert capsys.readouterr().err == ""


def test_a_short_step_after_a_long_one_writes_nothing_to_a_log(capsys, monkeypatch):
    """The 2 s count per step: a 13-step bisection of 0.1 s after a 10-s step (the spec sheet's workspace cube after
    its first compile) says nothing, while the long step said where it was."""
    clock = Clock()
    monkeypatch.setattr("time.monotonic", clock)
    with progress_bar(True) as report:
        for done in range(1, 11):
            clock.now = 1.0 * done
            report("long", done, 10)
        for done in range(1, 14):
            clock.now = 10.0 + 0.1 * done
            report("short", done, 13)
    err = capsys.readouterr().err
    assert "long: 10 of 10" in err and "short" not in err


def test_robustness_states_its_size_and_the_time_left(tmp_path):
    """The README's robustness run, small: before the searches their number, then the estimate (stderr of a
    child process, as in a log); --json stays quiet."""
    designs = write_designs(tmp_path / "designs.csv")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    args = [sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "robustness", "--designs", str(designs), "--errors", "0,5",
            "--draws", "10"]
    run = subprocess.run(args, capture_output=True, text=True, env=env, cwd=tmp_path, check=False)
    assert run.returncode == 0, run.stderr
    err = run.stderr.splitlines()
    assert err[0] == ("robustness: 4 designs x 2 error levels (10 draws at each level above 0) = 44 stable-range "
                      "searches (analytic)")
    assert any(line.startswith("robustness searches: 44 in all; at the pace so far, about ") for line in err)
    assert err[-1] == "robustness searches: 44 of 44"
    quiet = subprocess.run([*args, "--json"], capture_output=True, text=True, env=env, cwd=tmp_path, check=False)
    assert quiet.returncode == 0 and quiet.stderr == ""


def test_a_study_steps_title_is_never_cut_on_a_terminal():
    """The step's whole title (its references in parentheses aside) on an 80-column terminal, wrapped where it must
    be, not cut with an ellipsis (issue 45: "Analytic linearization and a realizable lin…")."""
    import io

    from rich.console import Console

    from hapticdesign.interface.commands.study import RichProgress

    title = "Campaigns over the design sets: stable impedance and transparency (§4.1.4, §4.2.4)"
    screen = io.StringIO()
    progress = RichProgress(Console(file=screen, width=80, force_terminal=True, color_system=None))
    with progress.bars:
        progress.begin(title)
        progress.update(3, 10)
    text = " ".join(screen.getvalue().split())
    assert "…" not in text
    words = "Campaigns over the design sets: stable impedance and transparency".split()
    last = text.rsplit("Campaigns", 1)[1]
    assert [w for w in words[1:] if w in last] == words[1:]


def test_a_study_in_a_log_says_each_step_when_it_starts_and_ends(capsys, monkeypatch):
    from hapticdesign.interface.commands.study import LineProgress
    from hapticdesign.studies.steps import STATUS_DONE, Outcome, StepResult

    clock = Clock()
    monkeypatch.setattr("time.monotonic", clock)
    lines = []
    progress = LineProgress(lines.append)
    title = "Analytic linearization and a realizable linear design (§3.2.1)"
    progress.begin(title)
    for done in range(1, 11):
        clock.now = float(done)
        progress.update(done, 10)
    progress.end(StepResult("linearization", title, STATUS_DONE, 10.0, Outcome()))
    assert lines[0] == "Analytic linearization and a realizable linear design..."
    assert lines[1] == "  1 of 10" and lines[-2] == "  9 of 10, about 1 s left" and lines[-1] == "  done in 10 s"


def test_a_map_reports_each_point_and_its_indices():
    """``maps`` feeds its bar from ``device_map``: every point once, in order, then the indices' batch."""
    import numpy as np

    from hapticdesign.analysis.metrics.maps import INDICES_STEP, REACH_STEP, device_map
    from hapticdesign.devices.loading import load_device

    device = load_device(ROOT / "examples" / "devices" / "five-bar.yaml")
    points = np.array([[0.0, 0.0, 0.2], [0.01, 0.0, 0.19], [5.0, 0.0, 0.0]])  # the last out of reach
    heard = []
    found = device_map(device, points, ["isotropy"], progress=lambda *report: heard.append(report))
    assert found.reached.tolist() == [True, True, False]
    assert heard == [(REACH_STEP, 0, 3), (REACH_STEP, 1, 3), (REACH_STEP, 2, 3), (REACH_STEP, 3, 3),
                     (INDICES_STEP, 0, None), (INDICES_STEP, 1, 1)]


def test_a_progress_bars_step_name_is_never_cut_on_a_terminal(monkeypatch):
    """The command line's bars (progress_bar) keep a long step name whole on an 80-column terminal."""
    import io

    from rich.console import Console

    screen = io.StringIO()
    monkeypatch.setattr("rich.console.Console", lambda **kw: Console(file=screen, width=80, force_terminal=True,
                                                                     color_system=None))
    step = "renderable stiffness (exact, with the hand, simulated) of the device at its home pose"
    with progress_bar(True) as report:
        report(step, 1, 3)
    text = " ".join(screen.getvalue().split())
    assert "…" not in text and all(word in text for word in step.split())
