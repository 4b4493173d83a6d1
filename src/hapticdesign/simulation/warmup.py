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
- :func:`compile_notice`: calls back once per group of kernels (:data:`GROUPS`: the rendering loop, the
  closed-loop kernels, the design kernels), when a kernel of the group actually starts compiling (a cache
  miss), with the CPU time that group's first compile takes, so that a command says why its first run on a
  machine takes longer, and nothing once the kernels are in the cache.

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
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numba
from numba.core import event

LOCK_FILE = "hapticdesign-compile.lock"
GROUPS: tuple[tuple[str, float, tuple[str, ...]], ...] = (
    ("the rendering loop", 10.0, ("hapticdesign.simulation.kernel", "hapticdesign.analysis.dynamics.closed_loop_plant")),
    ("the closed-loop kernels", 12.0, ("hapticdesign.analysis.loops.closure_kernel", "hapticdesign.analysis.loops.records",
                                       "hapticdesign.analysis.dynamics.actuated_kernel")),
    ("the design kernels", 7.0, ("hapticdesign.analysis.reach_kernel", "hapticdesign.analysis.design_batch")),
)
"""The kernels whose first compile takes long enough to announce: per group its name, about how many CPU seconds
its first compile takes (``benchmarks/bench_compile.py`` on a 2-core machine: the Phantom's rendering loop, the
delta's closed-loop kernels, the five-bar study's design kernels beyond those) and its modules."""


def notice(group: str, seconds: float) -> str:
    """The line that says a group of kernels is compiling."""
    return f"compiling {group}, once per machine: about {seconds:g} CPU-s (later runs load them from numba's cache)"


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
    """Calls ``show`` with the group's :func:`notice` at the start of the first compile of a kernel of each of
    :data:`GROUPS` that a command compiles itself (not the callees a kernel of another group compiles with it)."""

    def __init__(self, show: Callable[[str], None]):
        self.show = show
        self.shown: set[str] = set()
        self.depth = 0

    def on_start(self, ev) -> None:
        self.depth += 1
        if self.depth > 1:
            return
        module = getattr(getattr(ev.data.get("dispatcher"), "py_func", None), "__module__", "") or ""
        for group, seconds, modules in GROUPS:
            if module in modules and group not in self.shown:
                self.shown.add(group)
                self.show(notice(group, seconds))

    def on_end(self, ev) -> None:
        self.depth -= 1


@contextmanager
def compile_notice(show: Callable[[str], None]) -> Iterator[None]:
    """Within the block, ``show`` a group's :func:`notice` once when a kernel of the group starts compiling (not when
    it loads from the cache)."""
    with event.install_listener("numba:compile", _FirstCompile(show)):
        yield
