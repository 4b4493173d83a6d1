"""Practical and coarse bounds on the inertial parameters (seed 000 eq. 3.29-3.32, 3.35-3.38, 3.40-3.42).

Bounds are per body, in the seed's variables: mass, mass-centre coordinates, the diagonal
moments of inertia about the mass centre and the products of inertia. Bodies without bounds
(link 1 of the Phantom, which does not enter LN) keep the device's values.

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


def _phantom_arm(heavy: tuple[float, float], light: tuple[float, float]) -> dict[str, BodyBounds]:
    r, moments = (-0.25, 0.25), (1e-5, 1e-2)
    return {
        "2": BodyBounds(heavy, r, moments, 1e-2),
        "3a": BodyBounds(heavy, r, moments, 1e-2),
        "2a": BodyBounds(light, r, moments, 1e-2),
        "3": BodyBounds(light, r, moments, 1e-2),
    }


# Eq. 3.29-3.32 (= eq. 3.35-3.38): link 2 and 3a heavy, link 2a and 3 light.
PHANTOM_PRACTICAL = _phantom_arm((0.15, 0.30), (0.02, 0.15))
# Our practical bounds for the gimbal links (not in the seed): 5-50 g, moments 1e-7..1e-3 kg m^2.
GIMBAL_PRACTICAL = {b: BodyBounds((0.005, 0.05), (-0.25, 0.25), (1e-7, 1e-3), 1e-3) for b in ("4", "5", "6")}
# Eq. 3.40-3.42, every link.
COARSE = BodyBounds((1e-15, 1e15), (-1e15, 1e15), (1e-15, 1e15), 1e15)

PRACTICAL: dict[str, dict[str, BodyBounds]] = {
    "phantom-3dof": PHANTOM_PRACTICAL,
    "phantom-6dof": {**PHANTOM_PRACTICAL, **GIMBAL_PRACTICAL},
}
GENERIC = BodyBounds((0.01, 1.0), (-0.5, 0.5), (1e-6, 1e-1), 1e-1)


def practical_bounds(device: Device) -> dict[str, BodyBounds]:
    """Eq. 3.29-3.32 for the Phantom; for other devices every body with mass gets generic bounds."""
    if device.name in PRACTICAL:
        return PRACTICAL[device.name]
    return {b: GENERIC for b in device.body_names if device.body(b).m > 0}


def coarse_bounds(device: Device) -> dict[str, BodyBounds]:
    """Eq. 3.40-3.42 on every body."""
    return {b: COARSE for b in device.body_names}


def within_bounds(seed: np.ndarray, bodies: tuple[str, ...], bounds: dict[str, BodyBounds], rel_tol: float = 1e-9) -> bool:
    """Whether seed-variable parameters (bodies, 10) meet the bounds (relative slack ``rel_tol``)."""
    for k, body in enumerate(bodies):
        if body not in bounds:
            continue
        b = bounds[body]
        m, r, moments, products = seed[k, 0], seed[k, 1:4], seed[k, 4:7], seed[k, 7:10]
        tol_m, tol_r, tol_i = (rel_tol * max(abs(v) for v in pair) for pair in (b.mass, b.centre, b.moments))
        if not (b.mass[0] - tol_m <= m <= b.mass[1] + tol_m):
            return False
        if np.any(r < b.centre[0] - tol_r) or np.any(r > b.centre[1] + tol_r):
            return False
        if np.any(moments < b.moments[0] - tol_i) or np.any(moments > b.moments[1] + tol_i):
            return False
        if np.any(np.abs(products) > b.products * (1 + rel_tol)):
            return False
    return True


def clip_to_bounds(seed: np.ndarray, bodies: tuple[str, ...], bounds: dict[str, BodyBounds]) -> np.ndarray:
    """Seed-variable parameters (bodies, 10) with every bounded value clipped into its box."""
    out = np.array(seed, dtype=float)
    for k, body in enumerate(bodies):
        if body not in bounds:
            continue
        b = bounds[body]
        out[k, 0] = np.clip(out[k, 0], *b.mass)
        out[k, 1:4] = np.clip(out[k, 1:4], *b.centre)
        out[k, 4:7] = np.clip(out[k, 4:7], *b.moments)
        out[k, 7:10] = np.clip(out[k, 7:10], -b.products, b.products)
    return out
