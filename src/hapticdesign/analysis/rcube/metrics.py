"""All seed metrics of an R-CUBE design over sets of platform positions (seed 001 §6.1-6.3, §7.5).

Vectorized over positions; unreachable or singular positions give NaN in maps.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hapticdesign.analysis.metrics import dynamic, kinematic, names, stiffness
from hapticdesign.analysis.metrics.maps import evaluate_planes, plane_grid, save_map
from hapticdesign.analysis.metrics.names import METRICS
from hapticdesign.analysis.rcube.design import RCubeDesign
from hapticdesign.analysis.rcube.dynamics import cartesian_mass_matrix
from hapticdesign.analysis.rcube.kinematics import active_jacobian, inverse_kinematics, is_reachable, is_singular
from hapticdesign.analysis.rcube.stiffness import cartesian_stiffness

METRIC_NAMES = (
    names.MANIPULABILITY, names.CONDITION_NUMBER, names.POSITIONING_RESOLUTION,
    names.INERTIA_VOLUME, names.INERTIA_FROBENIUS, names.INERTIA_UNIFORMITY, names.DYNAMIC_MANIPULABILITY,
    names.ACCELERATION_RADIUS, names.STIFFNESS_UNIFORMITY, names.STIFFNESS_FROBENIUS, names.STIFFNESS_VOLUME,
    names.TRANSLATIONAL_UNIFORMITY, names.ROTATIONAL_UNIFORMITY, names.TRANSLATIONAL_VOLUME,
    names.ROTATIONAL_VOLUME, names.FREQUENCY_INDEX,
)
"""The metrics of :func:`metrics_at`, keyed as in :mod:`hapticdesign.analysis.metrics.names`."""


def metrics_at(design: RCubeDesign, positions) -> dict[str, np.ndarray]:
    """Every metric at reachable, regular positions ``(P, 3)`` (NaN elsewhere).

    Kinematic metrics use ``J_m`` (eq. 6.1-6.18); inertia metrics ``M_C`` (eq. 5.227) with
    the joint-space view ``M = J_m^T M_C J_m``; stiffness metrics ``K_C`` (eq. 5.123);
    ``omega_n = ||M_C^-1 K_CA||_F`` (eq. 4.107 with eq. 7.8's translational block).
    """
    r = np.asarray(positions, dtype=float).reshape(-1, 3)
    out = {name: np.full(len(r), np.nan) for name in METRIC_NAMES}
    ok = is_reachable(design.geometry, r)
    if ok.any():
        q = inverse_kinematics(design.geometry, r[ok])
        ok_idx = np.flatnonzero(ok)
        regular = ~is_singular(design.geometry, q, 1e-6)
        ok_idx, q, rr = ok_idx[regular], q[regular], r[ok][regular]
        if len(rr):
            Jm = active_jacobian(design.geometry, q[..., 0])
            M_C = cartesian_mass_matrix(design, rr)
            K_C = cartesian_stiffness(design, rr)
            M = np.swapaxes(Jm, -1, -2) @ M_C @ Jm
            values = {
                names.MANIPULABILITY: kinematic.absolute_manipulability(Jm),
                names.CONDITION_NUMBER: kinematic.condition_number(Jm),
                names.POSITIONING_RESOLUTION: kinematic.positioning_resolution(Jm),
                names.INERTIA_VOLUME: dynamic.inertia_volume(M_C),
                names.INERTIA_FROBENIUS: dynamic.inertia_frobenius(M_C),
                names.INERTIA_UNIFORMITY: dynamic.inertia_uniformity(M_C),
                names.DYNAMIC_MANIPULABILITY: dynamic.dynamic_manipulability(M, Jm),
                names.ACCELERATION_RADIUS: dynamic.acceleration_radius(M, Jm),
                **stiffness.all_stiffness_metrics(K_C),
                names.FREQUENCY_INDEX: dynamic.natural_frequency_index(M_C, stiffness.translational_block(K_C)),
            }
            for name in METRIC_NAMES:
                out[name][ok_idx] = values[name]
    return out


def plane_centres(design: RCubeDesign, offsets=(-0.06, 0.0, 0.06)) -> list[np.ndarray]:
    """Centres of the planes ``f_p(-60), f_p(0), f_p(60)`` (§7.5): home shifted along z; each plane
    spans the cube's x-y extent (the figures are labelled by the corner ``(o, o, o)``)."""
    return [design.geometry.home + np.array([0.0, 0.0, o]) for o in offsets]


def workspace_maps(design: RCubeDesign, n: int = 21, half_width: float = 0.06, offsets=(-0.06, 0.0, 0.06)):
    """Metric maps ``(n, n)`` on the three planes normal to z of §7.5."""
    return evaluate_planes(lambda p: metrics_at(design, p), plane_centres(design, offsets), half_width, n)


def save_workspace_maps(design: RCubeDesign, out_dir: Path, n: int = 21, half_width: float = 0.06,
                        offsets=(-0.06, 0.0, 0.06), names=METRIC_NAMES) -> list[Path]:
    """PNG images of each metric on each plane: ``<metric>_plane<offset mm>.png``."""
    planes = workspace_maps(design, n, half_width, offsets)
    _, grid_offsets = plane_grid(np.zeros(3), half_width, n)
    paths = []
    for o, maps in zip(offsets, planes):
        for name in names:
            tag = f"{o * 1e3:+.0f}".replace("+", "p").replace("-", "m")
            paths.append(save_map(Path(out_dir) / f"{name}_plane{tag}.png", maps[name], grid_offsets,
                                  f"{name}, plane {o * 1e3:+.0f} mm", ("x", "y"), unit=METRICS[name].unit))
    return paths
