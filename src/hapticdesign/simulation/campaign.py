"""Campaigns over a design set: both criteria, both types (seed 000 §4.1.4, §4.2.4, Tables 4.4, 4.6).

Design files are CSV with the columns ``level, ln, ln_H, ln_C, ln_G`` and every inertial
parameter of the device in the seed's names (``m1 ... Iyz3a``); an optional ``design`` column
names the rows. The LN columns are carried along (``nan`` allowed where unknown); ``level`` groups. The first design's cases run in
the calling process before any worker starts, so that the numba kernels are compiled (or loaded) once and left
in numba's cache for the workers (:mod:`.warmup`); every other case (design x criterion x type) runs on Dask
workers (local processes by default, or a cluster at ``--scheduler``; one task per design). Each case is
written to ``cases/<key>.json`` the moment its design's task finishes; a rerun skips the cases already written. The aggregation writes the per-design table
(``results.csv``), per-level range, mean and standard deviation with the share of designs whose
type 1 and type 2 results agree (``summary.csv``, ``summary.md``) and the figures.
"""

from __future__ import annotations

import csv
import io
import fcntl
import json
import logging
import math
import os
import re
import signal
import socket
import struct
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from hapticdesign.analysis.dynamics.device import coriolis_centrifugal, gravity, mass_matrix
from hapticdesign.devices.registry import preset
from hapticdesign.errors import InputError, PhysicalConsistencyWarning, UserError
from hapticdesign.files import csv_rows, output_folder, read_text, write_atomically
from hapticdesign.simulation.analytic import AnalyticProblem, wall_loop
from hapticdesign.simulation.config import LoopConfig
from hapticdesign.simulation.impedance import (ImpedanceProblem, fast_search, planned_simulations,
                                               require_search_workload)
from hapticdesign.simulation.paths import Chirp
from hapticdesign.simulation.transparency import transparency
from hapticdesign.simulation.transparency_estimate import check_request
from hapticdesign.workload import require_plant_steps, worker_count

META_COLUMNS = ("level", "ln", "ln_H", "ln_C", "ln_G")
CRITERIA = ("impedance", "transparency")
TYPES = (1, 2)
# Design names become file names under cases/: letters, digits, '.', '_', '-', not starting with '.'.
DESIGN_NAME = re.compile(r"^[A-Za-z0-9_-][A-Za-z0-9._-]{0,99}$")
LOCK_FILE = "campaign.lock"
DASK_LOG_ENV = "DASK_LOGGING__DISTRIBUTED"
# Entries of H, C, G beyond this overflow once multiplied by rates and gains in the simulation.
DYNAMICS_BOUND = 1e150


@dataclass(frozen=True)
class Design:
    """One row of a design file."""

    name: str
    level: float
    meta: dict[str, float]
    params: dict[str, float]


@dataclass(frozen=True)
class CampaignOptions:
    """Settings shared by every case (the seed's by default)."""

    preset: str = "phantom-3dof"
    k_limit: int = 200
    stiffness: float = 4.0
    chirp: Chirp = field(default_factory=Chirp)
    duration: float = 5.0
    bandwidth_agreement_hz: float = 0.1
    method: str = "simulation"
    """How the cases are answered: ``simulation`` (the numba loop) or ``analytic`` (the loop linearized at the
    start pose, no loop run: the impedance range from the exact linear response of :mod:`.analytic` (type 2
    along the driven motion, :mod:`.analytic_driven`; exact for joint 1), the bandwidth from the linear
    transmitted torque of :mod:`.analytic_transparency`; exact for type 1, and for type 2 when LN = 0)."""

    conditions: LoopConfig = field(default_factory=LoopConfig)
    """Realistic conditions for every case (seed 000 ch. 5's first future-work item): the loop (its
    :class:`~hapticdesign.analysis.sampled_loop.SampledLoop`: period, delay, modelling error, hand), encoder
    quantization, the compensator (its terms, its error per group with seeded signs) and Coulomb friction in the
    plant. The seed's ideal loop by default; ``duration`` above sets the impedance runs' length, the campaign sets
    the wall."""

    def __post_init__(self) -> None:
        if self.method not in ("simulation", "analytic"):
            raise UserError(f"the campaign method must be 'simulation' or 'analytic', got {self.method!r}")
        if self.method == "analytic" and self.conditions.counts is not None:
            raise UserError("the analytic method has no encoder quantization (not linear): use the simulation")
        if self.method == "analytic" and self.conditions.coulomb is not None and any(self.conditions.coulomb):
            raise UserError("the analytic method has no Coulomb friction (not linear): use the simulation")


