"""The exact Z-width (the one-joint loop of the sampled-loop record) against independent derivations: python-control's
interconnection of the exactly discretized plant and the digital side, the closed form, a recursion written here."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from scipy.linalg import expm

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.sampled_loop import SampledLoop
from hapticdesign.errors import UserError
from hapticdesign.simulation.zwidth import max_stiffness, passivity_stiffness, zwidth


def _oracle_radius(j, b, t, delay, velocity, c, k, damper) -> float:
    """The loop built with python-control from scratch: the plant ``J qdd + b qd = u`` with outputs ``(q, qd)``
    discretized with ``control.c2d`` (zero-order hold), the digital side ``u_k = -K q_(k-N) - B v^_(k-N) +
    c (u_(k-N-1) - b v_(k-N))`` a discrete state-space system (state: the last N + 1 positions, N velocities and
    N + 1 torques), joined with ``control.feedback``; its largest pole modulus."""
    plant = control.c2d(control.ss([[0.0, 1.0], [0.0, -b / j]], [[0.0], [1.0 / j]], np.eye(2), np.zeros((2, 1))), t,
                        method="zoh")
    nq, nv, nu = delay + 1, delay, delay + 1
    size = nq + nv + nu
    cc, dd = np.zeros((1, size)), np.zeros((1, 2))

    def add(signal, lag, gain):
        if lag == 0:
            dd[0, "qv".index(signal)] += gain
        else:
            cc[0, {"q": 0, "v": nq, "u": nq + nv}[signal] + lag - 1] += gain

    add("q", delay, -k)
    if velocity == "sampled":
        add("v", delay, -damper)
    else:
        add("q", delay, -damper / t)
        add("q", delay + 1, damper / t)
    add("v", delay, -c * b)
    add("u", delay + 1, c)
    a, bb = np.zeros((size, size)), np.zeros((size, 2))
    bb[0, 0] = 1.0
    a[1:nq, 0:nq - 1] = np.eye(nq - 1)
    if nv:
        bb[nq, 1] = 1.0
        a[nq + 1:nq + nv, nq:nq + nv - 1] = np.eye(nv - 1)
    a[nq + nv], bb[nq + nv] = cc[0], dd[0]
    a[nq + nv + 1:, nq + nv:size - 1] = np.eye(nu - 1)
    closed = control.feedback(plant, control.ss(a, bb, cc, dd, t), sign=1)
    return float(np.max(np.abs(control.poles(closed))))


def _oracle_limit(j, b, t, delay, velocity, c, damper) -> float:
    lo, hi = 1e-6, 1.0
    assert _oracle_radius(j, b, t, delay, velocity, c, lo, damper) < 1.0
    while _oracle_radius(j, b, t, delay, velocity, c, hi, damper) < 1.0:
        lo, hi = hi, 2.0 * hi
    while hi - lo > 1e-11 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _oracle_radius(j, b, t, delay, velocity, c, mid, damper) < 1.0 else (lo, mid)
    return 0.5 * (lo + hi)


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
@pytest.mark.parametrize("error", [None, 10.0, 0.0])
@pytest.mark.parametrize("velocity", ["sampled", "difference"])
def test_the_limit_is_python_controls_interconnection(delay, error, velocity):
    """The one-joint loop of the sampled-loop record against python-control's (c2d + feedback), without the
    compensator (None) and with it (E = 10 %, 0 %)."""
    j, b, t = 0.02, 0.3, 1e-3
    for damper in (0.0, 0.2, 0.05):
        loop = SampledLoop(period=t, delay=delay, velocity=velocity, compensation="none" if error is None else "full",
                           error_percent=error or 0.0)
        expected = _oracle_limit(j, b, t, delay, velocity, loop.fraction, damper)
        assert max_stiffness(j, b, loop, damper) == pytest.approx(expected, rel=1e-8)


@pytest.mark.parametrize("fraction", [1.0, 0.99, 0.9, 0.0])
def test_compensator_case_is_the_closed_form(fraction):
    loop = SampledLoop.seed(error_percent=100.0 * (1.0 - fraction)) if fraction else SampledLoop.seed(compensation="none")
    assert max_stiffness(0.039, 0.5, loop) == pytest.approx(_closed_form(0.039, 0.5, 1e-3, fraction), rel=1e-8)


@pytest.mark.parametrize("velocity, delay, damper", [("difference", 0, 0.3), ("difference", 0, 3.0),
                                                     ("difference", 2, 0.2), ("sampled", 1, 1.0)])
def test_boundary_separates_decaying_from_growing_recursions(velocity, delay, damper):
    j, b, t = 0.01, 0.5, 1e-3
    k = max_stiffness(j, b, SampledLoop(period=t, delay=delay, velocity=velocity, compensation="none"), damper)
    assert 0 < k < math.inf
    assert not _recursion_grows(j, b, t, delay, velocity, 0.0, 0.99 * k, damper)
    assert _recursion_grows(j, b, t, delay, velocity, 0.0, 1.01 * k, damper)


@pytest.mark.parametrize("velocity", ["sampled", "difference"])
@pytest.mark.parametrize("delay", [0, 1, 3])
def test_passivity_bound_is_never_above_the_exact_boundary(velocity, delay):
    loop = SampledLoop(delay=delay, velocity=velocity, compensation="none")
    zw = zwidth(0.01, 0.5, loop, [0.0, 0.05, 0.1, 0.2, 0.3, 0.45, 0.5, 1.0])
    assert all(p <= k for p, k in zip(zw.passivity, zw.K))
    assert zw.passivity[0] == pytest.approx(2 * 0.5 / (1e-3 * (1 + 2 * delay))) and zw.passivity[-1] == 0.0
    assert passivity_stiffness(0.5, loop, -0.2) == passivity_stiffness(0.5, loop, 0.2)


def test_default_grid_ends_where_a_damper_alone_destabilizes():
    zw = zwidth(0.01, 0.5, SampledLoop(delay=0, compensation="none"), points=6)
    assert zw.B[0] == 0.0 and zw.K[-1] < 0.01 * max(zw.K)
    assert max(zw.K) > 5 * zw.K[0]  # virtual damping widens the stable range (the Z-width)


@pytest.mark.parametrize("plant", [dict(inertia=0.0), dict(damping=-1.0), dict(inertia=math.nan)])
def test_bad_plants_are_user_errors(plant):
    with pytest.raises(UserError):
        zwidth(**{"inertia": 0.01, "damping": 0.5, "loop": SampledLoop(), **plant}, dampers=[0.0])


@pytest.mark.parametrize("kwargs", [dict(delay=-1), dict(velocity="x"), dict(error_percent=250.0),
                                    dict(period=math.inf), dict(compensation="exact")])
def test_bad_settings_are_user_errors(kwargs):
    with pytest.raises(UserError):
        SampledLoop(**kwargs)


def test_stiffness_map_is_b_squared_over_h11_with_full_compensation():
    from hapticdesign.devices.registry import preset
    from hapticdesign.simulation.zwidth import stiffness_map

    device = preset("phantom-3dof").with_params({"m3": 0.1, "r3x": 0.05, "m2": 0.25})
    result = stiffness_map(device, 0, (1, 2), 3, SampledLoop.seed())
    for i, a in enumerate(result.first):
        for j, b in enumerate(result.second):
            h11 = mass_matrix(device, np.array([0.0, a, b]))[0, 0]
            assert result.K[i][j] == pytest.approx(0.5 ** 2 / h11, rel=1e-8)
    with pytest.raises(UserError):
        stiffness_map(device, 0, (0, 2), 3, SampledLoop.seed())
