"""A handle's Cartesian mass and damping from energy: joint rates of handle velocities by central differences of
the inverse kinematics, then the kinetic energy ``1/2 qd^T H qd`` and the dissipated power ``qd^T B qd``."""

from __future__ import annotations

import itertools

import numpy as np

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics.device import mass_matrix


def joint_rates(device, point: np.ndarray, v: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """``qd_a`` moving the handle at ``point`` with velocity ``v`` (central differences of the inverse kinematics)."""
    space = configuration_of(device)
    _, full = space.reach(point[None])
    ahead, _ = space.reach(np.array([point + h * v]), start=full[0])
    back, _ = space.reach(np.array([point - h * v]), start=full[0])
    return (ahead[0] - back[0]) / (2 * h)


def quadratic_form(device, point: np.ndarray, basis: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """``S`` in ``basis`` (3 x k) with ``qd^T matrix qd = v^T S v`` for handle velocities ``v`` (polarization over the
    basis vectors and their sums)."""
    def value(v):
        qd = joint_rates(device, point, v)
        return qd @ matrix @ qd

    k = basis.shape[1]
    out = np.zeros((k, k))
    for i in range(k):
        out[i, i] = value(basis[:, i])
    for i, j in itertools.combinations(range(k), 2):
        out[i, j] = out[j, i] = (value(basis[:, i] + basis[:, j]) - out[i, i] - out[j, j]) / 2
    return out


def cartesian_mass(device, point: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """``Lambda`` in ``basis`` from ``2 T(v) = v^T Lambda v`` (H of :func:`mass_matrix`, checked against Pinocchio)."""
    q_a, _ = configuration_of(device).reach(point[None])
    return quadratic_form(device, point, basis, mass_matrix(device, q_a[0]))


def cartesian_damping(device, point: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """The handle's damping in ``basis`` from the dissipated power ``qd^T B qd = v^T D v`` (B: joints and motors)."""
    return quadratic_form(device, point, basis, device.damping_matrix)
