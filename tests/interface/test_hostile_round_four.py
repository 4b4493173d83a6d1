"""Hostile and careless input, round four (issue 46): the sampled loop's doors, interrupted polishing, forged
checkpoints, names on pages, and errors before work. Each case is one ``error:`` line, exit status 2, nothing
half-written and nothing outside ``--out``."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app

from tests.helpers.sim_designs import write_designs

runner = CliRunner()
ZWIDTH = ["zwidth", "--inertia", "0.039", "--damping", "0.5"]


def one_line_error(args: list[str], fragment: str) -> str:
    """Run the CLI; assert exit 2, exactly one ``error:`` line on stderr (no progress line before it) holding
    ``fragment``, and nothing on stdout."""
    result = runner.invoke(app, args)
    assert result.exit_code == 2, (args, result.output)
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), (args, result.stderr)
    assert fragment in lines[0], (fragment, lines[0])
    assert result.stdout == ""
    return lines[0]


# -- the sampled loop's settings: one validation, work estimated before it is built ------------------------------
@pytest.mark.parametrize("args, fragment", [
    (["--b-values", "1e308", "--json"], "the wall damping must be at most 1e+12 (N s/m or N m s/rad), got 1e+308 "
                                        "(--b-values)"),
    (["--b-values", "0.1,1e13"], "got 1e+13 (--b-values)"),
    (["--delay", "1000000000"], "a delay of 1,000,000,000 samples) would take 2e+09 rows, above the limit of 600 rows"),
    (["--period", "1e-300", "--json"], "the sample period must be at least 1e-12 s, got 1e-300 (--period)"),
])
def test_zwidth_refuses_loops_out_of_range_before_building_them(args, fragment):
    one_line_error([*ZWIDTH, *args], fragment)


@pytest.mark.parametrize("args, fragment", [
    (["impedance-range", "--hand-mass", "1e308"], "the hand's mass must be at most 1e+12 (SI units), got 1e+308 "
                                                  "(--hand-mass)"),
    (["impedance-range", "--hand-stiffness", "1e13"], "(--hand-stiffness)"),
    (["impedance-range", "--wall-damping", "1e308"], "(--wall-damping)"),
    (["impedance-range", "--hand-damping", "1e308"], "(--hand-damping)"),
    (["spec", "--no-workspace", "--hand-mass", "1e308"], "(--hand-mass)"),
    (["impedance-range", "--period", "1e-300"], "at least 1e-12 s, got 1e-300 (--period)"),
])
def test_every_sampled_loop_command_refuses_settings_out_of_range(args, fragment):
    one_line_error(args, fragment)


def test_a_delay_of_a_billion_samples_is_refused_even_when_forced(monkeypatch):
    """Above the soft order limit the memory estimate still holds: the matrix is never allocated."""
    monkeypatch.setenv("HAPTICDESIGN_FORCE", "1")
    one_line_error([*ZWIDTH, "--delay", "1000000000"], "of memory; this machine has")


def test_the_loop_record_owns_the_ranges_and_the_estimate():
    from hapticdesign.analysis.sampled_loop import SampledLoop, joint_limits
    from hapticdesign.errors import InputError
    from hapticdesign.workload import WorkloadTooLarge

    with pytest.raises(InputError, match="at least 1e-12 s"):
        SampledLoop(period=1e-300)
    with pytest.raises(InputError, match="at most 1e\\+12"):
        SampledLoop(wall_damping=1e308)
    assert SampledLoop(delay=300, compensation="full").order() == 2 * 301 + 301
    with pytest.raises(WorkloadTooLarge, match="above the limit of 600 rows"):
        joint_limits(0.039, 0.5, SampledLoop(delay=10**9))


def test_the_analytic_criteria_estimate_their_loops_before_building_them():
    """``impedance-range --method analytic --delay 1000`` built loops of order 3003 and searched them for minutes."""
    import numpy as np

    from hapticdesign.simulation.analytic import WallJoint, wall_loops
    from hapticdesign.analysis.sampled_loop import SampledLoop
    from hapticdesign.simulation.config import LoopConfig
    from hapticdesign.workload import WorkloadTooLarge

    wall = WallJoint(0.04, 0.5, np.array([1.0, 0.0, 0.0]), 0.0, 0.04, 0.0, 0.0, True)
    with pytest.raises(WorkloadTooLarge, match="order 3,003 .* above the limit of 600 rows"):
        wall_loops([wall], LoopConfig(loop=SampledLoop.seed(delay=1000)))


def test_the_default_damper_grid_stops_at_the_largest_damper():
    """A heavy joint at a short period reaches the damper cap: the grid ends there instead of overflowing."""
    from hapticdesign.analysis.sampled_loop import MAX_WALL_DAMPING, SampledLoop
    from hapticdesign.simulation.zwidth import damping_grid

    grid = damping_grid(1e7, 0.5, SampledLoop(period=1e-6, delay=0, velocity="sampled"), points=3)
    assert grid[-1] <= MAX_WALL_DAMPING


# -- options checked before the work is announced ---------------------------------------------------------------
@pytest.mark.parametrize("errors", ["100", "-5", "1e9"])
def test_robustness_checks_its_error_levels_before_announcing_the_work(tmp_path, errors):
    designs = write_designs(tmp_path / "designs.csv")
    one_line_error(["robustness", "--designs", str(designs), "--errors", errors, "--out", str(tmp_path / "o")],
                   "error levels must be percentages in [0, 100)")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("flag", ["--tol-l1", "--tol-joint"])
def test_rcube_tolerance_checks_the_tolerances_before_announcing_the_run(tmp_path, flag):
    one_line_error(["rcube", "tolerance", flag, "10", "--out", str(tmp_path / "o")],
                   f"must be below 0.1 of the link length")
    assert not (tmp_path / "o").exists()


# -- an interrupted run leaves only complete files ---------------------------------------------------------------
SIGNALLED_WRITE = """
import os, signal, sys
from pathlib import Path

