"""The stiffest stable virtual wall at a handle: the sampled loop's exact limit along a direction, or the worst one.

A wall along a unit direction ``u`` at the handle acts on the joints as the spring ``K J_v^T u u^T J_v``; with every
actuated joint free (as under a user's hand; :attr:`~hapticdesign.analysis.sampled_loop.SampledLoop.held` names the
ones held) the n-joint plant ``H``, ``B`` (the hand of the loop's settings and gravity's gradient at the pose in it)
discretized exactly and the sampled controller form one linear map whose spectral radius reaches 1 at the limit
(:func:`hapticdesign.analysis.sampled_loop.handle_limits`). This is not the 1-DOF model of the handle along ``u``
(mass ``1 / (u^T J_v H^-1 J_v^T u)``, damping ``u^T J_v^+T B J_v^+ u``): the two agree where ``u`` is a principal
direction of both the handle's mobility and its damping, and differ elsewhere, where the other directions' motion
couples into the wall's. The worst direction is searched over the axes of the handle's range, the principal
directions of its mobility ``U^T J_v H^-1 J_v^T U`` and damping ``U^T J_v^+T B J_v^+ U`` and :data:`DIRECTIONS`
evenly spread directions (a Fibonacci sphere; a half circle for a planar device). :func:`wall_limits` takes many
points at once: the loops of all their directions are searched together, and a direction whose stable bracket lies
above another's unstable one leaves the search early.

:func:`kmax` is the ``kmax`` design index: the options of a study (:data:`KMAX_OPTIONS`) read into a
:class:`~hapticdesign.analysis.sampled_loop.SampledLoop`. Its value is the upper end of the stable springs; where
gravity pulls the handle off the wall (a model error over-compensating, an inverted pose), springs below a lower end
are unstable too (:func:`~hapticdesign.analysis.sampled_loop.handle_intervals`; ``impedance-range`` and the spec
sheet, through :func:`worst_direction`, state it), and where no spring holds the handle along a free direction the
value is 0.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from hapticdesign.analysis.dynamics import cartesian
from hapticdesign.analysis.metrics.kinematic import handle_range_basis
from hapticdesign.analysis.sampled_loop import GRASP, HANDS, Hand, SampledLoop, handle_intervals, handle_limits
from hapticdesign.errors import UserError
from hapticdesign.model.actuators import Transmission

DIRECTIONS = 60
"""Directions spread over the sphere (circle for a planar device) for the worst wall direction."""


def directions(dim: int, count: int = DIRECTIONS) -> np.ndarray:
    """Evenly spread unit vectors (Fibonacci sphere; a half circle in 2-D, a line in 1-D), symmetric use."""
    if dim == 1:
        return np.ones((1, 1))
    if dim == 2:
        t = np.pi * np.arange(count) / count
        return np.stack([np.cos(t), np.sin(t)], axis=1)
    k = np.arange(count) + 0.5
    z = 1.0 - k / count
    r = np.sqrt(1.0 - z**2)
    phi = np.pi * (3.0 - math.sqrt(5.0)) * k
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def wall_directions(mobility: np.ndarray, damping: np.ndarray) -> np.ndarray:
    """The axes, the principal directions of the mobility and of the damping, and evenly spread ones (rows; (..., C,
    k) for a stack of matrices (..., k, k))."""
    dim = mobility.shape[-1]
    stack = mobility.shape[:-2]
    principal = [np.swapaxes(np.linalg.eigh(m)[1], -1, -2) for m in (mobility, damping)]
    fixed = [np.broadcast_to(rows, (*stack, *rows.shape)) for rows in (np.eye(dim), directions(dim))]
    return np.concatenate([fixed[0], *principal, fixed[1]], axis=-2)


def handle_range(jacobian: np.ndarray, mass: np.ndarray, damping: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                                                         np.ndarray]:
    """The basis ``U`` (P, 3, k) of the directions the handle moves, its mobility ``U^T J_v H^-1 J_v^T U`` and
    damping ``U^T J_v^+T B J_v^+ U`` (P, k, k) in it."""
    basis, _, along = handle_range_basis(jacobian)
    return basis, cartesian.mobility(mass, along), cartesian.damping(jacobian, basis, damping)


CHUNK_BYTES = 1 << 24
"""The closed-loop matrices :func:`wall_limits` searches at once, at least one point's."""


def wall_limit(jacobian: np.ndarray, mass: np.ndarray, damping: np.ndarray, loop: SampledLoop | None = None,
               direction: np.ndarray | None = None, gravity: np.ndarray | None = None,
               model: tuple[np.ndarray, np.ndarray] | None = None, transmission: Transmission | None = None) -> float:
    """The exact stable wall stiffness (N/m) at one pose along ``direction`` (a unit base-frame 3-vector), or the
    smallest over :func:`wall_directions` when it is None (see the module docstring); ``gravity`` the gradient
    ``dG/dq`` (n, n) at the pose (None: 0), ``model`` the compensator's ``H_m`` and ``dG_m/dq`` there (None: the
    loop's shares, :func:`~hapticdesign.analysis.sampled_loop.handle_loops`), ``transmission`` the compliant drive
    between the motors and the handle (n, n) each (the transmissions' and the links',
    :mod:`hapticdesign.analysis.stiffness.drive`; None: rigid)."""
    along = None if direction is None else np.reshape(direction, (1, 1, 3))
    return float(wall_limits(jacobian[None], mass[None], damping, loop, along,
                             None if gravity is None else np.asarray(gravity)[None],
                             None if model is None else tuple(np.asarray(x, dtype=float)[None] for x in model),
                             transmission)[0])


