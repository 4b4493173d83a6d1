"""A campaign's local Dask cluster starts quietly on free ports and closes cleanly: a successful run's stderr is
its progress and nothing else, even while another program holds Dask's default dashboard port 8787."""

import errno
import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from tests.helpers.sim_designs import write_designs

pytestmark = pytest.mark.slow  # a child process starts a cluster of two worker processes

ROOT = Path(__file__).resolve().parents[2]


def _hold_port(port: int) -> socket.socket | None:
    """Listen on ``port`` (None when something already does: then it is held anyway)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        sock.bind(("", port))
    except OSError as exc:
        sock.close()
        if exc.errno == errno.EADDRINUSE:
            return None
        raise
    sock.listen()
    return sock


def test_an_analytic_campaign_ends_without_traceback_or_port_warning(tmp_path):
    designs = write_designs(tmp_path / "designs.csv")
    held = _hold_port(8787)
    try:
        run = subprocess.run(
            [sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "campaign", "--designs",
             str(designs), "--out", str(tmp_path / "out"), "--method", "analytic", "--workers", "2"],
            capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(ROOT / "src")}, cwd=tmp_path,
            check=False, timeout=600)
    finally:
        if held is not None:
            held.close()
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr and "CommClosedError" not in run.stderr
    assert "8787" not in run.stderr and "Warning" not in run.stderr
    assert all(line.startswith("campaign cases: ") for line in run.stderr.splitlines()), run.stderr
    assert run.stdout.startswith("16 cases: 16 run, 0 already done")


def test_the_local_cluster_takes_free_ports_and_warns_of_none(recwarn):
    """Dask's default puts the scheduler's HTTP server on 8787 and warns when that port is taken (as by a second
    run, or another test under xdist); the campaign's cluster asks the system for a free port instead."""
    from hapticdesign.simulation.campaign import close_client, dask_client

    held = _hold_port(8787)
    try:
        client = dask_client(None, 1, quiet=True)
        try:
            ports = [s.getsockname()[1] for s in client.cluster.scheduler.http_server._sockets.values()]
            assert client.submit(sum, [1, 2]).result() == 3
        finally:
            close_client(client, own_cluster=True)
    finally:
        if held is not None:
            held.close()
    assert ports and 8787 not in ports
    assert not [w for w in recwarn if "8787" in str(w.message)]
