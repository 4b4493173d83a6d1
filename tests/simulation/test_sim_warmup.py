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


class Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_the_notice_names_the_area_once_then_says_every_half_minute_that_compiling_goes_on(monkeypatch):
    toy = _toy_kernel()
    shown = []
    with warmup.compile_notice(shown.append):
        toy(1.0)  # a kernel outside the toolkit (a user's): no notice
    assert shown == []
    monkeypatch.setattr(warmup, "AREAS", (*warmup.AREAS, (toy.py_func.__module__, "toy", 120.0)))
    clock = Clock()
    with warmup.compile_notice(shown.append, clock):
        toy(np.zeros(2))  # a new signature: numba compiles it
        toy(np.ones(2))  # compiled already: nothing to say
        clock.now = 10.0
        toy(3)  # another compile 10 s later: the first line is enough
        assert shown == [warmup.notice("toy", 120.0)]
        clock.now = 40.0
        toy(np.zeros((2, 2)))  # 40 s in: still compiling, with the time left of the typical 2 min
        clock.now = 50.0
        toy(np.zeros((2, 2, 2)))  # 10 s after the last line: quiet
        clock.now = 200.0
        toy(True)  # past the typical time
    assert shown[1:] == ["still compiling the toy kernels: 3 so far in 40 s; about 80 s left...",
                         "still compiling the toy kernels: 5 so far in 3.3 min; longer than the usual 2.0 min (a busy "
                         "machine)..."]
    assert shown[0].startswith("compiling the toy kernels (once per machine") and "about 2.0 min" in shown[0]
    with warmup.compile_notice(shown.append):
        toy(np.zeros(3))  # in memory: no compile, no notice
    assert len(shown) == 3


def test_each_kernel_module_of_the_toolkit_has_its_area():
    assert warmup.area_of("hapticdesign.model.walk")[0] == "kinematics"
    assert warmup.area_of("hapticdesign.analysis.loops.closure_kernel")[0] == "kinematics"
    assert warmup.area_of("hapticdesign.analysis.dynamics.kernel")[0] == "dynamics"
    assert warmup.area_of("hapticdesign.analysis.dynamics.closed_loop_plant")[0] == "rendering"
    assert warmup.area_of("hapticdesign.simulation.kernel")[0] == "rendering"
    assert warmup.area_of("hapticdesign.analysis.design_batch")[0] == "design-index"
    assert warmup.area_of("hapticdesignx.model") is None and warmup.area_of("numpy.linalg") is None


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


KERNEL_SOURCE = '''
import numba as nb
import numpy as np

from hapticdesign.simulation.warmup import ensure_compiled


@nb.njit(cache=True)
def double(x):
    return 2.0 * x


def warm():
    ensure_compiled(double, np.zeros(3))
'''


def test_a_kernel_compiled_aside_is_loaded_here_from_the_cache_not_compiled_again(tmp_path, monkeypatch):
    import importlib
    import sys

    (tmp_path / "aside_kernel.py").write_text(KERNEL_SOURCE)
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("aside_kernel")
    try:
        assert not warmup.in_cache(module.double)
        process = warmup.compile_aside(module.double, module.warm)
        assert process is not None
        process.join()
        assert process.exitcode == 0 and warmup.in_cache(module.double)
        warmup.ensure_compiled(module.double, np.zeros(3))
        stats = module.double.stats
        assert sum(stats.cache_hits.values()) == 1 and sum(stats.cache_misses.values()) == 0
        assert module.double(np.ones(3)).tolist() == [2.0, 2.0, 2.0]
        assert warmup.compile_aside(module.double, module.warm) is None  # in the cache: no second process
    finally:
        sys.modules.pop("aside_kernel", None)
