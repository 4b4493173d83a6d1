"""Work whose size a user sets: estimated before it starts, refused above a stated limit.

Every command whose running time or memory grows with a number the user chooses (a count of
designs, a simulated duration, a plant step, a region, the joints of a device file, worker
processes) asks this module first. Above a limit the work is refused with one line that states
the estimate and the limit; inside :func:`allow_large` (the command line's ``--force``) the
soft limits are lifted, but never the hard ones, which are what this machine cannot hold.

Soft limits (lifted by :func:`allow_large`), with how each estimate is computed; the times are
what this toolkit measured on a shared 2-core machine, rounded up:

- :data:`MEMORY_LIMIT` = 2 GiB for one array build: the sampled-data loop allocates
  ``8 (2 s + 1)(1 + 3 N) + 8 (s / r + 1) 6 N + 24 (d + 1) N`` bytes for ``s`` plant steps,
  ``N`` joints, a record every ``r`` steps and a delay of ``d`` samples; the exact basis of the
  equations of motion ``8 P p (3 N M + N^2 + 3 M + 3 N)`` bytes for ``P`` grid poses (the product
  of ``2 d + 1`` per revolute, ``d + 1`` per prismatic and 1 per cyclic coordinate at degree
  ``d``), ``p = 10`` parameters per body and ``M = N (N + 1) / 2`` (the Phantom 6-DOF, one cyclic
  and five revolute joints, about 1 GiB; 6 general revolute joints at degree 2 about 3.5 GiB, 7
  about 30 GiB).
- :data:`PLANT_STEPS_LIMIT` = 5e8 plant integration steps per command (duration / step x the
  number of simulations the search can run; about 10 minutes at 1e6 steps/s). The defaults of
  ``impedance-range`` take about 1e6, ``transparency`` 1e5; ``stability-boundary`` counts
  ``(42 + log2(1 / tol))`` runs of samples x substeps; a campaign checks each case on its own.
- :data:`DESIGN_LIMITS`: 100 000 designs of the fast design-set method (about 6 ms each),
  1 000 of differential evolution (about 2.5 s each), 50 000 fully linear designs (about 20 ms
  each).
- :data:`QUADRATURE_POINTS_LIMIT` = 1e6 quadrature points per joint range of an LN region
  (24 points per pi radians: a range of about 130 000 rad).
- :data:`EIGEN_ORDER_LIMIT` = 600: the order ``3 + 3 d`` of the closed-loop matrix of the exact
  stability boundary with a delay of ``d`` samples (about 100 eigenvalue problems each).
- :data:`DEVICE_LIMITS`: 32 joints, 1 000 frames and 16 closed loops per device, checked when a
  device file or a URDF is read, before anything is built (every command meets a
  device there; a device at these limits loads and shows in well under a minute, while the work
  on it grows with their squares and cubes).
- Worker processes: the machine's cores (``os.cpu_count()``).

Hard limits (never lifted): 80 % of the machine's physical memory for one array build, and
estimates that are not finite numbers.

Commands without a ``--force`` flag (e.g. ``dynamics`` on a large device file) honour the
environment variable ``HAPTICDESIGN_FORCE=1`` instead.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from hapticdesign.errors import UserError

MEMORY_LIMIT = 2 * 2**30
PLANT_STEPS_LIMIT = 5e8
DESIGN_LIMITS = {"fast": 100_000, "de": 1_000, "linear": 50_000}
QUADRATURE_POINTS_LIMIT = 1e6
EIGEN_ORDER_LIMIT = 600
DEVICE_LIMITS = {"joints": 32, "frames": 1000, "loops": 16}

_ALLOWED: ContextVar[bool] = ContextVar("hapticdesign_allow_large", default=False)


class WorkloadTooLarge(UserError):
    """The work asked for is estimated above a limit of this module."""


@contextmanager
def allow_large(enabled: bool = True, hint: str | None = None) -> Iterator[None]:
    """Lift the soft limits inside the block when ``enabled``; ``hint`` is appended to a refusal
    (the command line names its flag there, e.g. "add --force to run it anyway")."""
    token = _ALLOWED.set(enabled)
    try:
        yield
    except WorkloadTooLarge as exc:
        if hint and not enabled:
            raise WorkloadTooLarge(f"{exc}; {hint}") from None
        raise
    finally:
        _ALLOWED.reset(token)


def large_allowed() -> bool:
    """True inside :func:`allow_large` or with ``HAPTICDESIGN_FORCE=1`` (soft limits lifted)."""
    return _ALLOWED.get() or os.environ.get("HAPTICDESIGN_FORCE", "") == "1"


def require_within(what: str, amount: float, limit: float, unit: str) -> None:
    """Refuse ``amount`` (of ``unit``) for ``what`` above ``limit`` unless large work is allowed.

    A non-finite estimate is always refused: the work cannot be done at all.
    """
    if not math.isfinite(amount):
        raise UserError(f"{what} is not a finite amount of work (the inputs overflow)")
    if amount > limit and not large_allowed():
        raise WorkloadTooLarge(f"{what} would take {_amount(amount)} {unit}, above the limit of "
                               f"{_amount(limit)} {unit}")


def require_device_size(what: str, joints: int, frames: int, loops: int) -> None:
    """Refuse a device with more joints, frames or closed loops than :data:`DEVICE_LIMITS`, before it is built."""
    for name, count in (("joints", joints), ("frames", frames), ("loops", loops)):
        limit = DEVICE_LIMITS[name]
        if count > limit and not large_allowed():
            raise WorkloadTooLarge(f"{what} has {count:,} {name}, above the limit of {limit:,} {name}")


def physical_memory() -> int:
    """Bytes of physical memory (a large number when the system does not say)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 2**50


