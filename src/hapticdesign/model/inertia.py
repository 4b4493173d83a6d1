"""Inertial parameters of a rigid body and their physical consistency.

Seed convention (seed 000, Table 2.3): mass ``m``; mass-centre vector ``r`` resolved in the
body's frame; inertia tensor about the mass centre, in the body's frame, written with the
*products of inertia* ``Ixy, Ixz, Iyz`` entering with a minus sign::

    I_c = [[Ixx, -Ixy, -Ixz], [-Ixy, Iyy, -Iyz], [-Ixz, -Iyz, Izz]]

The dynamics are linear in the ten *standard* inertial parameters of each body,
``pi = (m, hx, hy, hz, Jxx, Jyy, Jzz, Jxy, Jxz, Jyz)`` with ``h = m r`` the first moment and ``J``
the entries of the inertia tensor about the body frame's origin (parallel-axis theorem,
``J = I_c + m (r.r 1 - r r^T)``). Physical consistency follows Wensing, Kim & Slotine (2017):
the pseudo-inertia ``[[tr(J)/2 1 - J, h], [h^T, m]]`` is positive semi-definite exactly when the
parameters belong to a rigid body (mass >= 0, triangle inequality on the principal moments).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from hapticdesign.errors import InputError, UserError

SEED_FIELDS = ("m", "rx", "ry", "rz", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")
STANDARD_FIELDS = ("m", "hx", "hy", "hz", "Jxx", "Jyy", "Jzz", "Jxy", "Jxz", "Jyz")


def seed_parameter_name(field: str, body: str) -> str:
    """The seed's name of one inertial parameter of a body: ``m2``, ``r2ax``, ``Ixy3a``."""
    if field == "m":
        return f"m{body}"
    if field.startswith("r"):
        return f"r{body}{field[1]}"
    return f"{field}{body}"


def tube_body(axis, D: float, d: float, density: float) -> BodyInertia:
    """A straight tube (``d = 0``: a rod) of outer and inner diameters ``D``, ``d`` (m) and ``density`` (kg/m^3) from
    the frame origin to the point ``axis`` (m, in the frame), in the seed's convention (Table 2.3): the one body of
    :func:`tube_seed`."""
    return BodyInertia(*(float(v) for v in tube_seed(axis, D, d, density)))


def tube_seed(axis, D, d, density: float) -> np.ndarray:
    """The ten seed parameters ``(..., 10)`` (:data:`SEED_FIELDS`) of tubes from the frame origin to ``axis``
    ``(..., 3)`` with diameters ``D``, ``d`` ``(...)`` (many designs' tubes at once).

    Length ``L = |axis|``, mass ``m = rho pi (D^2 - d^2) / 4 L``, mass centre at mid-link ``axis / 2``, moments about
    the mass centre ``m (D^2 + d^2) / 8`` about the axis ``u = axis / L`` and ``m (3 (D^2 + d^2) / 4 + L^2) / 12``
    about any transverse axis (a thick-walled cylinder), i.e. ``I_c = I_t 1 + (I_a - I_t) u u^T``.
    """
    axis = np.asarray(axis, dtype=float)
    D, d = np.asarray(D, dtype=float), np.asarray(d, dtype=float)
    length = np.linalg.norm(axis, axis=-1)
    u = axis / length[..., None]
    m = density * math.pi * (D**2 - d**2) / 4.0 * length
    axial = m * (D**2 + d**2) / 8.0
    transverse = m * (3.0 * (D**2 + d**2) / 4.0 + length**2) / 12.0
    tensor = (transverse[..., None, None] * np.eye(3)
              + (axial - transverse)[..., None, None] * u[..., :, None] * u[..., None, :])
    r = axis / 2.0
    return np.stack([m, r[..., 0], r[..., 1], r[..., 2], tensor[..., 0, 0], tensor[..., 1, 1], tensor[..., 2, 2],
                     -tensor[..., 0, 1], -tensor[..., 0, 2], -tensor[..., 1, 2]], axis=-1)