def _number(text: str, where: str, allow_nan: bool = False) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise UserError(f"{where}: {text!r} is not a number") from None
    if not (math.isfinite(value) or (allow_nan and math.isnan(value))):
        raise UserError(f"{where}: value must be finite, got {text!r}")
    return value


def read_designs(path: Path, preset_name: str = "phantom-3dof") -> list[Design]:
    """Read and check a design file: required columns, numbers, physically meaningful bodies."""
    path = Path(path)
    device = preset(preset_name)
    try:
        rows = list(csv.DictReader(io.StringIO(read_text(path, "design file"), newline="")))
    except csv.Error as exc:
        raise UserError(f"{path}: malformed CSV ({exc})") from None
    header = rows[0].keys() if rows else []
    if not rows:
        raise UserError(f"{path}: no designs")
    names = device.inertial_names()
    missing = [c for c in (*META_COLUMNS, *names) if c not in header]
    if missing:
        shown = ", ".join(missing[:8]) + (" ..." if len(missing) > 8 else "")
        raise UserError(f"{path}: missing columns {shown}")
    designs = []
    for i, row in enumerate(rows, start=1):
        where = f"{path} row {i}"
        name = (row.get("design") or f"d{i:04d}").strip()
        if not DESIGN_NAME.match(name):
            raise UserError(f"{where}: design name {name[:40]!r} cannot name a file (use at most 100 letters, digits, "
                            "'.', '_' or '-', not starting with '.')")
        meta = {c: _number(row[c], f"{where} column {c}", allow_nan=c != "level") for c in META_COLUMNS}
        params = {c: _number(row[c], f"{where} column {c}") for c in names}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PhysicalConsistencyWarning)
            try:
                _check_design(device.with_params(params))
            except UserError as exc:
                raise UserError(f"{where} ({name}): {exc}") from None
        designs.append(Design(name, meta["level"], meta, params))
    if len({d.name for d in designs}) != len(designs):
        raise UserError(f"{path}: design names must be unique")
    return designs


def _check_design(device) -> None:
    """Physically consistent bodies and finite dynamics (checked before any case runs)."""
    device.check(strict=False)
    rng = np.random.default_rng(0)
    poses = np.vstack([np.zeros(device.n_dof), rng.uniform(-np.pi, np.pi, (4, device.n_dof))])
    with np.errstate(all="ignore"):
        largest = max(float(np.max(np.abs(f(device, q)))) for q in poses for f in (mass_matrix, coriolis_centrifugal, gravity))
    if not largest <= DYNAMICS_BOUND:
        raise UserError(f"its parameters make the equations of motion overflow (entries of H, C or G reach "
                        f"{largest:.3g}, beyond {DYNAMICS_BOUND:g})")


def _require_case_workload(options: CampaignOptions) -> None:
    """Refuse cases whose own plant steps exceed the workload limit (a campaign has many; each is one job), and a
    transparency request that every transparency case would refuse (:func:`check_request`)."""
    from hapticdesign.simulation.config import LoopConfig

    check_request(preset(options.preset), 1, options.stiffness, options.chirp, options.conditions)
    if options.method == "analytic":  # each case's exact loop, estimated before the folder is made
        wall_loop(options.conditions).require_exact(1, 1)
    require_search_workload(LoopConfig(duration=options.duration), planned_simulations("fast", options.k_limit))
    require_plant_steps(f"a transparency case of {options.chirp.sweep_time:g} s",
                        options.chirp.sweep_time / LoopConfig().step)


def case_key(design: str, criterion: str, sim_type: int) -> str:
    return f"{design}__{criterion}__type{sim_type}"


