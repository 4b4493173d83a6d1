"""The region R of the Linearity Number (seed 000 eq. 3.1-3.4) and its exact moments.

LN averages over a region of joint space. The seed's region is the full torus
``0 <= theta_i <= 2 pi`` (eq. 3.4); the seed also notes that R may be restricted to a task
region, which we support as a box of joint ranges. Because the joint coordinates are
independent and uniform on R, every average of a product of basis functions factorizes into
one-dimensional moments: the mean ``w_k = E[phi_i(q_k)]`` and the covariance
``C_k = Cov[phi_i(q_k), phi_j(q_k)]`` of each coordinate's basis. On the torus they are exact
closed forms (orthogonal Fourier basis); on a box they come from Gauss-Legendre quadrature,
converged to machine precision.

A device's joint limits (device files' ``joints[].limits``, URDF ``<limit>``) define its default
region: the box of its limits, with full turns only where no limit is given (:func:`limits_region`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from hapticdesign.analysis.dynamics.basis import CoordinateBasis, CoordinateKind
from hapticdesign.errors import InputError, UserError
from hapticdesign.workload import QUADRATURE_POINTS_LIMIT, require_within

PANEL_POINTS = 24
PANEL_LENGTH = math.pi


@dataclass(frozen=True)
class Region:
    """Joint ranges ``{coordinate index: (low, high)}``; coordinates not listed span the torus."""

    ranges: dict[int, tuple[float, float]] = field(default_factory=dict)

    @property
    def is_torus(self) -> bool:
        return not self.ranges

    def describe(self, names: tuple[str, ...]) -> str:
        if self.is_torus:
            return "torus [0, 2 pi]^N (eq. 3.4)"
        return ", ".join(f"{names[k]} in [{lo:g}, {hi:g}]" for k, (lo, hi) in sorted(self.ranges.items()))

    def moments(self, k: int, basis: CoordinateBasis) -> tuple[np.ndarray, np.ndarray]:
        """Mean vector ``w`` and covariance matrix ``C`` of coordinate ``k``'s basis functions on R."""
        if k in self.ranges:
            lo, hi = self.ranges[k]
            return _box_moments(basis, lo, hi)
        if basis.kind is CoordinateKind.PRISMATIC:
            raise InputError(
                f"coordinate {k + 1} is prismatic: give its range in the region (the torus needs revolute joints)", "region"
            )
        w = np.zeros(basis.size)
        w[0] = 1.0
        cov = basis.mean_gram()
        cov[0, 0] = 0.0
        return w, cov


def quadrature_points(lo: float, hi: float) -> int:
    """Quadrature points of the uniform average over [lo, hi] (see :func:`_box_moments`)."""
    return max(1, math.ceil((hi - lo) / PANEL_LENGTH)) * PANEL_POINTS


def _box_moments(basis: CoordinateBasis, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    """Uniform average over [lo, hi] by composite Gauss-Legendre quadrature.

    Panels of at most pi radians with 24 nodes each integrate products of harmonics up to
    order 4 to machine precision; values are centred before their products are formed, so
    small variances keep their relative accuracy.
    """
    if not (math.isfinite(lo) and math.isfinite(hi) and math.isfinite(hi - lo) and lo < hi):
        raise UserError(f"a joint range must be finite with low < high, got [{lo}, {hi}]")
    require_within(f"averaging over [{lo:g}, {hi:g}]", quadrature_points(lo, hi), QUADRATURE_POINTS_LIMIT,
                   "quadrature points")
    x, wx = np.polynomial.legendre.leggauss(PANEL_POINTS)
    panels = quadrature_points(lo, hi) // PANEL_POINTS
    edges = np.linspace(lo, hi, panels + 1)
    half = 0.5 * np.diff(edges)
    q = (half[:, None] * x + (0.5 * (edges[1:] + edges[:-1]))[:, None]).ravel()
    wq = np.tile(wx, panels) * np.repeat(half, PANEL_POINTS) / (hi - lo)
    values = basis.values(q)
    mean = wq @ values
    centred = values - mean
    cov = centred.T @ (wq[:, None] * centred)
    return mean, cov


_RANGE = re.compile(r"^\s*(?:q|theta)?(\d+)\s*=\s*([^:]+):(.+)$")


def parse_region(text: str | None, n_dof: int) -> Region:
    """Parse ``"q2=-0.5:0.5,q3=0:1"`` (radians; ``theta2=...`` or ``2=...`` also accepted).

    Ranges must be finite with ``low < high``.
    """
    if text is None or not text.strip() or text.strip().lower() == "torus":
        return Region()
    ranges: dict[int, tuple[float, float]] = {}
    for part in text.split(","):
        match = _RANGE.match(part)
        if not match:
            raise InputError(f"region: cannot read {part.strip()!r}; expected e.g. q2=-0.5:0.5", "region")
        index = int(match.group(1)) - 1
        if not 0 <= index < n_dof:
            raise InputError(f"region: coordinate {index + 1} does not exist (the device has {n_dof})", "region")
        try:
            lo, hi = float(match.group(2)), float(match.group(3))
        except ValueError:
            raise InputError(f"region: bounds of {part.strip()!r} are not numbers", "region") from None
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise InputError(f"region: bounds of {part.strip()!r} must be finite", "region")
        if not lo < hi:
            raise InputError(f"region: range {part.strip()!r} is empty or inverted (need low < high)", "region")
        if not math.isfinite(hi - lo):
            raise InputError(f"region: range {part.strip()!r} is too wide to average over (its width overflows)", "region")
        require_within(f"averaging over {part.strip()!r}", quadrature_points(lo, hi), QUADRATURE_POINTS_LIMIT,
                       "quadrature points")
        if index in ranges:
            raise InputError(f"region: coordinate {index + 1} is given twice", "region")
        ranges[index] = (lo, hi)
    return Region(ranges)


def limits_region(limits) -> Region:
    """The box of a device's joint limits (``device.joint_limits()``); coordinates without limits span the torus."""
    return Region({k: (float(span[0]), float(span[1])) for k, span in enumerate(limits) if span is not None})


def resolve_region(text: str | None, limits) -> Region:
    """The region of ``--region`` for a device with joint ``limits`` (one entry per coordinate, or None).

    No text: the limits' box (:func:`limits_region`). ``torus``: the seed's full torus (eq. 3.4),
    limits ignored. Ranges such as ``q2=-0.5:0.5``: those coordinates as given, the others keep
    their limits.
    """
    n_dof = len(limits)
    if text is None or not text.strip():
        return limits_region(limits)
    given = parse_region(text, n_dof)
    if given.is_torus:
        return given
    return Region({**limits_region(limits).ranges, **given.ranges})