class Realizability(str, Enum):
    """How strictly inertial parameters are checked.

    ``positive-definite`` is the seed's condition (eq. 3.28): positive mass and a positive
    definite inertia tensor. ``rigid-body`` adds the triangle inequality, i.e. a positive
    semi-definite pseudo-inertia (Wensing et al. 2017).
    """

    POSITIVE_DEFINITE = "positive-definite"
    RIGID_BODY = "rigid-body"


@dataclass(frozen=True)
class BodyInertia:
    """Mass, mass centre and inertia about the mass centre, in the seed's convention (Table 2.3)."""

    m: float = 0.0
    rx: float = 0.0
    ry: float = 0.0
    rz: float = 0.0
    Ixx: float = 0.0
    Iyy: float = 0.0
    Izz: float = 0.0
    Ixy: float = 0.0
    Ixz: float = 0.0
    Iyz: float = 0.0

    @property
    def r(self) -> np.ndarray:
        return np.array([self.rx, self.ry, self.rz])

    @property
    def inertia_at_com(self) -> np.ndarray:
        """Inertia tensor about the mass centre (products enter with a minus sign, Table 2.3)."""
        return np.array(
            [
                [self.Ixx, -self.Ixy, -self.Ixz],
                [-self.Ixy, self.Iyy, -self.Iyz],
                [-self.Ixz, -self.Iyz, self.Izz],
            ]
        )

    def standard(self) -> np.ndarray:
        """The ten standard parameters ``(m, h, J about the frame origin)``."""
        return standard_from_seed(np.array([getattr(self, f) for f in SEED_FIELDS]))


def standard_terms(m, rx, ry, rz, ixx, iyy, izz, ixy, ixz, iyz) -> tuple:
    """The ten standard parameters of one body from its ten seed parameters.

    The one statement of the seed -> standard map (seed 000 Table 2.3, eq. 2.30, eq. 2.44).
    The seed gives the mass centre ``r`` resolved in the body's frame and the inertia tensor
    about the mass centre with the products entering with a minus sign; the standard
    parameters are the first moment ``h = m r`` and the tensor ``J`` about the frame origin
    (parallel-axis theorem ``J = I_c + m (r.r 1 - r r^T)``), whose off-diagonal entries are::

        Jxx = Ixx + m (ry^2 + rz^2)    Jxy = -Ixy - m rx ry
        Jyy = Iyy + m (rx^2 + rz^2)    Jxz = -Ixz - m rx rz
        Jzz = Izz + m (rx^2 + ry^2)    Jyz = -Iyz - m ry rz

    Only ``+``, ``-`` and ``*`` are used, so the arguments may be floats, NumPy arrays (the
    same entry of many bodies), SymPy symbols or exact polynomial-ring elements.
    """
    return (
        m, m * rx, m * ry, m * rz,
        ixx + m * (ry**2 + rz**2), iyy + m * (rx**2 + rz**2), izz + m * (rx**2 + ry**2),
        -ixy - m * rx * ry, -ixz - m * rx * rz, -iyz - m * ry * rz,
    )


def seed_terms(m, hx, hy, hz, jxx, jyy, jzz, jxy, jxz, jyz) -> tuple:
    """The inverse of :func:`standard_terms` (the mass must be non-zero): ``r = h / m``, then
    the same parallel-axis terms subtracted and the products' sign turned back."""
    rx, ry, rz = hx / m, hy / m, hz / m
    return (
        m, rx, ry, rz,
        jxx - m * (ry**2 + rz**2), jyy - m * (rx**2 + rz**2), jzz - m * (rx**2 + ry**2),
        -(jxy + m * rx * ry), -(jxz + m * rx * rz), -(jyz + m * ry * rz),
    )


def standard_from_seed(seed: np.ndarray) -> np.ndarray:
    """Map seed parameters ``(..., 10)`` to standard parameters ``(..., 10)`` (:func:`standard_terms`)."""
    seed = np.asarray(seed, dtype=float)
    return np.stack(standard_terms(*np.moveaxis(seed, -1, 0)), axis=-1)


