"""Study runs shared by the tests: each smallest ("smoke") study runs once per test session.

Under pytest-xdist the workers share the session's temporary root and take a file lock, so the
run happens once and the other worker reads its result.
"""

from __future__ import annotations

import fcntl
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

CLI = Path(sys.executable).with_name("hapticdesign")


def run_cli(*args: str, timeout: float = 900) -> subprocess.CompletedProcess:
    return subprocess.run([str(CLI), *args], capture_output=True, text=True, timeout=timeout)


def _shared_root(tmp_path_factory) -> Path:
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def _study(tmp_path_factory, name: str) -> tuple[Path, dict]:
    root = _shared_root(tmp_path_factory)
    out = root / f"study-{name}"
    with open(root / f"study-{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (out / "stdout.json").exists():
            done = run_cli("study", name, "--scale", "smoke", "--out", str(out), "--json")
            assert done.returncode == 0, done.stderr
            (out / "stdout.json").write_text(done.stdout)
    return out, json.loads((out / "stdout.json").read_text())


@pytest.fixture(scope="session")
def phantom_study(tmp_path_factory):
    return _study(tmp_path_factory, "phantom")


@pytest.fixture(scope="session")
def rcube_study(tmp_path_factory):
    return _study(tmp_path_factory, "rcube")


@pytest.fixture(scope="session")
def cli():
    """Run ``hapticdesign`` in a subprocess: ``cli(*args)`` -> CompletedProcess."""
    return run_cli