def wall_limits(jacobian: np.ndarray, mass: np.ndarray, damping: np.ndarray, loop: SampledLoop | None = None,
                along: np.ndarray | None = None, gravity: np.ndarray | None = None,
                model: tuple[np.ndarray, np.ndarray] | None = None,
                transmission: Transmission | None = None) -> np.ndarray:
    """:func:`wall_limit` at P poses at once: ``jacobian`` ``J_v`` (P, 3, n), ``mass`` ``H`` (P, n, n), ``damping``
    ``B`` (n, n) or (P, n, n), ``gravity`` ``dG/dq`` (P, n, n) or None; ``along`` None (the worst of
    :func:`wall_directions`) or (P, C, 3) unit base-frame rows (the smallest over them), ``model`` the compensator's
    ``H_m`` and ``dG_m/dq`` (P, n, n) each or None (the loop's shares), ``transmission`` the motors' compliant
    transmissions ((n, n) or (P, n, n) each; None: rigid motors); (P,) in N/m, the loops searched together in chunks
    of about :data:`CHUNK_BYTES` of matrices."""
    loop = loop or SampledLoop()
    jacobian, mass = np.asarray(jacobian, dtype=float), np.asarray(mass, dtype=float)
    damping = np.broadcast_to(np.asarray(damping, dtype=float), mass.shape)
    gravity = np.zeros_like(mass) if gravity is None else np.broadcast_to(np.asarray(gravity, dtype=float), mass.shape)
    if along is None:
        basis, mobility, cartesian_damping = handle_range(jacobian, mass, damping)
        along = np.einsum("pik,pck->pci", basis, wall_directions(mobility, cartesian_damping))
    along = np.asarray(along, dtype=float)
    count, per_point = along.shape[:2]
    n = jacobian.shape[-1]
    coords = n if transmission is None else 2 * n  # the motors' own coordinates beside the links'
    order = 2 * coords * (loop.delay + 2) + n * (loop.delay + 1)
    per = max(1, CHUNK_BYTES // (8 * order * order * per_point))
    out = np.empty(count)
    for start in range(0, count, per):
        part = slice(start, start + per)
        size = len(along[part])
        rows = np.repeat(np.arange(start, start + size), per_point)
        spring = np.einsum("sk,skn->sn", along[part].reshape(-1, 3), jacobian[rows])
        out[part] = handle_limits(jacobian[part], mass[part], damping[part], spring, loop,
                                  np.repeat(np.arange(size), per_point), poses=rows - start, gravity=gravity[part],
                                  model=None if model is None else tuple(x[part] for x in model),
                                  transmission=None if transmission is None else transmission.taken(part))
    return out


def worst_direction(jacobian: np.ndarray, mass: np.ndarray, damping: np.ndarray, loop: SampledLoop | None = None,
                    gravity: np.ndarray | None = None, model: tuple[np.ndarray, np.ndarray] | None = None,
                    transmission: Transmission | None = None) -> tuple[float, np.ndarray, float]:
    """The smallest exact wall limit at one pose over :func:`wall_directions`, the direction (unit, base frame)
    that gives it (every direction searched to the end) and the largest lower end over the directions (0 unless
    gravity pulls the handle off a wall: a wall in any direction is then stable for springs between the two, and
    for none when it is the larger);
    ``gravity`` ``dG/dq`` (n, n) at the pose or None, ``model`` and ``transmission`` as :func:`wall_limit`'s."""
    loop = loop or SampledLoop()
    jacobian, mass = np.asarray(jacobian, dtype=float)[None], np.asarray(mass, dtype=float)[None]
    damping = np.broadcast_to(np.asarray(damping, dtype=float), mass.shape)
    basis, mobility, cartesian_damping = handle_range(jacobian, mass, damping)
    along = np.einsum("ik,ck->ci", basis[0], wall_directions(mobility, cartesian_damping)[0])
    count = len(along)
    lows, limits = handle_intervals(jacobian, mass, damping, along @ jacobian[0], loop,
                                    poses=np.zeros(count, dtype=np.int64),
                                    gravity=None if gravity is None else np.asarray(gravity, dtype=float)[None],
                                    model=model, transmission=transmission)
    best = int(np.argmin(limits))
    return float(limits[best]), along[best], float(lows.max())


MAX_PERIOD = 1.0
"""Longest sample period (s) of ``kmax``'s loop: a haptic loop samples far faster than 1 Hz, and the exact
discretization of a handle's mass over much longer periods overflows."""

KMAX_OPTIONS = {"period": 0.001, "delay": 1, "wall_damping": 0.0, "direction": None, "velocity": "difference",
                "compensation": "gravity", "error_percent": 0.0, "hand": None}
"""The ``kmax`` index's options and defaults: the settings of :class:`SampledLoop` under its names (``wall_damping``
the wall's damper in N s/m; the index takes ``damping``, its former name, for one release with a deprecation line),
``direction`` a base-frame vector (default: the worst direction) and ``hand`` None, a preset's name of
:data:`~hapticdesign.analysis.sampled_loop.HANDS` (``light``, ``firm``) or ``{mass, damping, stiffness}``."""


def kmax_loop(options: Mapping[str, object]) -> tuple[SampledLoop, np.ndarray | None]:
    """The loop settings and the unit direction (or None) of the ``kmax`` options; a one-line error for a bad one."""
    period, delay, damping, direction = (options[k] for k in ("period", "delay", "wall_damping", "direction"))
    if isinstance(period, bool) or not isinstance(period, (int, float)) or not 0 < period <= MAX_PERIOD:
        raise UserError(f"index kmax: the sample period is a positive number of seconds, at most {MAX_PERIOD:g} s, "
                        f"got {period!r}")
    if isinstance(delay, bool) or not isinstance(delay, int) or not 0 <= delay <= 100:
        raise UserError(f"index kmax: the delay is a whole number of samples from 0 to 100, got {delay!r}")
    if isinstance(damping, bool) or not isinstance(damping, (int, float)) or not (math.isfinite(damping)
                                                                                   and damping >= 0):
        raise UserError(f"index kmax: the wall's damping is a number >= 0 (N s/m), got {damping!r}")
    error = options["error_percent"]
    if isinstance(error, bool) or not isinstance(error, (int, float)):
        raise UserError(f"index kmax: the modelling error is a percentage, got {error!r}")
    if direction is not None:
        try:
            direction = np.asarray(direction, dtype=float)
        except (TypeError, ValueError):
            raise UserError(f"index kmax: the direction is 3 finite numbers, got {options['direction']!r}") from None
        if direction.shape != (3,) or not np.all(np.isfinite(direction)) or not np.linalg.norm(direction) > 0:
            raise UserError(f"index kmax: the direction is 3 finite numbers, not all 0, got {options['direction']!r}")
        direction = direction / np.linalg.norm(direction)
    try:
        loop = SampledLoop(float(period), delay, str(options["velocity"]), str(options["compensation"]), float(error),
                           float(damping), _hand(options["hand"]))
    except UserError as exc:
        raise UserError(f"index kmax: {exc}") from None
    return loop, direction


def _hand(value: object) -> Hand | None:
    if value is None or value is False:
        return None
    if value is True:
        return GRASP
    if isinstance(value, str):
        return Hand.named(value)
    if isinstance(value, Mapping) and set(value) <= {"mass", "damping", "stiffness"} and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value.values()):
        return Hand(**{k: float(v) for k, v in value.items()})
    raise UserError(f"the hand is none, a name ({', '.join(HANDS)}) or a mapping of mass, damping and stiffness, got "
                    f"{str(value)[:60]!r}")