def seed_from_standard(standard: np.ndarray) -> np.ndarray:
    """Map standard parameters ``(..., 10)`` to seed parameters ``(..., 10)`` (:func:`seed_terms`)."""
    standard = np.asarray(standard, dtype=float)
    return np.stack(seed_terms(*np.moveaxis(standard, -1, 0)), axis=-1)


def pseudo_inertia(standard: np.ndarray) -> np.ndarray:
    """4x4 pseudo-inertia matrix of standard parameters (Wensing, Kim & Slotine 2017, eq. 9)."""
    m, hx, hy, hz, jxx, jyy, jzz, jxy, jxz, jyz = np.asarray(standard, dtype=float)
    j = np.array([[jxx, jxy, jxz], [jxy, jyy, jyz], [jxz, jyz, jzz]])
    out = np.zeros((4, 4))
    out[:3, :3] = 0.5 * np.trace(j) * np.eye(3) - j
    out[:3, 3] = out[3, :3] = (hx, hy, hz)
    out[3, 3] = m
    return out


@dataclass(frozen=True)
class ConsistencyReport:
    """Outcome of :func:`check_body`: ``error`` rules the body out, ``warning`` is the seed's weaker case."""

    body: str
    error: str | None = None
    warning: str | None = None


def check_body(name: str, body: BodyInertia, rel_tol: float = 1e-12) -> ConsistencyReport:
    """Classify a body's parameters.

    Errors: NaN, negative mass, a massless body with inertia, an inertia tensor that is not
    positive definite. Warning: positive definite but breaking the triangle inequality
    (accepted by the seed's eq. 3.28, not realizable by a rigid body).

    A *point mass* (positive mass, every moment and product exactly zero) is consistent: its
    pseudo-inertia ``m [r; 1][r; 1]^T`` is positive semi-definite (rank one), the limit of a
    shrinking rigid body, and its inertia about the frame origin is ``m (r.r 1 - r r^T)``.
    """
    values = np.array([getattr(body, f) for f in SEED_FIELDS])
    if not np.all(np.isfinite(values)):
        return ConsistencyReport(name, error=f"body {name}: inertial parameters must be finite numbers")
    if body.m < 0:
        return ConsistencyReport(name, error=f"body {name}: negative mass m{name} = {body.m:g}")
    with np.errstate(over="ignore"):
        moment = body.m * float(np.dot(values[1:4], values[1:4]))
    if not math.isfinite(moment):
        return ConsistencyReport(name, error=f"body {name}: m r^2 overflows (mass and centre of mass too large "
                                            "to be a finite number)")
    inertia = body.inertia_at_com
    scale = max(np.abs(inertia).max(), 1e-300)
    if body.m == 0:
        if np.abs(inertia).max() > 0:
            return ConsistencyReport(name, error=f"body {name}: massless body with non-zero inertia")
        return ConsistencyReport(name)
    if not np.any(inertia):  # a point mass
        return ConsistencyReport(name)
    eig = np.linalg.eigvalsh(inertia)
    if eig[0] <= rel_tol * scale:
        return ConsistencyReport(
            name,
            error=f"body {name}: inertia tensor is not positive definite (smallest principal moment {eig[0]:.3g})",
        )
    a, b, c = eig
    if a + b < c * (1 - rel_tol):
        return ConsistencyReport(
            name,
            warning=(
                f"body {name}: principal moments {a:.4g}, {b:.4g}, {c:.4g} break the triangle inequality "
                "(positive definite as the seed's eq. 3.28 asks, but no rigid body has them)"
            ),
        )
    return ConsistencyReport(name)


def require_consistent(reports: list[ConsistencyReport], strict: bool) -> list[str]:
    """Raise :class:`UserError` on the first error (or warning when ``strict``); return the warnings."""
    for rep in reports:
        if rep.error:
            raise UserError(rep.error)
        if strict and rep.warning:
            raise InputError(rep.warning + "; the strict check refuses it", "strict")
    return [rep.warning for rep in reports if rep.warning]
