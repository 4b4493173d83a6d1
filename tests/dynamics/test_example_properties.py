"""Properties every correct model must have, over every example device (issue 21: one suite, not a copy
per device).

For each file of examples/devices: H symmetric positive definite; ``Hdot - 2 C_cvt`` skew-symmetric
(seed 000 eq. 2.51-2.52; ``Hdot`` by a fourth-order central difference of H along ``qd``); the power
balance ``d/dt (qd^T H qd / 2) = qd^T (tau - G)`` along a smooth motion with ``tau`` the inverse
dynamics (the time derivative by a fourth-order central difference); the handle's Jacobian over the
actuated coordinates against central differences of its position. Poses near the device's home
(its configuration space's, a closed-loop device's assembly branch).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics.device import coriolis_matrix, gravity, inverse_dynamics, mass_matrix
from hapticdesign.devices.loading import load_device

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
FILES = sorted(p.name for p in EXAMPLES.iterdir() if p.suffix in (".yaml", ".toml"))
SPREAD = 0.15
"""rad or m: poses within this of home on every actuated coordinate."""


@pytest.fixture(scope="module", params=FILES)
def device(request):
    return load_device(EXAMPLES / request.param)


def _poses(device, n: int, seed: int) -> np.ndarray:
    home = configuration_of(device).home
    return home + np.random.default_rng(seed).uniform(-SPREAD, SPREAD, (n, len(home)))


def _d_dt(f, t: float, h: float):
    """Fourth-order central difference of ``f`` at ``t``."""
    return (-f(t + 2 * h) + 8 * f(t + h) - 8 * f(t - h) + f(t - 2 * h)) / (12 * h)


def test_mass_matrix_is_symmetric_positive_definite(device):
    for q in _poses(device, 8, 1):
        h = mass_matrix(device, q)
        np.testing.assert_allclose(h, h.T, rtol=0, atol=1e-14 * np.abs(h).max())
        assert np.linalg.eigvalsh(h).min() > 0.0


def test_hdot_minus_two_c_cvt_is_skew_symmetric(device):
    rng = np.random.default_rng(2)
    for q in _poses(device, 3, 3):
        qd = rng.normal(size=len(q))
        hdot = _d_dt(lambda s: mass_matrix(device, q + s * qd), 0.0, 1e-3)
        n = hdot - 2 * coriolis_matrix(device, q, qd)
        # truncation ~1e-12 |Hdot|, round-off of the difference ~1e-13 |H| |qd| (a device whose H hardly
        # changes near home has a tiny Hdot)
        scale = max(np.abs(hdot).max(), np.abs(mass_matrix(device, q)).max() * np.abs(qd).max())
        assert np.abs(n + n.T).max() <= 1e-7 * scale


def test_power_balance_along_a_motion(device):
    """``d/dt (qd^T H qd / 2) = qd^T (tau - G)`` at instants of ``q(t) = q0 + a sin(w t)``."""
    q0 = _poses(device, 1, 4)[0]
    a = np.random.default_rng(5).uniform(-0.05, 0.05, len(q0))
    w = 2.0

    def q(t):
        return q0 + a * np.sin(w * t)

    def qd(t):
        return a * w * np.cos(w * t)

    def kinetic(t):
        return 0.5 * qd(t) @ mass_matrix(device, q(t)) @ qd(t)

    for t in (0.1, 0.7):
        qdd = -a * w**2 * np.sin(w * t)
        power = qd(t) @ (inverse_dynamics(device, q(t), qd(t), qdd) - gravity(device, q(t)))
        assert abs(_d_dt(kinetic, t, 1e-3) - power) <= 1e-7 * max(abs(power), np.abs(a * w).max() ** 2
                                                                  * np.abs(mass_matrix(device, q0)).max())


def test_handle_jacobian_is_the_derivative_of_its_position(device):
    if device.mechanism.end_effector is None:
        pytest.skip("the device names no handle frame")
    space = configuration_of(device)
    eps = 1e-6
    for q in _poses(device, 2, 6):
        numeric = np.column_stack([(space.pose(q + eps * e)[:3, 3] - space.pose(q - eps * e)[:3, 3]) / (2 * eps)
                                   for e in np.eye(len(q))])
        jac = space.jacobian(q)[:3]
        np.testing.assert_allclose(jac, numeric, rtol=0, atol=1e-7 * max(np.abs(jac).max(), 1e-3))