def kmax(jacobian: np.ndarray, mass: np.ndarray, damping: np.ndarray,
         ranges: tuple[np.ndarray, np.ndarray, np.ndarray], options: Mapping[str, object],
         gravity: np.ndarray | None = None, model: tuple[np.ndarray, np.ndarray] | None = None,
         transmission: Transmission | None = None) -> np.ndarray:
    """The ``kmax`` index (N/m) at P poses: ``J_v`` (P, 3, n), ``H`` (P, n, n), ``B`` (n, n) or (P, n, n), the
    handle's range as :func:`handle_range` gives it (the basis ``U``, mobility and damping in it, already known to
    the caller), the options of :data:`KMAX_OPTIONS`, gravity's gradient ``dG/dq`` (P, n, n) or None and the
    compensator's ``H_m`` and ``dG_m/dq`` (P, n, n each; None: the loop's uniform shares) and the compliant drive
    between the motors and the handle (the transmissions' and the links'; None: rigid)."""
    loop, direction = kmax_loop(options)
    basis, mobility, cartesian_damping = ranges
    if direction is None:
        along = np.einsum("pik,pck->pci", basis, wall_directions(mobility, cartesian_damping))
    else:
        inside = np.linalg.norm(np.swapaxes(basis, 1, 2) @ direction, axis=1)
        if not np.all(np.abs(inside - 1.0) <= 1e-9):
            raise UserError(f"index kmax: the direction {np.round(direction, 6).tolist()} is not one the handle "
                            "moves in")
        along = np.broadcast_to(direction, (len(jacobian), 1, 3))
    return wall_limits(jacobian, mass, damping, loop, along, gravity, model, transmission)
