"""The exact wall limit of the n-joint sampled loop at a handle against an independent construction.

python-control builds the loop from scratch: the continuous plant ``H_h qdd + B_h qd + K_h q = tau`` (the hand's mass,
damping and stiffness added as ``x J_v^T J_v``), ``control.c2d`` with a zero-order hold, the delay as ``z^-d``, and
``control.feedback`` with the wall's spring ``K J_v^T u u^T J_v``; the limit is the spring at which the closed loop's
largest pole modulus reaches 1, bisected here. Without a hand the loop seen by the spring is single-input
single-output (force along u, displacement along u); the displacements along the wall are neither driven nor seen by
it: each is a pole at z = 1 over a zero at z = 1 of the transfer function, divided out. The inputs J_v, H, B are the five-bar's at a pose of its workspace.
"""

from __future__ import annotations

from pathlib import Path

import control
import numpy as np
import pytest

from hapticdesign.analysis.configuration import configuration_of, handle_pose
from hapticdesign.analysis.dynamics.device import gravity_gradient, mass_matrix
from hapticdesign.analysis.sampled_loop import GRASP, HANDS, Hand, SampledLoop, compensated_boundary
from hapticdesign.analysis.wall_stiffness import KMAX_OPTIONS, kmax_loop, wall_limit
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.errors import RenamedWarning, UserError
from hapticdesign.analysis.metrics.indices import INDICES, Request, evaluate, requests_of

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
PERIOD = 1e-3


@pytest.fixture(scope="module")
def five_bar():
    device = load_device_file(EXAMPLES / "five-bar.yaml")
    point = np.array([0.01, 0.0, 0.19])
    q = handle_pose(device, point).q
    return device, point, configuration_of(device).jacobian(q)[:3], mass_matrix(device, q), device.damping_matrix


def _loop_gain(jv, h, b, u, hand: Hand | None, delay: int):
    """The discrete loop the spring closes, ``w^T P(z) w z^-d`` (SISO, w = J_v^T u) or, with a hand, the MIMO
    ``P(z) z^-d`` and the spring's direction ``w w^T``."""
    n = h.shape[0]
    jtj = jv.T @ jv
    hand = hand or Hand()
    hh, bh, kh = h + hand.mass * jtj, b + hand.damping * jtj, hand.stiffness * jtj
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(hh, kh), -np.linalg.solve(hh, bh)]])
    bu = np.vstack([np.zeros((n, n)), np.linalg.inv(hh)])
    w = jv.T @ u
    lag = control.tf([1.0], [1.0] + [0.0] * delay, PERIOD)
    if hand.stiffness == 0:
        siso = control.ss(a, bu @ w[:, None], w[None, :] @ np.hstack([np.eye(n), np.zeros((n, n))]), 0)
        tf = control.tf(control.c2d(siso, PERIOD, "zoh"))
        num, den = np.asarray(tf.num[0][0]), np.asarray(tf.den[0][0])
        for _ in range(n - 1):  # each displacement along the wall: a pole at z = 1 over a zero at z = 1
            (num, r_num), (den, r_den) = np.polydiv(num, [1.0, -1.0]), np.polydiv(den, [1.0, -1.0])
            assert np.abs(r_num).max() <= 1e-9 * np.abs(num).max() and np.abs(r_den).max() <= 1e-9
        return control.tf(num, den, PERIOD) * lag, np.ones((1, 1))
    plant = control.c2d(control.ss(a, bu, np.hstack([np.eye(n), np.zeros((n, n))]), np.zeros((n, n))), PERIOD, "zoh")
    shift = np.eye(n * delay, k=-n)  # z^-d on n channels: a line of d held vectors
    line = control.ss(shift, np.eye(n * delay, n), np.eye(n, n * delay, k=n * (delay - 1)), np.zeros((n, n)), PERIOD)
    return plant * line, np.outer(w, w)


def _independent_limit(gain, spring) -> float:
    def radius(k):
        return np.abs(control.poles(control.feedback(gain, k * spring))).max()

    lo, hi = 1e-6, 1.0
    while radius(hi) < 1.0:
        lo, hi = hi, 2.0 * hi
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if radius(mid) < 1.0 else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("hand", [None, GRASP, HANDS["firm"], Hand(0.5, 8.0, 600.0)])
@pytest.mark.parametrize("u", [np.array([1.0, 0.0, 0.0]), np.array([0.6, 0.0, 0.8])])
def test_the_wall_limit_is_python_controls_closed_loop(five_bar, hand, u):
    _, _, jv, h, b = five_bar
    for delay in (1, 2):
        loop = SampledLoop(period=PERIOD, delay=delay, hand=hand)
        gain, spring = _loop_gain(jv, h, b, u, hand, delay)
        assert wall_limit(jv, h, b, loop, u) == pytest.approx(_independent_limit(gain, spring), rel=1e-6)