def run_case(preset_name: str, params: dict[str, float], criterion: str, sim_type: int,
             options: CampaignOptions) -> dict:
    """One simulation case on a worker: maximum stable impedance or transparency bandwidth."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicalConsistencyWarning)
        device = preset(preset_name).with_params(params)
    if criterion == "impedance":
        config = replace(options.conditions, duration=options.duration)
        kind = AnalyticProblem if options.method == "analytic" else ImpedanceProblem
        result = fast_search(kind(device, sim_type, config=config), options.k_limit)
        found = result.as_dict()
        found["limiting_criterion"] = found.pop("criterion")  # "criterion" names the campaign's (impedance)
        return {"value": float(result.k_max), **found, "method": options.method}
    result = transparency(device, sim_type, options.stiffness, options.chirp, config=options.conditions,
                          method=options.method)
    keep = result.frequency <= options.chirp.f1
    return {
        **{k: v for k, v in result.as_dict().items() if k in ("steady_bandwidth_hz", "analytic_exact")},
        "value": result.bandwidth_hz,
        "bandwidth_hz": result.bandwidth_hz,
        "frequency": result.frequency[keep].tolist(),
        "g_t_db": (20 * np.log10(np.abs(result.g_t[keep]))).tolist(),
        "method": options.method,
    }


def run_design_cases(preset_name: str, params: dict[str, float], cases: list[tuple[str, int]],
                     options: CampaignOptions) -> list[dict]:
    """Several cases of one design on a worker, in one task (an analytic case takes milliseconds: one task
    per case would spend most of the time scheduling)."""
    return [run_case(preset_name, params, criterion, sim_type, options) for criterion, sim_type in cases]


SCHEDULER_ADDRESS = re.compile(r"^(?:(?:tcp|tls|inproc|ucx|ws|wss)://)?[A-Za-z0-9.\-\[\]:]+:\d{1,5}$")


@contextmanager
def dask_logging(quiet: bool) -> Iterator[None]:
    """Dask's loggers here and in the worker processes it starts: warnings and errors only (no
    connection chatter), nothing at all when ``quiet``."""
    logger = logging.getLogger("distributed")
    before, env_before = logger.level, os.environ.get(DASK_LOG_ENV)
    logger.setLevel(logging.CRITICAL + 1 if quiet else logging.WARNING)
    os.environ[DASK_LOG_ENV] = "critical" if quiet else "warning"  # read by the spawned worker processes
    try:
        yield
    finally:
        logger.setLevel(before)
        if env_before is None:
            os.environ.pop(DASK_LOG_ENV, None)
        else:
            os.environ[DASK_LOG_ENV] = env_before


def check_scheduler(address: str) -> None:
    """Refuse text that is not a Dask scheduler address (``tcp://host:port`` or ``host:port``)."""
    if not SCHEDULER_ADDRESS.match(address.strip()):
        raise UserError(f"{address[:80]!r} is not a Dask scheduler address (expected e.g. tcp://host:8786)")


SCHEDULER_ANSWER_SECONDS = 10.0
"""How long the service at a TCP ``--scheduler`` address has to greet a new connection as a Dask scheduler does
before it is refused (docs/limits.md): a service that is not Dask (a web server, which waits for a request) never
greets, or greets with bytes that Dask's client would read as a message of exabytes."""
HANDSHAKE_MOST_BYTES = 1 << 16
"""Largest first message taken for a Dask handshake (Dask's is about a hundred bytes)."""


def check_dask_answers(address: str, seconds: float | None = None) -> None:
    """Refuse a TCP scheduler address whose service does not greet as Dask within ``seconds`` (default
    :data:`SCHEDULER_ANSWER_SECONDS`): a Dask server writes its handshake first, a message framed by its 8-byte length
    (``struct`` ``Q``, as Dask's TCP comm) that names the ``pickle-protocol``. Other transports (tls, ws, ucx) are
    left to Dask's client."""
    seconds = SCHEDULER_ANSWER_SECONDS if seconds is None else seconds
    text = address.strip()
    scheme, _, rest = text.rpartition("://")
    if scheme not in ("", "tcp"):
        return
    host, _, port = rest.rpartition(":")
    try:
        sock = socket.create_connection((host.strip("[]"), int(port)), timeout=seconds)
    except OSError as exc:
        raise UserError(f"cannot reach the Dask scheduler at {text}: {exc.strerror or exc}") from None
    deadline = time.monotonic() + seconds
    with sock:
        try:
            (size,) = struct.unpack("Q", _received(sock, struct.calcsize("Q"), deadline))
            greets = 0 < size <= HANDSHAKE_MOST_BYTES and b"pickle-protocol" in _received(sock, size, deadline)
        except OSError:
            greets = False
    if not greets:
        raise UserError(f"the service at {text} did not answer as a Dask scheduler within {seconds:g} s (is it a "
                        "Dask scheduler's address?)")


def _received(sock: socket.socket, size: int, deadline: float) -> bytes:
    """``size`` bytes from ``sock`` before ``deadline`` (time.monotonic), else OSError (a timeout or a closed peer)."""
    data = b""
    while len(data) < size:
        sock.settimeout(max(deadline - time.monotonic(), 1e-3))
        chunk = sock.recv(size - len(data))
        if not chunk:
            raise OSError("closed")
        data += chunk
    return data


def local_cluster(workers: int | None, quiet: bool = False, processes: bool = True):
    """A Dask cluster on this machine, quiet and on free ports: ``workers`` processes (or threads when ``processes``
    is false) of one thread each, the scheduler and its HTTP server on ports the system picks on 127.0.0.1, no
    dashboard (Dask's default binds port 8787 even without one, and warns when another run holds it). A context
    manager: leaving it stops the workers, then the scheduler."""
    from dask.distributed import LocalCluster

    return LocalCluster(n_workers=worker_count(workers), threads_per_worker=1, processes=processes,
                        host="127.0.0.1", protocol="tcp://", dashboard_address=None,
                        scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
                        silence_logs=logging.CRITICAL + 1 if quiet else logging.ERROR)


def dask_client(scheduler: str | None, workers: int | None, quiet: bool = False):
    """A client of the Dask scheduler at ``scheduler`` (a one-line error when it cannot be reached), or of a
    :func:`local_cluster` of ``workers`` processes when ``scheduler`` is None."""
    from dask.distributed import Client

    if scheduler:
        check_scheduler(scheduler)
        check_dask_answers(scheduler)
        try:
            return Client(scheduler.strip(), timeout="20s")
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            first = str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
            raise UserError(f"cannot reach the Dask scheduler at {scheduler}: {first}") from None
    return Client(local_cluster(workers, quiet))


@contextmanager
def deferred_interrupts() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) over the block and raise it after: a Ctrl-C while Dask's worker processes start
    or stop is kept, not lost, and the block is never cut half-way.

    Ctrl-C reaches the terminal's whole process group. Over the block, SIGINT is blocked in this thread's signal
    mask, which the threads started inside (Dask's event loop, which spawns the workers) and the worker processes
    inherit: the workers never answer it (no traceback from them), and this process alone ends the campaign. A
    SIGINT that another thread receives meanwhile is recorded by a handler instead of interrupting the block; one
    left pending is delivered once the mask is restored. Off the main thread (where Python cannot set a handler)
    the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    from multiprocessing import resource_tracker

    # started now, unmasked: starting it later (for the first worker) would unblock SIGINT in that thread
    resource_tracker.ensure_running()
    caught: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        signal.signal(signal.SIGINT, signal.SIG_DFL if previous is None else previous)
    if caught:
        raise KeyboardInterrupt


def close_client(client, own_cluster: bool) -> None:
    """Stop the client, then the local cluster it started, as Dask orders it (the cluster retires its workers
    before it stops the scheduler, so none heartbeats a closed scheduler)."""
    cluster = getattr(client, "cluster", None) if own_cluster else None
    client.close()
    if cluster is not None:
        cluster.close()


@contextmanager
def campaign_lock(out: Path) -> Iterator[None]:
    """An exclusive lock on ``out`` for the run: a second campaign in the same folder is refused."""
    output_folder(out)
    try:  # never through a link: the lock file is created in ``out`` itself
        handle = os.fdopen(os.open(out / LOCK_FILE, os.O_WRONLY | os.O_CREAT | os.O_APPEND | os.O_NOFOLLOW, 0o666), "a")
    except OSError as exc:
        raise UserError(f"cannot write {out / LOCK_FILE}: {exc.strerror or exc}") from None
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise UserError(f"another campaign is running in {out}; wait for it or choose another output folder") from None
        yield
    finally:
        handle.close()


def case_done(path: Path, design: str, criterion: str, sim_type: int) -> bool:
    """True when ``path`` holds this case's complete record; empty, corrupt or stray files are not done."""
    try:
        record = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, ValueError):
        return False
    result_key = "k_max" if criterion == "impedance" else "bandwidth_hz"
    return (isinstance(record, dict) and record.get("design") == design and record.get("type") == sim_type
            and "value" in record and result_key in record)


