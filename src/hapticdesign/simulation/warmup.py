"""Compile the rendering kernels once per machine, not once per process (numba's on-disk cache).

Every numba kernel of the toolkit is compiled with ``cache=True``: the first process that needs a kernel
for a record type compiles it and writes the machine code to numba's cache folder (``__pycache__``
beside the sources, a user-wide folder when that is not writable, or ``NUMBA_CACHE_DIR``); every later
process on the machine loads it from there in milliseconds. What this module adds:

- :func:`ensure_compiled`: a process's first call of a kernel for a record type loads or compiles it
  under an exclusive lock on a file in the cache folder, so that processes starting together (Dask or
  pytest-xdist workers) wait for the one compiling and then load its result, instead of all compiling
  the same kernel, and so that two processes never write one kernel's cache index at the same time
  (numba rewrites the index whole: two writers compiling different record types could lose one entry);
- :func:`compile_notice`: calls back when the kernels of an area (kinematics, dynamics, rendering, design
  indices) actually start compiling (a cache miss) with the time a first compile takes, then every half minute
  while they go on, so that a command's first run on a machine says why it takes longer and for how long.

What a first run compiles is kept small where the kernels call each other: a constant argument written
as a literal (``0``, ``True``) to a separately compiled kernel makes numba compile that kernel once more
for the literal (``Literal[int](0)`` beside ``int64``), so such calls pass ``np.int64(0)`` or
``np.bool_(True)``; arrays handed to a kernel are writable and C-contiguous (a read-only or strided array is
another specialization); and wrappers that only allocate scratch for a compiled loop stay Python functions.
Helpers that several kernels call (the walk of the frame tree, the closures' residual and Jacobian, a pose's
reduced Jacobians and mass terms) are compiled once as functions of their own that LLVM inlines
(``forceinline``), not copied and typed again by numba at every call site (``inline="always"``, whose cost
grows with the size of the caller): ``benchmarks/bench_compile.py`` lists what each first command compiles.
"""

from __future__ import annotations

import fcntl
import multiprocessing
import os
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numba
from numba.core import event

LOCK_FILE = "hapticdesign-compile.lock"
AREAS = (("hapticdesign.simulation", "rendering", 30.0),
         ("hapticdesign.analysis.dynamics.closed_loop_plant", "rendering", 30.0),
         ("hapticdesign.analysis.dynamics", "dynamics", 7.0),
         ("hapticdesign.analysis.design_batch", "design-index", 8.0),
         ("hapticdesign", "kinematics", 11.0))
"""Kernel areas by module prefix (the longest matching prefix wins): the area's name and the seconds its first
compile took on this project's 2-core machine at a load average of 2-4 (wall time of the compiles, empty cache:
``spec`` of examples/devices/falcon-assumed-motors.yaml for the kinematics, the closed-loop dynamics and the rendering
loop, ``optimize`` of examples/studies/falcon-redesign.yaml for the design indices), which the notice quotes as the
time to expect. Issue 43 cut these compiles; the figures were scaled by the CPU time each area's compiles took in
the same two commands before and after (``benchmarks/bench_compile.py falcon-spec falcon-study``: kinematics 37-38
-> 13-14 CPU-s, dynamics 12 -> 5-6, rendering 24 -> 21, design indices 23 -> 5)."""
HEARTBEAT = 30.0
"""Seconds between the lines that say a long compile is still going."""


def area_of(module: str) -> tuple[str, float] | None:
    """The area of :data:`AREAS` a kernel's module belongs to and its typical first compile (seconds), or None
    for a kernel outside the toolkit (a user's)."""
    found = [(prefix, name, typical) for prefix, name, typical in AREAS
             if module == prefix or module.startswith(prefix + ".")]
    if not found:
        return None
    _, name, typical = max(found, key=lambda item: len(item[0]))
    return name, typical


def notice(area: str, typical: float) -> str:
    """The line a first compile of ``area``'s kernels starts with (``typical``: seconds it takes, :data:`AREAS`)."""
    return (f"compiling the {area} kernels (once per machine: later runs load them from numba's cache); about "
            f"{_duration(typical)} on a 2-core machine, longer under load...")


def still(area: str, kernels: int, seconds: float, typical: float) -> str:
    """The line that says a compile of ``area``'s kernels is still going, with what is left of the typical time."""
    left = typical - seconds
    rest = f"about {_duration(left)} left" if left > 0 else f"longer than the usual {_duration(typical)} (a busy machine)"
    return f"still compiling the {area} kernels: {kernels} so far in {_duration(seconds)}; {rest}..."


