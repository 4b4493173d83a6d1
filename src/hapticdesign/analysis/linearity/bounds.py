"""Practical bounds on the inertial parameters (seed 000 eq. 3.29-3.32, 3.35-3.38).

Bounds are per body, in the seed's variables: mass, mass-centre coordinates, the diagonal
moments of inertia about the mass centre and the products of inertia. Bodies without bounds
(link 1 of the Phantom, which does not enter LN) keep the device's values.

A :class:`SeedBox` is the general form: a lower and an upper value for each of a body's ten seed
variables (equal values fix a variable); a study file's variables give one (docs/optimization.md),
and :class:`BodyBounds` is the seed's special case (:meth:`BodyBounds.box`).

Reading of "10^-5 <= I_i <= 10^-2 for all elements" (eq. 3.32, 3.38): the lower bound applies to
the moments; the products are bounded in magnitude by the upper value (the seed's own example
design, eq. 3.33, and all its Appendix C designs have zero products, which a positive lower bound
on the products would forbid).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.device import Device


@dataclass(frozen=True)
class BodyBounds:
    mass: tuple[float, float]
    centre: tuple[float, float]
    moments: tuple[float, float]
    products: float

    def __post_init__(self) -> None:
        for name, (lo, hi) in (("mass", self.mass), ("centre", self.centre), ("moments", self.moments)):
            if not lo <= hi:
                raise UserError(f"bounds: {name} lower bound {lo:g} exceeds upper bound {hi:g}")
        if self.mass[1] <= 0:
            raise UserError("bounds: the mass upper bound must be positive")
        if self.products < 0:
            raise UserError("bounds: the product-of-inertia bound must be non-negative")

    def box(self) -> "SeedBox":
        """The same bounds per seed variable (products ``-products ... products``)."""
        return SeedBox(
            np.array([self.mass[0], *[self.centre[0]] * 3, *[self.moments[0]] * 3, *[-self.products] * 3]),
            np.array([self.mass[1], *[self.centre[1]] * 3, *[self.moments[1]] * 3, *[self.products] * 3]),
        )


@dataclass(frozen=True)
class SeedBox:
    """Lower and upper values of one body's ten seed variables (``SEED_FIELDS`` order: m, r, moments
    about the mass centre, products); ``low == high`` fixes a variable."""

    low: np.ndarray
    high: np.ndarray

    def __post_init__(self) -> None:
        low, high = (np.asarray(v, dtype=float) for v in (self.low, self.high))
        if low.shape != (10,) or high.shape != (10,) or not np.all(np.isfinite(low) & np.isfinite(high)):
            raise UserError("bounds: a body's box has ten finite lower and upper values")
        if np.any(low > high):
            raise UserError(f"bounds: a lower bound exceeds its upper bound ({low[low > high][0]:g})")
        if high[0] <= 0:
            raise UserError("bounds: the mass upper bound must be positive")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)

    @property
    def fixed(self) -> np.ndarray:
        """Which variables the box fixes (10,)."""
        return self.low == self.high


Bounds = BodyBounds | SeedBox
"""A body's bounds, either form."""


def as_box(bounds: Bounds) -> SeedBox:
    """Either form of a body's bounds as a :class:`SeedBox`."""
    return bounds if isinstance(bounds, SeedBox) else bounds.box()


GENERIC = BodyBounds((0.01, 1.0), (-0.5, 0.5), (1e-6, 1e-1), 1e-1)
"""Every body with mass of a device whose source gives no practical bounds."""


def practical_bounds(device: Device) -> dict[str, BodyBounds]:
    """The device's own practical bounds (:attr:`~hapticdesign.model.device.Device.preset_data`; eq. 3.29-3.32 for
    the Phantom presets); for other devices every body with mass gets generic bounds."""
    if device.preset_data.bounds:
        return {body: BodyBounds(*row) for body, row in device.preset_data.bounds.items()}
    return {b: GENERIC for b in device.body_names if device.body(b).m > 0}


def within_bounds(seed: np.ndarray, bodies: tuple[str, ...], bounds: dict[str, Bounds], rel_tol: float = 1e-9) -> bool:
    """Whether seed-variable parameters (bodies, 10) meet the bounds (relative slack ``rel_tol`` of the
    larger magnitude of each variable's two bounds)."""
    for k, body in enumerate(bodies):
        if body not in bounds:
            continue
        box = as_box(bounds[body])
        tol = rel_tol * np.maximum(np.abs(box.low), np.abs(box.high))
        if np.any(seed[k] < box.low - tol) or np.any(seed[k] > box.high + tol):
            return False
    return True


def clip_to_bounds(seed: np.ndarray, bodies: tuple[str, ...], bounds: dict[str, Bounds]) -> np.ndarray:
    """Seed-variable parameters (bodies, 10) with every bounded value clipped into its box."""
    out = np.array(seed, dtype=float)
    for k, body in enumerate(bodies):
        if body in bounds:
            box = as_box(bounds[body])
            out[k] = np.clip(out[k], box.low, box.high)
    return out