def run_campaign(designs_path: Path, out: Path, options: CampaignOptions | None = None,
                 scheduler: str | None = None, workers: int | None = None,
                 progress: Callable[[int, int], None] | None = None, quiet: bool = False) -> dict:
    """Run every missing case, then aggregate; returns counts of cases run and skipped.

    Cases whose file is missing, empty, corrupt or not this case's record are (re)computed; a lock
    on ``out`` refuses a second campaign in the same folder; ``quiet`` silences Dask's logs.
    """
    options = options or CampaignOptions()
    if scheduler:
        check_scheduler(scheduler)
    else:
        worker_count(workers)
    _require_case_workload(options)
    designs = read_designs(designs_path, options.preset)
    out = Path(out)
    with campaign_lock(out), dask_logging(quiet):
        return _run_locked(designs, out, options, scheduler, workers, progress, quiet)


def _run_locked(designs: list[Design], out: Path, options: CampaignOptions, scheduler: str | None,
                workers: int | None, progress: Callable[[int, int], None] | None, quiet: bool) -> dict:
    cases_dir = out / "cases"
    output_folder(cases_dir)
    output_folder(out / "figures")
    settings = json.dumps({**asdict(options), "designs": [asdict(d) for d in designs]}, sort_keys=True)
    stamp = out / "campaign.json"
    if stamp.exists() and stamp.read_text() != settings:
        raise InputError(f"{out} holds a campaign with other designs or settings; choose another output folder", "out")
    write_atomically(stamp, settings)
    todo = [(d, c, t) for d in designs for c in CRITERIA for t in TYPES
            if not case_done(cases_dir / f"{case_key(d.name, c, t)}.json", d.name, c, t)]
    total = len(designs) * len(CRITERIA) * len(TYPES)
    by_design: dict[str, tuple[Design, list[tuple[str, int]]]] = {}
    for d, c, t in todo:
        by_design.setdefault(d.name, (d, []))[1].append((c, t))
    done = total - len(todo)

    def record(d: Design, cases: list[tuple[str, int]], results: list[dict]) -> None:
        nonlocal done
        for (c, t), result in zip(cases, results):
            write_atomically(cases_dir / f"{case_key(d.name, c, t)}.json",
                             json.dumps({"design": d.name, "level": d.level, "criterion": c, "type": t, **result}))
            done += 1
            if progress is not None:
                progress(done, total)

    if by_design:
        # The first design here, before any worker starts: this process compiles the kernels (or loads them)
        # once and leaves them in numba's cache, where the workers load them instead of each compiling them.
        first, *rest = by_design.values()
        record(*first, run_design_cases(options.preset, first[0].params, first[1], options))
        if rest:
            from dask.distributed import as_completed

            client = None
            try:
                with deferred_interrupts():
                    client = dask_client(scheduler, workers, quiet)
                futures = {client.submit(run_design_cases, options.preset, d.params, cases, options,
                                         key=f"cases-{d.name}", pure=False): (d, cases) for d, cases in rest}
                for fut in as_completed(futures):
                    record(*futures[fut], fut.result())
            finally:
                if client is not None:
                    with deferred_interrupts():
                        close_client(client, own_cluster=not scheduler)
    aggregate(designs, out, options)
    return {"cases": total, "run": len(todo), "skipped": total - len(todo)}