def _duration(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 90 else f"{seconds / 60:.1f} min"


def cache_folder(dispatcher) -> str | None:
    """The folder numba caches a kernel's machine code in (``None`` for a kernel without ``cache=True``)."""
    cache = getattr(dispatcher, "_cache", None)
    return getattr(cache, "_cache_path", None)


@contextmanager
def compile_lock(dispatcher) -> Iterator[None]:
    """An exclusive lock on the kernel's cache folder (blocking: the next process waits for the compile)."""
    folder = cache_folder(dispatcher)
    try:
        os.makedirs(folder, exist_ok=True)
        handle = open(os.path.join(folder, LOCK_FILE), "a")
    except (TypeError, OSError):  # no cache, or a folder we cannot write: numba compiles in memory only
        yield
        return
    with handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def ensure_compiled(dispatcher, *args) -> None:
    """Load ``dispatcher``'s machine code for the types of ``args`` from numba's cache, or compile and cache it,
    under :func:`compile_lock`; nothing to do once this process has it."""
    signature = tuple(numba.typeof(a) for a in args)
    if signature in dispatcher.overloads:
        return
    with compile_lock(dispatcher):
        dispatcher.compile(signature)


def in_cache(dispatcher) -> bool:
    """Whether numba's cache folder holds an index of ``dispatcher``'s machine code, written by an earlier process
    (for some signature; numba drops the index when the kernel's source file changes)."""
    cache_file = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
    index = getattr(cache_file, "_index_path", None)
    return index is not None and os.path.exists(index)


def compile_aside(dispatcher, target: Callable[[], None]) -> multiprocessing.process.BaseProcess | None:
    """Compile ``dispatcher`` in a second process while this one goes on, when numba's cache does not hold it yet:
    start a fresh (spawned) process that runs ``target`` (a module-level function that calls the kernel through
    :func:`ensure_compiled`), its output discarded, and return it; None when the cache already holds the kernel.

    The compile lock makes this process's own first call of the kernel wait for the second process's compile and
    then load it from the cache, so that on a 2-core machine the compile runs beside this process's other work
    (``make demo``'s equations and Linearity Number step) instead of after it. If the second process fails, this
    one compiles the kernel itself, as without it."""
    if in_cache(dispatcher) or cache_folder(dispatcher) is None:
        return None
    process = multiprocessing.get_context("spawn").Process(target=_quietly, args=(target,), daemon=True)
    process.start()
    return process


def _quietly(target: Callable[[], None]) -> None:
    """Run ``target`` with this process's standard output and error sent to the null device."""
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    os.dup2(null, 2)
    target()


class _FirstCompile(event.Listener):
    """Calls ``show`` with :func:`notice` at the start of the first compile of each area's kernels (:data:`AREAS`),
    then with :func:`still` at most every :data:`HEARTBEAT` seconds while kernels of that area keep compiling."""

    def __init__(self, show: Callable[[str], None], clock: Callable[[], float] = time.monotonic):
        self.show = show
        self.clock = clock
        self.started: dict[str, tuple[float, float]] = {}
        self.count: dict[str, int] = {}
        self.last = 0.0

    def on_start(self, ev) -> None:
        module = getattr(getattr(ev.data.get("dispatcher"), "py_func", None), "__module__", "") or ""
        found = area_of(module)
        if found is None:
            return
        area, typical = found
        now = self.clock()
        self.count[area] = self.count.get(area, 0) + 1
        if area not in self.started:
            self.started[area] = (now, typical)
            self.last = now
            self.show(notice(area, typical))
        elif now - self.last >= HEARTBEAT:
            self.last = now
            self.show(still(area, self.count[area], now - self.started[area][0], typical))

    def on_end(self, ev) -> None:
        """Nothing to do when a compile ends."""


@contextmanager
def compile_notice(show: Callable[[str], None], clock: Callable[[], float] = time.monotonic) -> Iterator[None]:
    """Within the block, ``show`` a line when an area's kernels start compiling (not when they load from the
    cache), then one every :data:`HEARTBEAT` seconds while they go on (see :class:`_FirstCompile`)."""
    with event.install_listener("numba:compile", _FirstCompile(show, clock)):
        yield