import hapticdesign.files as files

written = files._write_new


def signalled(path, data):  # the signal arrives between writing the temporary file and renaming it
    written(path, data)
    os.kill(os.getpid(), signal.{name})


files._write_new = signalled
files.write_atomically(Path(sys.argv[1]) / "polish-generation-0001.json", '{{"X": []}}')
print("after")
"""


@pytest.mark.parametrize("name", ["SIGTERM", "SIGHUP"])
def test_a_signal_during_a_checkpoint_write_leaves_the_complete_file_only(tmp_path, name):
    """SIGTERM while ``optimize`` polishes (or runs its generations): every checkpoint goes through
    ``write_atomically``, which holds the signal until the file is in its place, then ends the process as the
    signal would have."""
    import os
    import signal
    import subprocess
    import sys
    from pathlib import Path

    src = str(Path(__file__).resolve().parents[2] / "src")
    done = subprocess.run([sys.executable, "-c", SIGNALLED_WRITE.format(name=name), str(tmp_path)],
                          env={**os.environ, "PYTHONPATH": src}, capture_output=True, text=True, timeout=120)
    assert done.returncode == -getattr(signal, name), done.stderr
    assert done.stdout == ""  # ended at the signal, after the write
    assert sorted(p.name for p in tmp_path.iterdir()) == ["polish-generation-0001.json"]
    assert (tmp_path / "polish-generation-0001.json").read_text() == '{"X": []}'


def test_ctrl_c_during_a_write_keeps_the_file_and_raises_after_it(tmp_path, monkeypatch):
    import os
    import signal

    import hapticdesign.files as files

    written = files._write_new

    def interrupted(path, data):
        written(path, data)
        os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(files, "_write_new", interrupted)
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(KeyboardInterrupt):
        files.write_atomically(tmp_path / "generation-0001.json", "{}")
    assert [p.name for p in tmp_path.iterdir()] == ["generation-0001.json"]
    assert signal.getsignal(signal.SIGTERM) is before


# -- the seed studies' work folders: no link followed, no special file opened -------------------------------------
def _appendix_c_into(work: Path) -> None:
    from hapticdesign.studies.phantom import PhantomSettings
    from hapticdesign.studies.phantom_rendering import _appendix_c_csv
    from hapticdesign.studies.steps import Context, SilentProgress

    work.mkdir(exist_ok=True)
    _appendix_c_csv(Context(PhantomSettings.for_scale("smoke"), work, SilentProgress()), work / "appendix_c_1.csv", 1)


def test_a_link_planted_in_the_phantom_work_folder_is_replaced_not_followed(tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    work = tmp_path / "o" / "work"
    work.mkdir(parents=True)
    (work / "appendix_c_1.csv").symlink_to(elsewhere / "x.csv")
    _appendix_c_into(work)
    assert list(elsewhere.iterdir()) == []
    written = work / "appendix_c_1.csv"
    assert not written.is_symlink() and written.read_text().startswith("design,level,ln,")


def test_a_named_pipe_in_the_phantom_work_folder_is_refused_not_waited_on(tmp_path):
    import os
    import threading

    from hapticdesign.errors import UserError

    work = tmp_path / "o" / "work"
    work.mkdir(parents=True)
    pipe = work / "appendix_c_1.csv"
    os.mkfifo(pipe)
    raised: list[BaseException] = []

    def attempt() -> None:
        try:
            _appendix_c_into(work)
        except BaseException as exc:  # noqa: BLE001 - handed to the test's thread
            raised.append(exc)

    thread = threading.Thread(target=attempt, daemon=True)
    thread.start()
    thread.join(60)
    if thread.is_alive():  # blocked opening the pipe: release it, then fail
        os.close(os.open(pipe, os.O_RDONLY | os.O_NONBLOCK))
        pytest.fail("the study waited on a named pipe in its work folder")
    assert len(raised) == 1 and isinstance(raised[0], UserError), raised
    assert "named pipe" in str(raised[0]) and pipe.is_fifo()


# -- forged checkpoints: a recomputed checksum does not make a value trusted -------------------------------------
def _forged(path: Path, change) -> None:
    """Change a checkpoint file's values and recompute its checksum as :class:`Checkpoint` does (not keyed)."""
    import hashlib
    import json

    run = json.loads((path.parent / "run.json").read_text())
    data = json.loads(path.read_text())
    change(data)
    key = f"{run['study']}:{run['seed']}"
    data["checksum"] = hashlib.sha256(json.dumps([key, data["X"], data["reduced"], data["reasons"]]).encode()
                                      ).hexdigest()
    path.write_text(json.dumps(data))


