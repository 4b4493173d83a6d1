"""Ctrl-C to a real campaign (the CLI in a child process, a Dask LocalCluster of 2 worker processes): while the
first design runs in the campaign's own process, while the workers start, and while they run. Each time the
whole process group gets SIGINT, as from a terminal; the campaign must end with the CLI's one line and status
130, leave only complete case files, leave no process behind, and a rerun must resume from the cases written."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from hapticdesign.simulation.campaign import CRITERIA, TYPES, case_done
from tests.helpers.sim_designs import PERTURBATIONS, write_designs

pytestmark = pytest.mark.slow  # three interrupted campaigns and one that finishes

ROOT = Path(__file__).resolve().parents[2]
DESIGNS = PERTURBATIONS + [(0.0, {"m3": 0.06}), (1.0, {"m2": 0.12})]
CASES_PER_DESIGN = len(CRITERIA) * len(TYPES)
QUICK = ["--workers", "2", "--duration", "1", "--k-limit", "20", "--sweep", "2", "--f1", "5"]


def _foreground_signals() -> None:
    """In the child before it runs: SIGINT at its default, as a terminal gives its foreground job (a signal that
    this test process ignores would stay ignored in the child: an in-process test of a library may have left it so)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start(designs: Path, out: Path, *extra: str) -> subprocess.Popen:
    """The CLI in its own process group (its Dask workers join it), as a terminal's foreground job."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    return subprocess.Popen(
        [sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "campaign", "--designs",
         str(designs), "--out", str(out), *QUICK, *extra],
        env=env, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        preexec_fn=_foreground_signals)


def _case_files(out: Path) -> list[Path]:
    folder = out / "cases"
    return sorted(folder.iterdir()) if folder.is_dir() else []


def _interrupt_when(child: subprocess.Popen, ready) -> tuple[int, str]:
    """Send SIGINT to the child's process group once ``ready()`` holds; its exit status and stderr."""
    while not ready():
        assert child.poll() is None, f"the campaign ended before the moment to interrupt it: {child.stderr.read()}"
        time.sleep(0.01)
    os.killpg(child.pid, signal.SIGINT)
    _, err = child.communicate()
    return child.returncode, err


def _group_gone(pgid: int) -> bool:
    """True once no process of the group is left (the workers were closed, not orphaned)."""
    for _ in range(300):
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.1)
    return False


def _complete_cases(out: Path) -> int:
    """Count the case files, each required to be a complete record; no temporary file is left."""
    files = _case_files(out)
    assert not [f.name for f in files if f.name.endswith(".tmp")]
    for f in files:
        design, criterion, sim_type = f.stem.split("__")
        assert case_done(f, design, criterion, int(sim_type.removeprefix("type"))), f"{f.name} is incomplete"
    return len(files)


def test_ctrl_c_before_during_worker_start_and_while_running_ends_with_one_line_and_resumes(tmp_path):
    designs = write_designs(tmp_path / "designs.csv", DESIGNS)
    out = tmp_path / "out"
    total = len(DESIGNS) * CASES_PER_DESIGN
    moments = {
        # the first design runs in the campaign's own process, before any worker exists
        "before": lambda n0: (out / "campaign.json").exists(),
        # that design's cases are written just before the workers start: they are starting now
        "worker start-up": lambda n0: len(_case_files(out)) >= n0 + CASES_PER_DESIGN,
        # a worker's design is written: the workers run (at least two designs are still out)
        "running": lambda n0: len(_case_files(out)) >= n0 + 2 * CASES_PER_DESIGN,
    }
    for moment, ready in moments.items():
        n0 = _complete_cases(out)
        child = _start(designs, out, "--quiet")
        status, err = _interrupt_when(child, lambda: ready(n0))
        assert (moment, status, err) == (moment, 130, "error: interrupted\n")
        assert _group_gone(child.pid), f"processes left behind after Ctrl-C {moment}"
        assert not (out / "results.csv").exists()
        assert _complete_cases(out) < total
    written = _complete_cases(out)
    assert written >= 2 * CASES_PER_DESIGN  # the interrupted runs kept what they finished
    child = _start(designs, out, "--json")
    stdout, stderr = child.communicate()
    assert child.returncode == 0, stderr
    counts = json.loads(stdout)
    assert (counts["cases"], counts["run"], counts["skipped"]) == (total, total - written, written)
    assert _complete_cases(out) == total and (out / "results.csv").exists()
