"""The compensator's model of a device: the device whose inertial parameters carry a modelling error.

The seed's Simscape compensator is a second copy of the device whose "error %" scales masses, mass centres and
inertias alike (seed 000 §4.1.1.2); :func:`model_device` builds it, with optional per-group errors.
:func:`scaled_standard` is the same uniform error on standard parameters, for many designs at once: scaling the
mass ``m``, the mass centre ``r`` and the inertia about it ``I_c`` by ``f`` gives ``m' = f m``, ``h' = m' r' = f^2 h``
and, about the frame origin, ``J' = f I_c + f^3 m S(r) = f J + (f^3 - f) S(h) / m`` with ``S(h) = h.h 1 - h h^T``
(the parallel-axis term), so the compensator's ``H`` and ``G`` are not ``f`` times the device's.
"""

from __future__ import annotations

import math

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.model.inertia import SEED_FIELDS

ERROR_GROUPS = {"mass": ("m",), "centre": ("rx", "ry", "rz"), "inertia": ("Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")}


def _check_percent(value: float, what: str) -> None:
    if not (math.isfinite(value) and -100 < value < 100):
        raise UserError(f"{what} must be a finite number between -100 and 100 (exclusive), got {value}")


def model_device(device: Device, error_percent: float, group_errors: tuple[tuple[str, float], ...] = (),
                 error_seed: int | None = None) -> Device:
    """The compensator's device: every inertial parameter times ``1 - error_percent / 100``, then each
    group of :data:`ERROR_GROUPS` times ``1 + s E_group / 100`` (``s = -1``, or a seeded random sign)."""
    _check_percent(error_percent, "error percentage")
    groups = dict(group_errors)
    for name, value in groups.items():
        if name not in ERROR_GROUPS:
            raise UserError(f"unknown error group {name!r}; groups: {', '.join(ERROR_GROUPS)}")
        _check_percent(value, f"the {name} error")
    if error_percent == 0 and not any(groups.values()):
        return device
    factor = 1.0 - error_percent / 100.0
    names = device.inertial_names()
    fields = [f for _ in device.body_names for f in SEED_FIELDS]
    rng = np.random.default_rng(error_seed) if error_seed is not None else None
    signs = rng.choice([-1.0, 1.0], size=len(names)) if rng is not None else -np.ones(len(names))
    values = {}
    for name, kind, sign in zip(names, fields, signs):
        group = next((g for g, members in ERROR_GROUPS.items() if kind in members), None)
        scale = factor * (1.0 + sign * groups.get(group, 0.0) / 100.0)
        values[name] = device.params.get(name, 0.0) * scale
    return device.with_params(values)


def scaled_standard(standard: np.ndarray, factor: float) -> np.ndarray:
    """The standard parameters ``(..., 10 B)`` of bodies whose mass, mass centre and inertia about it are each
    ``factor`` times these bodies' (the uniform error of :func:`model_device`; see the module docstring)."""
    bodies = np.asarray(standard, dtype=float).reshape(*np.shape(standard)[:-1], -1, 10)
    m, h = bodies[..., 0], bodies[..., 1:4]
    hh = np.einsum("...i,...i->...", h, h)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_m = np.where(m > 0, 1.0 / np.where(m > 0, m, 1.0), 0.0)
    shift = np.stack([hh - h[..., 0] ** 2, hh - h[..., 1] ** 2, hh - h[..., 2] ** 2,
                      -h[..., 0] * h[..., 1], -h[..., 0] * h[..., 2], -h[..., 1] * h[..., 2]], axis=-1)
    out = np.empty_like(bodies)
    out[..., 0] = factor * m
    out[..., 1:4] = factor ** 2 * h
    out[..., 4:] = factor * bodies[..., 4:] + (factor ** 3 - factor) * shift * inv_m[..., None]
    return out.reshape(np.shape(standard))