def _huge_integer(data: dict) -> None:
    data["reduced"][0][0] = 10 ** 400


def _largest_float(data: dict) -> None:
    data["reduced"] = [[1e308 for _ in row] for row in data["reduced"]]


def _huge_design(data: dict) -> None:
    data["X"][0][0] = 10 ** 400


@pytest.mark.parametrize("change", [_huge_integer, _largest_float, _huge_design])
@pytest.mark.parametrize("name", ["generation-0002.json", "polish-generation-0001.json"])
def test_a_forged_checkpoint_is_evaluated_again_with_a_warning(tmp_path, change, name):
    import yaml

    from tests.optimization.test_study_run import small_study

    study = small_study(tmp_path)
    data = yaml.safe_load(study.read_text())
    data["algorithm"]["polish"] = "ends"
    study.write_text(yaml.safe_dump(data, sort_keys=False))
    args = ["optimize", str(study), "--seed", "3", "--json"]
    clean = runner.invoke(app, [*args, "--out", str(tmp_path / "clean")])
    assert clean.exit_code == 0, clean.output
    out = tmp_path / "out"
    assert runner.invoke(app, [*args, "--out", str(out)]).exit_code == 0
    path = out / "checkpoint" / name
    _forged(path, change)
    again = runner.invoke(app, [*args, "--out", str(out)])
    assert again.exit_code == 0, again.output
    assert f"checkpoint {path} is not trusted" in again.stderr and "evaluated again" in again.stderr
    assert again.stdout == clean.stdout.replace(str(tmp_path / "clean"), str(out))  # as an unforged run's


# -- names on pages: escaped, nothing runs ------------------------------------------------------------------------
HOSTILE_STUDY = "<img src=x onerror=document.title='X'>.yaml"


@pytest.mark.slow  # a browser
def test_a_hostile_study_file_name_stays_text_in_the_report(browser, tmp_path):
    """The study file's name reaches report.html (its title and heading): escaped, it is text, and nothing runs."""
    from tests.optimization.test_study_run import small_study

    study = small_study(tmp_path).rename(tmp_path / HOSTILE_STUDY)
    out = tmp_path / "out"
    result = runner.invoke(app, ["optimize", str(study), "--seed", "3", "--out", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    browser.get((out / "report.html").resolve().as_uri())
    sources = browser.execute_script("return Array.from(document.images).map(function (i) { return i.src; })")
    assert sources and all(s.startswith("data:image/png;base64,") for s in sources)  # no <img src=x> was made
    title = browser.execute_script("return document.title")
    assert title != "X" and HOSTILE_STUDY in title
    assert HOSTILE_STUDY in browser.find_element("tag name", "h1").text
    page = (out / "report.html").read_text()
    assert "<img src=x" not in page and "&lt;img src=x onerror=document.title=&#x27;X&#x27;&gt;.yaml" in page
