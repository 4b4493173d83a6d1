"""General metrics (seed 001 ch. 4) on the Phantom and the R-CUBE, against closed forms and SciPy."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import eigh

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.kinematics import jacobian
from hapticdesign.analysis.dynamics.cartesian import cartesian_inertia
from hapticdesign.analysis.metrics import dynamic, kinematic, stiffness
from hapticdesign.analysis.metrics.globalization import global_index
from hapticdesign.analysis.rcube.design import final_design
from hapticdesign.analysis.rcube.metrics import METRIC_NAMES, metrics_at, save_workspace_maps
from hapticdesign.errors import UserError


def two_r_jacobian(l1, l2, t1, t2):
    return np.array([[-l1 * np.sin(t1) - l2 * np.sin(t1 + t2), -l2 * np.sin(t1 + t2)],
                     [l1 * np.cos(t1) + l2 * np.cos(t1 + t2), l2 * np.cos(t1 + t2)]])


def test_two_r_manipulability_eq_4_39_and_ellipsoids():
    J = two_r_jacobian(0.3, 0.2, 0.4, 1.1)
    assert kinematic.manipulability(J) == pytest.approx(0.3 * 0.2 * abs(np.sin(1.1)))
    assert kinematic.absolute_manipulability(J) == pytest.approx(0.3 * 0.2 * abs(np.sin(1.1)))
    radii, _ = kinematic.velocity_ellipsoid(J)
    fr, _ = kinematic.force_ellipsoid(J)
    assert np.prod(radii) == pytest.approx(kinematic.manipulability(J))
    assert np.allclose(np.sort(radii * fr), 1.0)
    assert kinematic.condition_number(J) == pytest.approx(np.linalg.cond(J))
    assert kinematic.order_independent_manipulability(J) == pytest.approx(kinematic.manipulability(J))
    # normalized Jacobian (eq. 4.42-4.44): J_n = J / (l1 + l2) has link ratios r1, r2
    Jn = kinematic.normalized_jacobian(J, actual_reach=0.5)
    assert np.allclose(Jn, two_r_jacobian(0.6, 0.4, 0.4, 1.1))
    assert kinematic.condition_number(Jn) == pytest.approx(kinematic.condition_number(J))


def test_phantom_metrics_from_the_core_jacobian_and_device_inertia(phantom3):
    mech = phantom3.mechanism
    q = np.array([0.2, 0.5, -0.4])
    J = jacobian(mech, q)[:3]
    H = mass_matrix(phantom3, q)
    M_C = cartesian_inertia(H, J)
    assert np.allclose(J.T @ M_C @ J, H)
    assert dynamic.inertia_volume(M_C) == pytest.approx(np.linalg.det(H) / np.linalg.det(J.T @ J))  # eq. 4.93
    assert dynamic.dynamic_manipulability(H, J) == pytest.approx(np.linalg.det(J) / np.linalg.det(H))  # eq. 4.97
    assert dynamic.inertia_frobenius(M_C) == pytest.approx(np.sqrt(np.trace(M_C @ M_C.T)))
    assert dynamic.inertia_uniformity(M_C) == pytest.approx(np.linalg.cond(M_C))
    # a joint-space stiffness K gives the Cartesian one by the congruence of eq. 4.106
    K = np.diag([3.0, 2.0, 1.0])
    K_C = np.linalg.inv(J).T @ K @ np.linalg.inv(J)
    m = dynamic.modes(M_C, K_C)
    w2 = eigh(K, H, eigvals_only=True)
    assert np.allclose(m.frequencies, np.sqrt(w2))  # invariant under the change of coordinates
    assert stiffness.determinant(K_C) == pytest.approx(np.linalg.det(K) / np.linalg.det(J) ** 2)
    assert dynamic.acceleration_radius(H, J) == pytest.approx(np.linalg.svd(J @ np.linalg.inv(H), compute_uv=False).min())


def test_stiffness_metrics_blocks_and_pseudo_inverse():
    rng = np.random.default_rng(2)
    A = rng.normal(size=(6, 6))
    K = A @ A.T + 6 * np.eye(6)
    m = stiffness.all_stiffness_metrics(K)
    assert m["S_e"] == pytest.approx(np.linalg.cond(K))
    assert m["S_f"] == pytest.approx(np.sqrt(np.trace(K @ K.T)))
    assert m["S_da"] == pytest.approx(np.linalg.det(K[:3, :3]))
    assert m["S_dd"] == pytest.approx(np.linalg.det(K[3:, 3:]))
    assert m["S_et"] == pytest.approx(np.linalg.cond(K[:3, :3]))
    singular = np.diag([4.0, 2.0, 0.0])
    assert stiffness.euclidean_condition(singular, pseudo=True) == pytest.approx(2.0)  # eq. 6.58


def test_global_index_eq_4_108():
    assert global_index([1.0, 2.0, np.nan, 3.0]) == pytest.approx(2.0)
    assert global_index([1.0, 3.0], weights=[3.0, 1.0]) == pytest.approx(1.5)
    with pytest.raises(UserError):
        global_index([np.nan])


def test_rcube_metrics_at_home_and_maps(tmp_path):
    design = final_design()
    home = design.geometry.home
    m = metrics_at(design, np.stack([home, home + 5.0]))
    assert set(m) == set(METRIC_NAMES)
    assert m["condition_number"][0] == pytest.approx(1.0)  # J_m = l1 I at home
    assert m["manipulability"][0] == pytest.approx(design.geometry.l1**3)  # eq. 6.2
    assert all(np.isnan(m[k][1]) for k in METRIC_NAMES)  # unreachable point
    paths = save_workspace_maps(design, tmp_path, n=3, names=("manipulability",))
    assert len(paths) == 3 and all(p.stat().st_size > 0 and p.read_bytes()[:4] == b"\x89PNG" for p in paths)


def test_dynamic_manipulability_is_a_magnitude():
    """A mirrored Jacobian (det J < 0) gives the same I_d: |det J| / det M (eq. 4.97)."""
    import numpy as np

    from hapticdesign.analysis.metrics.dynamic import dynamic_manipulability

    J = np.array([[1.0, 0.2], [0.1, 0.5]])
    M = np.array([[2.0, 0.3], [0.3, 1.0]])
    mirrored = J[::-1]
    assert np.linalg.det(mirrored) < 0
    assert dynamic_manipulability(M, mirrored) == dynamic_manipulability(M, J) == abs(np.linalg.det(J)) / np.linalg.det(M)


def test_every_metric_key_is_in_the_one_vocabulary(phantom3):
    """R-CUBE metrics, Table 7.3's indices and the metrics command name each metric by the same key."""
    from hapticdesign.analysis.metrics.names import METRICS
    from hapticdesign.analysis.rcube.design import final_design
    from hapticdesign.analysis.rcube.metrics import METRIC_NAMES, metrics_at
    from hapticdesign.interface.commands.metrics import device_metrics
    from hapticdesign.optimization.rcube import selection

    design = final_design()
    assert set(metrics_at(design, design.geometry.home[None])) == set(METRIC_NAMES) <= set(METRICS)
    assert set(selection.METRIC_NAMES) <= set(METRICS)
    shared = set(device_metrics(phantom3, np.array([0.2, 0.5, -0.4]))) & set(METRICS)
    assert shared == {"manipulability", "condition_number", "I_m", "I_f", "I_e", "I_d", "acceleration_radius"}


