"""Closed forms of a straight Euler-Bernoulli cantilever's end compliance and of carrying it to a point rigidly
attached to the free end (handbook formulas; shares no code with the package).

Twists are ``(u, theta)`` (displacement, small rotation) and wrenches ``(f, m)``, both in the base frame's axes; a
compliance maps a wrench at a point to the twist of that point.
"""

from __future__ import annotations

import math

import numpy as np


def skew(v) -> np.ndarray:
    """``[v]_x``: ``skew(v) @ w = v x w``."""
    x, y, z = (float(c) for c in v)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rod_rigidities(E: float, G: float, D: float) -> tuple[float, float, float]:
    """``(E A, E I, G J)`` of a solid round rod of diameter ``D`` (``A = pi D^2 / 4``, ``I = pi D^4 / 64``,
    ``J = pi D^4 / 32``)."""
    return E * math.pi * D ** 2 / 4.0, E * math.pi * D ** 4 / 64.0, G * math.pi * D ** 4 / 32.0


def cantilever_compliance(axis, axial: float, bending: float, torsion: float) -> np.ndarray:
    """The 6 x 6 compliance of a cantilever's free end (its axis ``axis``, from the clamped end to the free end, in
    the base's axes; its length ``|axis|``), axisymmetric section: ``L / E A`` along the axis, ``L^3 / (3 E I)``
    across it, ``L / (E I)`` and ``L / (G J)`` in rotation, and the couplings ``theta = L^2 / (2 E I) e x f``,
    ``u = -L^2 / (2 E I) e x m`` (a force across the beam turns its end towards the force)."""
    axis = np.asarray(axis, dtype=float)
    length = float(np.linalg.norm(axis))
    e = axis / length
    along, across = np.outer(e, e), np.eye(3) - np.outer(e, e)
    c = np.zeros((6, 6))
    c[:3, :3] = length ** 3 / (3.0 * bending) * across + length / axial * along
    c[3:, :3] = length ** 2 / (2.0 * bending) * skew(e)
    c[:3, 3:] = c[3:, :3].T
    c[3:, 3:] = length / bending * across + length / torsion * along
    return c


def carried_compliance(compliance: np.ndarray, offset) -> np.ndarray:
    """The compliance seen at a point ``offset`` (base axes) from the point of ``compliance``, the two rigidly
    joined: a wrench ``(f, m)`` there is ``(f, m + r x f)`` at the first point, whose twist ``(u, theta)`` moves the
    second by ``(u + theta x r, theta)``: ``W^T C W`` with ``W = [[I, 0], [[r]_x, I]]``."""
    w = np.eye(6)
    w[3:, :3] = skew(offset)
    return w.T @ compliance @ w
