"""Post-evaluation, normalization and RMS selection of Pareto designs (seed 001 §7.1-7.2,
Table 7.3-7.5, eq. 7.1-7.4, Figures 7.1-7.3).

Post-evaluation (Table 7.3): every design gets the same tubes (D = 20 mm, d = 10 mm,
rho = 2000 kg/m^3, material :attr:`EvaluationLinks.material`, reported by
:meth:`EvaluationLinks.settings`; the seed's ``S_f`` reproduces with structural steel) and is
evaluated at home for one serial chain: ``I_f = ||M_C1||_F``
(eq. 4.98, 5.223), ``S_f = ||K_C1||_F`` (eq. 4.73, 5.122), ``omega_n = ||M_C1^-1 K_C1A||_F``
(eq. 4.107), with the critical ``mu_v = l1 cos q_max`` (eq. 6.8) and ``c_v = 1 / cos^2 q_max``
(eq. 6.18).
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.metrics import names
from hapticdesign.analysis.metrics.dynamic import inertia_frobenius, natural_frequency_index
from hapticdesign.analysis.metrics.stiffness import frobenius, translational_block
from hapticdesign.analysis.rcube.dynamics import chain_cartesian_mass
from hapticdesign.analysis.rcube.kinematics import critical_condition_number, critical_manipulability, inverse_kinematics
from hapticdesign.analysis.rcube.stiffness import chain_stiffness_matrices
from hapticdesign.optimization.front_selection import normalize, weighted_rms
from hapticdesign.optimization.rcube.constraints import CubeWorkspace
from hapticdesign.optimization.rcube.objectives import EvaluationLinks, geometry_of

METRIC_NAMES = (names.INERTIA_FROBENIUS, names.STIFFNESS_FROBENIUS, names.FREQUENCY_INDEX,
                names.CRITICAL_MANIPULABILITY, names.CRITICAL_CONDITION_NUMBER)
"""Table 7.3's five indices, keyed as in :mod:`hapticdesign.analysis.metrics.names`."""
LARGER_IS_BETTER = (names.STIFFNESS_FROBENIUS, names.FREQUENCY_INDEX, names.CRITICAL_MANIPULABILITY)
"""Indices flipped by eq. 7.2-7.4 so that 0 is the best value of every normalized index."""


def post_evaluate(X, workspace: CubeWorkspace = CubeWorkspace(), links: EvaluationLinks = EvaluationLinks()) -> dict[str, np.ndarray]:
    """Table 7.3's five indices for each design vector ``(q_max, l2, l3)`` of ``X (n, 3)``."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    out = {name: np.empty(len(X)) for name in METRIC_NAMES}
    for k, x in enumerate(X):
        geometry = geometry_of(x, workspace)
        design = links.design(geometry)
        home = geometry.home
        q = inverse_kinematics(geometry, home)
        M = chain_cartesian_mass(design, 0, q[0])
        K = chain_stiffness_matrices(design, home, passive=links.passive_eliminated)[0]
        out[names.INERTIA_FROBENIUS][k] = inertia_frobenius(M)
        out[names.STIFFNESS_FROBENIUS][k] = frobenius(K)
        out[names.FREQUENCY_INDEX][k] = natural_frequency_index(M, translational_block(K))
        out[names.CRITICAL_MANIPULABILITY][k] = critical_manipulability(geometry, x[0])
        out[names.CRITICAL_CONDITION_NUMBER][k] = critical_condition_number(x[0])
    return out


def normalized_indices(metrics: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Table 7.4 (eq. 7.1) followed by eq. 7.2-7.4 (``1 - p_n`` for the larger-is-better indices):
    0 is the best value of every returned index."""
    out = {}
    for name, values in metrics.items():
        n = normalize(values)
        out[name] = 1.0 - n if name in LARGER_IS_BETTER else n
    return out


def select(metrics: dict[str, np.ndarray], weights=(0.0, 0.25, 0.5, 0.75)) -> dict[str, int | dict[float, int]]:
    """Index of the minimum RMS of ``(omega_nn*, mu_vn*)`` (Fig. 7.2) and of the minimum weighted RMS
    for each weight on ``mu_vn*`` (Fig. 7.3, Table 7.5)."""
    n = normalized_indices(metrics)
    return {
        "rms": int(np.argmin(weighted_rms(n[names.FREQUENCY_INDEX], n[names.CRITICAL_MANIPULABILITY]))),
        "weighted": {float(w): int(np.argmin(weighted_rms(n[names.FREQUENCY_INDEX], n[names.CRITICAL_MANIPULABILITY], w))) for w in weights},
    }
