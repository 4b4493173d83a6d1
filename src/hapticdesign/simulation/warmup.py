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
- :func:`compile_notice`: calls back once, when a kernel of the rendering loop actually starts compiling
  (a cache miss), so that a command can say why its first run takes longer.

What a first run compiles is kept small where the kernels call each other: a constant argument written
as a literal (``0``, ``True``) to a separately compiled kernel makes numba compile that kernel once more
for the literal (``Literal[int](0)`` beside ``int64``), so such calls pass ``np.int64(0)`` or
``np.bool_(True)``; and wrappers that only allocate scratch for a compiled loop stay Python functions.
"""

from __future__ import annotations

import fcntl
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numba
from numba.core import event

NOTICE = "compiling the rendering kernel, once per install (later runs load it from numba's cache)"
LOCK_FILE = "hapticdesign-compile.lock"
RENDERING = ("hapticdesign.simulation.kernel", "hapticdesign.analysis.dynamics.closed_loop_plant")
"""The modules of the rendering loop's kernels, whose first compile takes long enough to announce."""


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
    """Calls ``show(NOTICE)`` at the start of the first compile of a rendering kernel (:data:`RENDERING`)."""

    def __init__(self, show: Callable[[str], None]):
        self.show = show
        self.shown = False

    def on_start(self, ev) -> None:
        if self.shown:
            return
        module = getattr(getattr(ev.data.get("dispatcher"), "py_func", None), "__module__", "") or ""
        if module in RENDERING:
            self.shown = True
            self.show(NOTICE)

    def on_end(self, ev) -> None:
        """Nothing to do when a compile ends."""


@contextmanager
def compile_notice(show: Callable[[str], None]) -> Iterator[None]:
    """Within the block, ``show(NOTICE)`` once when a rendering kernel starts compiling (not when it loads from
    the cache)."""
    with event.install_listener("numba:compile", _FirstCompile(show)):
        yield