def load_cases(designs: list[Design], out: Path) -> dict[tuple[str, str, int], dict]:
    cases = {}
    for d in designs:
        for c in CRITERIA:
            for t in TYPES:
                path = Path(out) / "cases" / f"{case_key(d.name, c, t)}.json"
                if not case_done(path, d.name, c, t):
                    raise UserError(f"{path} is missing or corrupt; run the campaign again to recompute it")
                cases[(d.name, c, t)] = json.loads(path.read_text())
    return cases


def agree(criterion: str, a: float | None, b: float | None, options: CampaignOptions) -> bool:
    """Same result in types 1 and 2: equal stiffness; bandwidths equal at the seed's 0.1 Hz resolution."""
    if a is None or b is None:
        return a is None and b is None
    if criterion == "impedance":
        return a == b
    return abs(a - b) < 0.5 * options.bandwidth_agreement_hz


def summarize(designs: list[Design], cases: dict, options: CampaignOptions) -> list[dict]:
    """Per level, criterion and type: count, min, max, mean, standard deviation; agreement share."""
    rows = []
    for level in sorted({d.level for d in designs}):
        members = [d for d in designs if d.level == level]
        for c in CRITERIA:
            same = sum(agree(c, cases[(d.name, c, 1)]["value"], cases[(d.name, c, 2)]["value"], options) for d in members)
            for t in TYPES:
                values = np.array([np.nan if cases[(d.name, c, t)]["value"] is None else cases[(d.name, c, t)]["value"]
                                   for d in members], dtype=float)
                finite = values[np.isfinite(values)]
                rows.append({
                    "level": level, "criterion": c, "type": t, "n": len(members),
                    "min": float(finite.min()) if finite.size else None,
                    "max": float(finite.max()) if finite.size else None,
                    "mean": float(finite.mean()) if finite.size else None,
                    "std": float(finite.std(ddof=1)) if finite.size > 1 else None,
                    "agreement_share": same / len(members),
                })
    return rows


