"""Compiling once per machine (simulation/warmup.py): the compile notice and the locked first compile."""

from __future__ import annotations

import os

import numba as nb
import numpy as np

from hapticdesign.simulation import warmup


def _toy_kernel():
    @nb.njit
    def toy(x):
        return 2.0 * x

    return toy


def test_the_notice_comes_once_per_group_and_only_when_one_of_its_kernels_compiles(monkeypatch):
    toy = _toy_kernel()
    shown = []
    with warmup.compile_notice(shown.append):
        toy(1.0)  # a kernel outside the announced groups: no notice
    assert shown == []
    monkeypatch.setattr(warmup, "GROUPS", (("the toy kernels", 2.0, (toy.py_func.__module__,)),))
    with warmup.compile_notice(shown.append):
        toy(np.zeros(2))  # a new signature: numba compiles it
        toy(np.ones(2))  # compiled already: nothing to say
        toy(3)  # another compile in the same run: one line is enough
    assert shown == ["compiling the toy kernels, once per machine: about 2 CPU-s (later runs load them from numba's "
                     "cache)"]
    with warmup.compile_notice(shown.append):
        toy(np.zeros(3))  # in memory: no compile, no notice
    assert len(shown) == 1


def test_a_kernel_compiled_as_the_callee_of_another_group_is_not_announced(monkeypatch):
    def callee(x):
        return x + 1.0

    callee.__module__ = "hapticdesign.toy_callees"
    callee = nb.njit(callee)

    @nb.njit
    def caller(x):
        return callee(x)

    monkeypatch.setattr(warmup, "GROUPS", (("the callees", 1.0, ("hapticdesign.toy_callees",)),))
    shown = []
    with warmup.compile_notice(shown.append):
        caller(1.0)  # compiles the callee inside the caller's compile: the caller's group (none) speaks for it
        assert shown == []
        callee(np.zeros(2))  # the callee's own first compile
    assert shown == [warmup.notice("the callees", 1.0)]


def test_ensure_compiled_compiles_the_arguments_signature_under_the_cache_folder_lock():
    from hapticdesign.simulation import kernel

    toy = _toy_kernel()
    warmup.ensure_compiled(toy, np.zeros(4))
    assert [tuple(str(t) for t in sig) for sig in toy.signatures] == [("array(float64, 1d, C)",)]
    warmup.ensure_compiled(toy, np.zeros(5))  # same types: nothing more
    assert len(toy.signatures) == 1
    folder = warmup.cache_folder(kernel.run_loop)
    assert folder is not None and os.path.isdir(os.path.dirname(folder) or ".")
    with warmup.compile_lock(kernel.run_loop):
        assert os.path.exists(os.path.join(folder, warmup.LOCK_FILE))
