"""The Phantom Premium 1.5's mass matrix and handle Jacobian in closed form, an oracle that does not use the toolkit:
Cavusoglu & Feygin's memo (UC Berkeley ERL M01/15, 2001; the formulas as github.com/mahilab/Phantom transcribes
them, ``step_dynamics_cavusoglu``) with the reflected rotor inertia ``n^2 J_r`` of examples/devices/phantom-premium.yaml,
and the derivative of their handle position ``x = cos q1 (l1 cos q2 + l2 sin q3)``, ``y = sin q1 (...)``,
``z = l1 sin q2 - l2 cos q3``."""

from __future__ import annotations

import math

import numpy as np

L1, L2, L3, L5, L6 = 0.215, 0.170, 0.0325, -0.0368, 0.0527
MA, MC, MBE, MDF = 0.0202, 0.0249, 0.2359, 0.1906
IA = (0.4864e-4, 0.001843e-4, 0.4864e-4)
IC = (0.959e-4, 0.959e-4, 0.0051e-4)
IBE = (11.09e-4, 10.06e-4, 0.591e-4)
IDF = (7.11e-4, 0.629e-4, 6.246e-4)
IBASE_YY = 11.87e-4
ROTOR = 1.08e-6 * np.array([13.3, 11.2, 11.2]) ** 2


def cavusoglu_mass_matrix(q) -> np.ndarray:
    """The memo's M(q) (without motors)."""
    _, q2, q3 = q
    m11 = (0.125 * (4 * IA[1] + 4 * IA[2] + 8 * IBASE_YY + 4 * IBE[1] + 4 * IBE[2] + 4 * IC[1] + 4 * IC[2]
                    + 4 * IDF[1] + 4 * IDF[2] + 4 * L1**2 * MA + L2**2 * MA + L1**2 * MC + 4 * L3**2 * MC)
           + 0.125 * (4 * IBE[1] - 4 * IBE[2] + 4 * IC[1] - 4 * IC[2] + L1**2 * (4 * MA + MC)) * math.cos(2 * q2)
           + 0.125 * (4 * IA[1] - 4 * IA[2] + 4 * IDF[1] - 4 * IDF[2] - L2**2 * MA - 4 * L3**2 * MC) * math.cos(2 * q3)
           + L1 * (L2 * MA + L3 * MC) * math.cos(q2) * math.sin(q3))
    m22 = IBE[0] + IC[0] + L1**2 * MA + 0.25 * L1**2 * MC
    m23 = -0.5 * L1 * (L2 * MA + L3 * MC) * math.sin(q2 - q3)
    m33 = IA[0] + IDF[0] + 0.25 * L2**2 * MA + L3**2 * MC
    return np.array([[m11, 0, 0], [0, m22, m23], [0, m23, m33]])


def handle_jacobian(q, l1: float = L1, l2: float = L2) -> np.ndarray:
    """d(x, y, z) / d(q1, q2, q3) of the memo's handle position."""
    q1, q2, q3 = q
    r = l1 * math.cos(q2) + l2 * math.sin(q3)
    c1, s1 = math.cos(q1), math.sin(q1)
    return np.array([[-s1 * r, -c1 * l1 * math.sin(q2), c1 * l2 * math.cos(q3)],
                     [c1 * r, -s1 * l1 * math.sin(q2), s1 * l2 * math.cos(q3)],
                     [0.0, l1 * math.cos(q2), l2 * math.sin(q3)]])


def apparent_mass(q) -> float:
    """The largest eigenvalue of the handle's Cartesian mass ``Lambda = (J H^-1 J^T)^-1``, ``H`` the memo's ``M`` plus
    ``diag(n^2 J_r)`` (kg): the heaviest the handle feels, accelerated from rest along its heaviest direction."""
    jac = handle_jacobian(q)
    h = cavusoglu_mass_matrix(q) + np.diag(ROTOR)
    return float(np.linalg.eigvalsh(np.linalg.inv(jac @ np.linalg.solve(h, jac.T))).max())
