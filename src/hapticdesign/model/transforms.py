"""Elementary transforms: the single kinematic vocabulary of every device.

A chain is a sequence of elementary transforms, each a rotation or a translation about the
local x, y or z axis (seed 000 eq. 2.4-2.7 build the DH link transform from four of them).
The value of a transform is either a constant or an affine function of the independent
joint coordinates, ``value = offset + sum_k coefficient_k * q_k``. Dependent coordinates
(the parallelogram links of the Phantom, the ``theta5 - pi/2`` of Table 2.5, the passive
joints of the R-CUBE) are expressed with that affine form.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np


class Axis(IntEnum):
    """Kind of an elementary transform; the integer codes are used by the compiled kernels."""

    RX = 0
    RY = 1
    RZ = 2
    TX = 3
    TY = 4
    TZ = 5

    @property
    def is_rotation(self) -> bool:
        return self <= Axis.RZ

    @property
    def unit(self) -> int:
        """Index 0, 1, 2 of the local axis the transform acts along."""
        return int(self) % 3


@dataclass(frozen=True)
class JointValue:
    """Affine function ``offset + sum_k coefficients[k] * q[k]`` of the independent coordinates."""

    coefficients: tuple[tuple[int, float], ...] = ()
    offset: float = 0.0

    @property
    def is_constant(self) -> bool:
        return not any(c != 0.0 for _, c in self.coefficients)

    def dense(self, n_dof: int) -> np.ndarray:
        row = np.zeros(n_dof)
        for k, c in self.coefficients:
            row[k] += c
        return row


def const(value: float) -> JointValue:
    """A constant transform value."""
    return JointValue((), float(value))


def joint(index: int, scale: float = 1.0, offset: float = 0.0) -> JointValue:
    """``offset + scale * q[index]``: an actuated coordinate or a simple coupling."""
    return JointValue(((int(index), float(scale)),), float(offset))


def combination(terms: dict[int, float], offset: float = 0.0) -> JointValue:
    """A dependent coordinate ``offset + sum_k terms[k] * q[k]``."""
    return JointValue(tuple((int(k), float(v)) for k, v in sorted(terms.items())), float(offset))


@dataclass(frozen=True)
class ElementaryTransform:
    """One rotation or translation about a local axis."""

    axis: Axis
    value: JointValue = field(default_factory=JointValue)

    def matrix(self, q: np.ndarray) -> np.ndarray:
        """Homogeneous 4x4 matrix of the transform at coordinates ``q``."""
        v = self.value.offset + sum(c * q[k] for k, c in self.value.coefficients)
        return elementary_matrix(self.axis, v)


def elementary_matrix(axis: Axis, v: float) -> np.ndarray:
    t = np.eye(4)
    i = axis.unit
    if axis.is_rotation:
        j, k = (i + 1) % 3, (i + 2) % 3
        c, s = np.cos(v), np.sin(v)
        t[j, j], t[j, k], t[k, j], t[k, k] = c, -s, s, c
    else:
        t[i, 3] = v
    return t


def Rx(v: JointValue | float) -> ElementaryTransform:
    return ElementaryTransform(Axis.RX, v if isinstance(v, JointValue) else const(v))


def Ry(v: JointValue | float) -> ElementaryTransform:
    return ElementaryTransform(Axis.RY, v if isinstance(v, JointValue) else const(v))


def Rz(v: JointValue | float) -> ElementaryTransform:
    return ElementaryTransform(Axis.RZ, v if isinstance(v, JointValue) else const(v))


def tx(v: JointValue | float) -> ElementaryTransform:
    return ElementaryTransform(Axis.TX, v if isinstance(v, JointValue) else const(v))


def ty(v: JointValue | float) -> ElementaryTransform:
    return ElementaryTransform(Axis.TY, v if isinstance(v, JointValue) else const(v))


def tz(v: JointValue | float) -> ElementaryTransform:
    return ElementaryTransform(Axis.TZ, v if isinstance(v, JointValue) else const(v))
