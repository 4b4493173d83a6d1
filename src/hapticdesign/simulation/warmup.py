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
``np.bool_(True)``; and wrappers that only allocate scratch for a compiled loop stay Python functions.
"""

from __future__ import annotations

import fcntl
import os
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numba
from numba.core import event

LOCK_FILE = "hapticdesign-compile.lock"
AREAS = (("hapticdesign.simulation", "rendering", 35.0),
         ("hapticdesign.analysis.dynamics.closed_loop_plant", "rendering", 35.0),
         ("hapticdesign.analysis.dynamics", "dynamics", 15.0),
         ("hapticdesign.analysis.design_batch", "design-index", 35.0),
         ("hapticdesign", "kinematics", 30.0))
"""Kernel areas by module prefix (the longest matching prefix wins): the area's name and the seconds its first
compile took on this project's 2-core machine at a load average of 2-4 (wall time of the compiles, empty cache:
``spec`` of examples/devices/falcon-assumed-motors.yaml for the kinematics, the closed-loop dynamics and the rendering
loop, ``optimize`` of examples/studies/falcon-redesign.yaml for the design indices), which the notice quotes as the
time to expect."""
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
