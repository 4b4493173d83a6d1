"""A serial 6R arm with full dynamic parameters, built in our core and in Pinocchio (``pin``).

The arm is given by random DH rows in seed 000's convention and random rigid bodies; Pinocchio
gets the same arm from its own API (joint placements ``tx(a) Rx(alpha) tz(s)`` between
revolute-z joints, inertias moved into its joint frames). H (CRBA), the gravity torque and
``C_cvt qd`` (RNEA with zero acceleration, minus gravity) must agree to 1e-9 relative.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from hapticdesign.analysis.dynamics.model import DynamicsModel
from hapticdesign.model.dh import dh_frames, revolute
from hapticdesign.model.inertia import BodyInertia
from hapticdesign.model.mechanism import BodyAttachment, JointType, Mechanism
from hapticdesign.model.transforms import Rx, const, tx, tz

N = 6


def _arm(rng: np.random.Generator):
    a = rng.uniform(-0.3, 0.3, N)
    alpha = rng.uniform(-np.pi, np.pi, N)
    s = rng.uniform(-0.3, 0.3, N)
    rows = [revolute(a[i], alpha[i], s[i], i) for i in range(N)]
    names = [str(i + 1) for i in range(N)]
    mech = Mechanism(
        coordinates=tuple(f"q{i + 1}" for i in range(N)),
        joint_types=(JointType.REVOLUTE,) * N,
        frames=tuple(dh_frames(rows, names)),
        bodies=tuple(BodyAttachment(n, f"body{n}") for n in names),
    )
    bodies = []
    for _ in range(N):
        m = rng.uniform(0.5, 3.0)
        r = rng.uniform(-0.2, 0.2, 3)
        principal = rng.uniform(0.01, 0.05, 3)
        principal[2] = min(principal[2], principal[0] + principal[1] - 1e-3)
        rot = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        ic = rot @ np.diag(principal) @ rot.T
        bodies.append(
            BodyInertia(m, *r, ic[0, 0], ic[1, 1], ic[2, 2], -ic[0, 1], -ic[0, 2], -ic[1, 2])
        )
    return mech, bodies, a, alpha, s


def _se3(*transforms) -> pin.SE3:
    t = np.eye(4)
    for et in transforms:
        t = t @ et.matrix(np.zeros(N))
    return pin.SE3(t[:3, :3], t[:3, 3])


def _pinocchio(bodies, a, alpha, s) -> pin.Model:
    model = pin.Model()
    parent = 0
    placement = _se3(tz(const(s[0])))
    for i in range(N):
        joint = model.addJoint(parent, pin.JointModelRZ(), placement, f"j{i + 1}")
        # our body frame is F_{i-1} Rz(q) Rx(alpha); the joint frame is F_{i-1} tz(s) Rz(q)
        body_in_joint = _se3(tz(const(-s[i])), Rx(const(alpha[i])))
        b = bodies[i]
        inertia = pin.Inertia(b.m, b.r, b.inertia_at_com)
        model.appendBodyToJoint(joint, body_in_joint.act(inertia), pin.SE3.Identity())
        parent = joint
        nxt = s[i + 1] if i + 1 < N else 0.0
        placement = _se3(tx(const(a[i])), Rx(const(alpha[i])), tz(const(nxt)))
    return model


@pytest.mark.parametrize("seed", [0, 1])
def test_serial_arm_matches_pinocchio(seed):
    rng = np.random.default_rng(seed)
    mech, bodies, a, alpha, s = _arm(rng)
    ours = DynamicsModel(mech)
    pi = np.concatenate([b.standard() for b in bodies])
    model = _pinocchio(bodies, a, alpha, s)
    data = model.createData()
    for _ in range(4):
        q = rng.uniform(-np.pi, np.pi, N)
        qd = rng.normal(size=N)
        h_ref = pin.crba(model, data, q)
        h_ref = np.triu(h_ref) + np.triu(h_ref, 1).T
        g_ref = pin.computeGeneralizedGravity(model, data, q)
        cqd_ref = pin.rnea(model, data, q, qd, np.zeros(N)) - g_ref
        h = ours.H(q, pi)
        assert np.abs(h - h_ref).max() <= 1e-9 * np.abs(h_ref).max()
        assert np.abs(ours.G(q, pi) - g_ref).max() <= 1e-9 * np.abs(g_ref).max()
        cqd = ours.C_cvt(q, qd, pi) @ qd
        assert np.abs(cqd - cqd_ref).max() <= 1e-9 * np.abs(cqd_ref).max()
        assert np.allclose(ours.inverse(q, qd, np.zeros(N), pi), cqd_ref + g_ref, rtol=1e-9, atol=1e-12)
