"""The 3-DOF Phantom against the literature model of Cavusoglu & Feygin (seed 000 ref. [25]).

Mapping (seed 000 eq. 2.53-2.55, Appendix A.3), with the literature lengths
``l1 = 0.215 (our l2 = l2a)``, ``l2 = 0.170 (our l3)``, ``l3 = 0.0325 (our l3a)``:

- joint angles ``theta2 = -theta2c``, ``theta3 = theta2c - theta3c`` (eq. 2.53), so
  ``M_lit = A^T H A`` and ``G_lit = A^T G`` with ``theta = A theta_c``;
- body ``a`` (forearm) is our link 3, mass centre mid-forearm, ``r3 = (0, 0, l2/2)``;
  body ``c`` (long parallelogram rod) is our link 2a, ``r2a = (-l1/2, 0, 0)``;
  body ``be`` (upper arm with motor counterweight) is our link 2, ``r2 = (l5, 0, 0)``;
  body ``df`` (short link with counterweight) is our link 3a, ``r3a = (0, 0, -l3 - l6)``;
  the base's ``Iyy`` is our link 1's moment about the vertical axis (frame-1 ``y``);
- inertia tensors rotate with eq. 2.54 (links 1, 2, 2a: ``R1(pi) R2(-pi/2)``) and eq. 2.55
  (links 3, 3a: ``R3(pi/2) R1(pi/2)``): ``I_ours = C I_lit C^T``;
- the literature's ``a`` and ``c`` inertias are about their mass centres, but its closed form
  (``M22 = IxxC + IxxEB + l1^2 ma + l1^2 mc / 4``, no ``mbe l5^2``) takes the ``be`` and ``df``
  inertias about the joint axes: we move them to the mass centre with the parallel-axis
  theorem before handing them to our model (the seed's Appendix A.3 leaves this implicit).

Test vectors: the literature closed form at g = 9.81 (public transcriptions of Cavusoglu & Feygin 2001).
"""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.model.inertia import BodyInertia, check_body


def _rot(axis: int, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


SET1 = _rot(0, np.pi) @ _rot(1, -np.pi / 2)
SET2 = _rot(2, np.pi / 2) @ _rot(0, np.pi / 2)
L1, L2, L3, L5, L6 = 0.215, 0.170, 0.0325, -0.0368, 0.0527
MASS = {"a": 0.0202, "c": 0.0249, "be": 0.2359, "df": 0.1906}
INERTIA = {
    "a": (0.4864e-4, 0.001843e-4, 0.4864e-4),
    "c": (0.959e-4, 0.959e-4, 0.0051e-4),
    "be": (11.09e-4, 10.06e-4, 0.591e-4),
    "df": (7.11e-4, 0.629e-4, 6.246e-4),
}
I_BASE_YY = 11.87e-4
A = np.array([[1.0, 0, 0], [0, -1, 0], [0, 1, -1]])


def _body(mass: float, r, lit_diag, frame_set, pivot_offset=None) -> BodyInertia:
    """Seed-convention body; ``pivot_offset`` (mass centre minus pivot, our frame) for pivot inertias."""
    i = frame_set @ np.diag(lit_diag) @ frame_set.T
    if pivot_offset is not None:
        d = np.asarray(pivot_offset, dtype=float)
        i = i - mass * (d @ d * np.eye(3) - np.outer(d, d))
    return BodyInertia(mass, *r, i[0, 0], i[1, 1], i[2, 2], -i[0, 1], -i[0, 2], -i[1, 2])


def literature_device(phantom3):
    bodies = {
        "2": _body(MASS["be"], (L5, 0, 0), INERTIA["be"], SET1, pivot_offset=(L5, 0, 0)),
        "2a": _body(MASS["c"], (-L1 / 2, 0, 0), INERTIA["c"], SET1),
        "3": _body(MASS["a"], (0, 0, L2 / 2), INERTIA["a"], SET2),
        "3a": _body(MASS["df"], (0, 0, -L3 - L6), INERTIA["df"], SET2, pivot_offset=(0, 0, -L6)),
    }
    params = {"l2": L1, "l2a": L1, "l3": L2, "l3a": L3, "g": 9.81}
    for name in phantom3.body_names:
        body = bodies.get(name, BodyInertia())
        for field in ("m", "rx", "ry", "rz", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz"):
            key = f"m{name}" if field == "m" else f"r{name}{field[1]}" if field[0] == "r" else f"{field}{name}"
            params[key] = getattr(body, field)
    return phantom3.with_params(params), bodies


def _literature_terms(device, theta_c):
    theta = A @ np.asarray(theta_c, dtype=float)
    pi = device.standard_parameters()
    pi[10 * 0 + 5] += I_BASE_YY  # base: moment about the vertical axis (frame-1 y), massless
    m = A.T @ dynamics_of(device).H(theta, pi) @ A
    n = A.T @ dynamics_of(device).G(theta, pi)
    return m, n


def test_mass_matrix_and_gravity_match_literature(phantom3):
    device, _ = literature_device(phantom3)
    m, n = _literature_terms(device, [0, 0, 0])
    assert np.allclose(m, np.diag([3.5735e-3, 2.4264e-3, 9.3189e-4]), rtol=0, atol=5e-8)
    assert np.allclose(n, [0, -0.016298, 0], atol=5e-7)
    _, n = _literature_terms(device, [0, 0.5, 0.5])
    assert np.allclose(n, [0, -0.014303, -0.035360], atol=5e-7)


def test_literature_closed_form_mass_matrix_at_random_poses(phantom3):
    """M22, M23 and M33 of Appendix A.3's closed form, away from the test pose."""
    device, _ = literature_device(phantom3)
    rng = np.random.default_rng(4)
    ma, mc = MASS["a"], MASS["c"]
    for _ in range(5):
        t1, t2, t3 = rng.uniform(-1, 1, 3)
        m, _ = _literature_terms(device, [t1, t2, t3])
        m22 = INERTIA["c"][0] + INERTIA["be"][0] + L1**2 * ma + 0.25 * L1**2 * mc
        m33 = INERTIA["a"][0] + INERTIA["df"][0] + 0.25 * L2**2 * ma + L3**2 * mc
        m23 = -0.5 * L1 * (L2 * ma + L3 * mc) * np.sin(t2 - t3)
        assert m[1, 1] == pytest.approx(m22, rel=1e-9)
        assert m[2, 2] == pytest.approx(m33, rel=1e-9)
        assert abs(m[1, 2]) == pytest.approx(abs(m23), rel=1e-9, abs=1e-15)


def test_literature_inertias_are_not_rigid_bodies():
    """The be and df inertias, as published, break the triangle inequality."""
    assert check_body("2", _body(MASS["be"], (L5, 0, 0), INERTIA["be"], SET1)).warning is not None
    assert check_body("3a", _body(MASS["df"], (0, 0, -L6), INERTIA["df"], SET2)).warning is not None
    assert check_body("3", _body(MASS["a"], (0, 0, L2 / 2), INERTIA["a"], SET2)).warning is None
