"""The exact Z-width (python-control interconnection) against independent derivations."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.errors import UserError
from hapticdesign.analysis.sampled_loop import MassDamper, closed_loop_matrix
from hapticdesign.simulation.zwidth import DisplayLoop, max_stiffness, passivity_stiffness, spectral_radius, zwidth


def _closed_form(j: float, b: float, t: float, c: float) -> float:
    a = math.exp(-b * t / j)
    return b * b * (1 - a) * (1 - a * c) / (j * (1 - a) * (1 - a * c) - t * a * b * (1 - c))


def _recursion_grows(j, b, t, delay, velocity, c, k, damper, samples=6000) -> bool:
    """The sampled loop iterated sample by sample with its exact ZOH step (written here, no library):
    does the oscillation of the last quarter exceed the second quarter's?"""
    m = expm(np.array([[0.0, 1.0, 0.0], [0.0, -b / j, 1.0 / j], [0.0, 0.0, 0.0]]) * t)
    phi, gamma = m[:2, :2], m[:2, 2]
    x = np.array([0.01, 0.0])
    qs, vs, us = [0.0] * (delay + 2), [0.0] * (delay + 2), [0.0] * (delay + 2)
    trace = []
    for _ in range(samples):
        qs, vs = [x[0], *qs[:-1]], [x[1], *vs[:-1]]
        v_hat = vs[delay] if velocity == "sampled" else (qs[delay] - qs[delay + 1]) / t
        u = -k * qs[delay] - damper * v_hat + c * (us[delay] - b * vs[delay])
        us = [u, *us[:-1]]
        x = phi @ x + gamma * u
        trace.append(abs(x[0]))
        if not np.isfinite(x[0]) or abs(x[0]) > 1e6:
            return True
    q = len(trace) // 4
    return max(trace[3 * q:]) > max(trace[q:2 * q])


@pytest.mark.parametrize("delay", [0, 1, 3])
@pytest.mark.parametrize("fraction", [0.0, 0.9, 1.0])
def test_control_interconnection_equals_the_hand_derived_map(delay, fraction):
    """python-control (c2d + feedback) against the one-sample map derived by hand in analysis/sampled_loop.py."""
    j, b, t = 0.02, 0.3, 1e-3
    for k, damper in ((50.0, 0.0), (150.0, 0.2), (3.0, 0.05)):
        ours = spectral_radius(DisplayLoop(j, b, t, delay, "sampled", fraction), k, damper)
        hand = MassDamper(j, b, t, delay, damper, compensate_inertia=fraction > 0, model_inertia=fraction * j)
        ref = float(np.max(np.abs(np.linalg.eigvals(closed_loop_matrix(hand, k)))))
        assert ours == pytest.approx(ref, rel=1e-9)


@pytest.mark.parametrize("fraction", [1.0, 0.99, 0.9, 0.0])
def test_compensator_case_is_the_closed_form(fraction):
    loop = DisplayLoop(0.039, 0.5, 1e-3, 0, "sampled", fraction)
    assert max_stiffness(loop) == pytest.approx(_closed_form(0.039, 0.5, 1e-3, fraction), rel=1e-8)


@pytest.mark.parametrize("velocity, delay, damper", [("difference", 0, 0.3), ("difference", 0, 3.0),
                                                     ("difference", 2, 0.2), ("sampled", 1, 1.0)])
def test_boundary_separates_decaying_from_growing_recursions(velocity, delay, damper):
    j, b, t = 0.01, 0.5, 1e-3
    k = max_stiffness(DisplayLoop(j, b, t, delay, velocity), damper)
    assert 0 < k < math.inf
    assert not _recursion_grows(j, b, t, delay, velocity, 0.0, 0.99 * k, damper)
    assert _recursion_grows(j, b, t, delay, velocity, 0.0, 1.01 * k, damper)


@pytest.mark.parametrize("velocity", ["sampled", "difference"])
@pytest.mark.parametrize("delay", [0, 1, 3])
def test_passivity_bound_is_never_above_the_exact_boundary(velocity, delay):
    loop = DisplayLoop(0.01, 0.5, 1e-3, delay, velocity)
    zw = zwidth(loop, [0.0, 0.05, 0.1, 0.2, 0.3, 0.45, 0.5, 1.0])
    assert all(p <= k for p, k in zip(zw.passivity, zw.K))
    assert zw.passivity[0] == pytest.approx(2 * 0.5 / (1e-3 * (1 + 2 * delay))) and zw.passivity[-1] == 0.0
    assert passivity_stiffness(loop, -0.2) == passivity_stiffness(loop, 0.2)


def test_default_grid_ends_where_a_damper_alone_destabilizes():
    zw = zwidth(DisplayLoop(0.01, 0.5, 1e-3, 0, "difference"), points=6)
    assert zw.B[0] == 0.0 and zw.K[-1] < 0.01 * max(zw.K)
    assert max(zw.K) > 5 * zw.K[0]  # virtual damping widens the stable range (the Z-width)


@pytest.mark.parametrize("kwargs", [dict(inertia=0.0), dict(damping=-1.0), dict(delay=-1), dict(velocity="x"),
                                    dict(fraction=2.5), dict(period=math.inf), dict(plant_stiffness=-1.0)])
def test_bad_loops_are_user_errors(kwargs):
    base = dict(inertia=0.01, damping=0.5, period=1e-3)
    with pytest.raises(UserError):
        DisplayLoop(**{**base, **kwargs})


def test_stiffness_map_is_b_squared_over_h11_with_full_compensation():
    from hapticdesign.devices.registry import preset
    from hapticdesign.simulation.zwidth import stiffness_map

    device = preset("phantom-3dof").with_params({"m3": 0.1, "r3x": 0.05, "m2": 0.25})
    result = stiffness_map(device, 0, (1, 2), 3, fraction=1.0)
    for i, a in enumerate(result.first):
        for j, b in enumerate(result.second):
            h11 = mass_matrix(device, np.array([0.0, a, b]))[0, 0]
            assert result.K[i][j] == pytest.approx(0.5 ** 2 / h11, rel=1e-8)
    with pytest.raises(UserError):
        stiffness_map(device, 0, (0, 2), 3)