@pytest.mark.parametrize("n", [1, 2, 3, 4, 6])
def test_handle_range_basis_agrees_with_lapack_svd_near_singular_poses_too(n):
    """The one-sided Jacobi range of 3 x n Jacobians against NumPy's (LAPACK's) SVD: singular values within a few
    ulps of sigma_1 (the backward error both have), ``U`` orthonormal and spanning the same range (``U^T J`` keeps
    J's norm along each direction, and is the returned Jacobian on the range), on random matrices and ones whose
    smallest singular value is 1e-4 .. 1e-12 of the largest (isotropy near 0) or exactly 0 (a zero row: a planar
    device)."""
    rng = np.random.default_rng(7)
    J = rng.normal(size=(400, 3, n)) * rng.uniform(1e-3, 1e3, size=(400, 1, 1))
    u0, s0, vt0 = np.linalg.svd(J, full_matrices=False)
    s0[:100, -1] *= 1e-4
    s0[100:200, -1] *= 1e-8
    s0[200:300, -1] *= 1e-12
    J = (u0 * s0[:, None, :]) @ vt0
    J[300:, 2] = 0.0
    u, s, along = kinematic.handle_range_basis(J)
    k = min(3, n)
    lapack = np.linalg.svd(J, compute_uv=False)
    eps = np.finfo(float).eps
    assert u.shape == (400, 3, k) and s.shape == (400, k)
    assert np.all(np.abs(s - lapack) <= 20 * eps * lapack[:, :1])
    assert np.all(s[:, :-1] >= s[:, 1:])
    assert np.abs(np.swapaxes(u, 1, 2) @ u - np.eye(k)).max() <= 20 * eps
    assert np.all(np.abs(along - np.swapaxes(u, 1, 2) @ J) <= 20 * eps * lapack[:, :1, None])
    assert np.all(np.abs(np.linalg.norm(np.swapaxes(u, 1, 2) @ J, axis=2) - s) <= 20 * eps * lapack[:, :1])
    # isotropy sigma_k / sigma_1 then within 40 eps of LAPACK's, near 0 too
    assert np.all(np.abs(s[:, -1] / s[:, 0] - lapack[:, k - 1] / lapack[:, 0]) <= 41 * eps)
    if n >= 3:  # the zero row leaves rank 2
        assert np.all(s[300:, 2] <= 20 * eps * lapack[300:, 0])


def test_handle_range_basis_of_a_planar_two_r_near_its_singularity():
    """The 2R arm's Jacobian on the x-y rows of a 3-row one (z row 0): sigma_1 sigma_2 = |det J| = l1 l2 |sin t2|
    and sigma_1^2 + sigma_2^2 = ||J||_F^2, to the rounding of J's entries, down to t2 = 1e-9 (isotropy ~1e-9);
    ``U`` spans the x-y plane."""
    eps = np.finfo(float).eps
    for t2 in (1.1, 1e-3, 1e-6, 1e-9):
        J = np.zeros((1, 3, 2))
        J[0, :2] = two_r_jacobian(0.3, 0.2, 0.4, t2)
        u, s, _ = kinematic.handle_range_basis(J)
        s1, s2 = s[0]
        assert s1 * s1 + s2 * s2 == pytest.approx(np.sum(J ** 2), rel=1e-14)
        assert abs(s2 - 0.3 * 0.2 * abs(np.sin(t2)) / s1) <= 10 * eps * s1
        assert np.abs(u[0, 2]).max() == 0.0