def _fmt(value, digits: int = 3) -> str:
    return "" if value is None else f"{value:.{digits}g}"


def aggregate(designs: list[Design], out: Path, options: CampaignOptions) -> None:
    """Write results.csv, summary.csv, summary.md and the figures from the case files."""
    from hapticdesign.simulation import figures

    out = Path(out)
    cases = load_cases(designs, out)
    header = ["design", *META_COLUMNS, "k_max_type1", "k_max_type2", "criterion_type1", "criterion_type2",
              "bandwidth_hz_type1", "bandwidth_hz_type2"]
    lines = []
    for d in designs:
        imp1, imp2 = cases[(d.name, "impedance", 1)], cases[(d.name, "impedance", 2)]
        bw1, bw2 = cases[(d.name, "transparency", 1)]["value"], cases[(d.name, "transparency", 2)]["value"]
        row = [d.name, *(repr(d.meta[c]) for c in META_COLUMNS), _fmt(imp1["value"], 6), _fmt(imp2["value"], 6),
               imp1.get("limiting_criterion", ""), imp2.get("limiting_criterion", ""), _fmt(bw1, 6), _fmt(bw2, 6)]
        lines.append(row)
    write_atomically(out / "results.csv", csv_rows(header, lines))
    summary = summarize(designs, cases, options)
    keys = list(summary[0])
    write_atomically(out / "summary.csv", "\n".join([",".join(keys)] + [
        ",".join("" if r[k] is None else str(r[k]) for k in keys) for r in summary]) + "\n")
    md = ["# Campaign summary", ""]
    for c, unit, title in (("impedance", "N m/rad", "Maximum stable impedance (Table 4.4 layout)"),
                           ("transparency", "Hz", "Transparency bandwidth (Table 4.6 layout)")):
        md += [f"## {title}", "", f"| level | type | range [{unit}] | mean | std (1 sigma) | type 1 = type 2 |",
               "|---|---|---|---|---|---|"]
        for r in (r for r in summary if r["criterion"] == c):
            md.append(f"| {r['level']:g} | {r['type']} | {_fmt(r['min'])} - {_fmt(r['max'])} | {_fmt(r['mean'])} | "
                      f"{_fmt(r['std'])} | {100 * r['agreement_share']:.0f} % |")
        md.append("")
    write_atomically(out / "summary.md", "\n".join(md))
    figures.write_all(designs, cases, summary, out / "figures")