def test_one_joint_loop_is_the_seed_limits_closed_form():
    """A 1-joint handle under the seed's settings (full compensation, no delay) is the 1-DOF mass-damper whose limit
    the closed form gives, with and without a modelling error."""
    jv, h, b = np.array([[1.0], [0.0], [0.0]]), np.array([[0.004]]), np.array([[0.0005]])
    for error in (0.0, 5.0, -0.5):
        loop = SampledLoop.seed(error_percent=error)
        assert wall_limit(jv, h, b, loop, np.array([1.0, 0.0, 0.0])) == pytest.approx(
            compensated_boundary(0.004, 0.0005, PERIOD, 1.0 - error / 100.0), rel=1e-8)


def test_kmax_index_is_the_wall_limit_with_its_options(five_bar):
    """The index's options reach the loop as this test writes it (``period``, ``delay``, ``wall_damping`` as the wall's
    damper, ``"light"`` as the light hand, the direction, gravity's gradient at the pose): the plumbing, checked
    against :func:`wall_limit`, whose values are pinned independently, python-control's loop with the hand and the
    delay in this file's other tests and gravity's gradient in test_sim_gravity_gradient.py."""
    device, point, jv, h, b = five_bar
    options = {"period": 0.0005, "delay": 2, "wall_damping": 0.5, "hand": "light"}
    u = np.array([0.6, 0.0, 0.8])
    result = evaluate(device, point[None], [Request("kmax", {**options, "direction": u}, "along"),
                                            Request("kmax", options, "worst")])
    loop = SampledLoop(period=0.0005, delay=2, wall_damping=0.5, hand=GRASP)
    gravity = gravity_gradient(device, handle_pose(device, point).q)  # the index linearizes gravity's pull too
    assert result.values["along"][0] == pytest.approx(wall_limit(jv, h, b, loop, u, gravity), rel=1e-9)
    assert result.values["worst"][0] <= result.values["along"][0]


def test_the_kmax_options_former_damping_is_the_wall_damping_for_one_release(five_bar):
    """``damping`` (the option's former name) gives the same values as ``wall_damping`` with one deprecation line;
    both at once is one line of error."""
    device, point, *_ = five_bar
    options = {"period": 0.0005, "delay": 2, "direction": [0.6, 0.0, 0.8]}
    new = evaluate(device, point[None], [Request("kmax", {**options, "wall_damping": 0.5}, "k")]).values["k"][0]
    with pytest.warns(RenamedWarning, match="'damping' is now called 'wall_damping'"):
        old = evaluate(device, point[None], [Request("kmax", {**options, "damping": 0.5}, "k")]).values["k"][0]
    assert old == new and new != evaluate(device, point[None], [Request("kmax", options, "k")]).values["k"][0]
    with pytest.warns(RenamedWarning), pytest.raises(UserError, match="give wall_damping once"):
        requests_of([Request("kmax", {"wall_damping": 0.5, "damping": 0.5})])
    with pytest.warns(RenamedWarning):
        assert requests_of([Request("kmax", {"damping": 0.5})])[0].options == {"wall_damping": 0.5}
    assert "damping" not in INDICES["kmax"].options


def test_the_kmax_index_takes_a_hand_by_name(five_bar):
    """``hand: firm`` in a study is the firm hand's loop, python-control's closed loop with 0.554 kg, 6.45 N s/m and
    135 N/m at the handle; an unknown name is one line; ``grasp`` is the light hand with a deprecation line."""
    device, point, jv, h, b = five_bar
    u = np.array([0.6, 0.0, 0.8])
    named = evaluate(device.with_params({"g": 0.0}), point[None],
                     [Request("kmax", {"hand": "firm", "direction": u}, "firm")]).values["firm"][0]
    gain, spring = _loop_gain(jv, h, b, u, Hand(0.554, 6.45, 135.0), 1)
    assert named == pytest.approx(_independent_limit(gain, spring), rel=1e-6)
    with pytest.raises(UserError, match="unknown hand 'soft'; choose one of light, firm"):
        kmax_loop({**KMAX_OPTIONS, "hand": "soft"})
    with pytest.warns(FutureWarning, match="now called 'light'"):
        assert Hand.named("grasp") == HANDS["light"] == GRASP