def require_memory(what: str, nbytes: float) -> None:
    """Refuse an array build above :data:`MEMORY_LIMIT` (soft) or the physical memory (hard)."""
    if not math.isfinite(nbytes):
        raise UserError(f"{what} is not a finite amount of memory (the inputs overflow)")
    available = physical_memory()
    if nbytes > 0.8 * available:
        raise UserError(f"{what} would need {_bytes(nbytes)} of memory; this machine has {_bytes(available)}")
    if nbytes > MEMORY_LIMIT and not large_allowed():
        raise WorkloadTooLarge(f"{what} would need {_bytes(nbytes)} of memory, above the limit of {_bytes(MEMORY_LIMIT)}")


def require_designs(what: str, count: float, method: str) -> None:
    """Refuse more than :data:`DESIGN_LIMITS` ``[method]`` designs."""
    require_within(what, count, DESIGN_LIMITS[method], "designs")


def require_plant_steps(what: str, steps: float) -> None:
    """Refuse more than :data:`PLANT_STEPS_LIMIT` plant integration steps."""
    require_within(what, steps, PLANT_STEPS_LIMIT, "plant steps")


def loop_bytes(n_steps: float, n_dof: int, stride: int = 1, delay: int = 0) -> float:
    """Bytes the sampled-data loop allocates for one run (paths, records, delay buffer)."""
    paths = 8.0 * (2 * n_steps + 1) * (1 + 3 * n_dof)
    records = 8.0 * (n_steps / max(stride, 1) + 1) * 6 * n_dof
    return paths + records + 24.0 * (delay + 1) * n_dof


def basis_bytes(grid_points: int, n_dof: int, n_params: int) -> float:
    """Bytes of the tables built for the exact basis of the equations of motion (see the module)."""
    m = n_dof * (n_dof + 1) // 2
    per_point = 3 * n_dof * m + n_dof * n_dof + 3 * m + 3 * n_dof
    return 8.0 * grid_points * n_params * per_point


def worker_count(requested: int | None) -> int:
    """Worker processes: ``requested`` (default every core), refused above the cores unless allowed."""
    cores = os.cpu_count() or 1
    if requested is None:
        return cores
    if requested < 1:
        raise UserError(f"the number of workers must be at least 1, got {requested}")
    if requested > cores and not large_allowed():
        raise WorkloadTooLarge(f"{requested} worker processes asked for, but this machine has {cores} cores")
    return requested


def _amount(value: float) -> str:
    return f"{value:,.0f}" if value < 1e7 else f"{value:.3g}"


def _bytes(value: float) -> str:
    for unit, size in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if value >= size:
            return f"{value / size:.3g} {unit}"
    return f"{value:.0f} bytes"


__all__ = ["DESIGN_LIMITS", "DEVICE_LIMITS", "EIGEN_ORDER_LIMIT", "MEMORY_LIMIT", "PLANT_STEPS_LIMIT", "QUADRATURE_POINTS_LIMIT",
           "WorkloadTooLarge", "allow_large", "basis_bytes", "large_allowed", "loop_bytes", "physical_memory",
           "require_designs", "require_device_size", "require_memory", "require_plant_steps", "require_within", "worker_count"]
