"""The spec sheet of the Phantom Premium at home against a hand computation from its published data.

At q = 0 (Cavusoglu & Feygin's coordinates) the handle is at (l1, 0, -l2) and its Jacobian's columns are
l1 e_y (q1), l1 e_z (q2) and l2 e_x (q3); H is diagonal: the memo's M(0) = diag(3.5735e-3, 2.4264e-3,
9.3189e-4) plus n^2 J_r (ratios 13.3, 11.2, 11.2; J_r = 1.08e-6). Hence by hand:
one count (1024 lines x 4) moves the handle by l 2 pi / (4096 n); the force a motor torque tau gives along
its axis is n tau / l; the apparent mass along each axis is H_ii / l_i^2; Coulomb friction 0.01 N m per joint
is felt as 0.01 / l_i along axis i, the largest over directions being the norm of the three; the joint
damping 0.0005 N m s/rad as 0.0005 / l_i^2. The inscribed-ball radius of the force polytope is also checked
against SciPy's linear programming (the Chebyshev centre LP) at a general pose.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog

from hapticdesign.devices.device_file import load_device_file
from hapticdesign.analysis.sampled_loop import SampledLoop, joint_limit
from hapticdesign.studies.spec import handle_at, inscribed_force, spec_sheet

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
L1, L2 = 0.215, 0.170
RATIO = np.array([13.3, 11.2, 11.2])
H0 = np.array([3.5735e-3, 2.4264e-3, 9.3189e-4]) + 1.08e-6 * RATIO**2
ARM = np.array([L1, L1, L2])  # lever of q1 (along y), q2 (along z), q3 (along x)


@pytest.fixture(scope="module")
def phantom():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_device_file(EXAMPLES / "phantom-premium.yaml")


@pytest.fixture(scope="module")
def sheet(phantom):
    return spec_sheet(phantom, workspace=False)


def test_phantom_resolution_and_forces_by_hand(sheet):
    assert sheet["resolution"] == pytest.approx(max(ARM * 2 * math.pi / (4096 * RATIO)), rel=1e-9)
    assert sheet["force_continuous"] == pytest.approx(min(RATIO * 0.0286 / ARM), rel=1e-9)
    assert sheet["force_peak"] == pytest.approx(min(RATIO * 0.129 / ARM), rel=1e-9)


def test_phantom_apparent_mass_friction_and_passivity_by_hand(sheet):
    mass = H0 / ARM**2
    assert sheet["apparent_mass"]["min"] == pytest.approx(mass.min(), rel=2e-5)
    assert sheet["apparent_mass"]["max"] == pytest.approx(mass.max(), rel=2e-5)
    friction = 0.01 / ARM
    assert sheet["backdrive_friction"]["min"] == pytest.approx(friction.min(), rel=1e-9)
    assert sheet["backdrive_friction"]["max"] == pytest.approx(np.linalg.norm(friction), rel=1e-9)
    damping = 0.0005 / ARM**2
    walls = sheet["renderable_stiffness"]
    assert walls["passivity_viscous"] == pytest.approx(2 * damping.min() * 1000, rel=1e-9)
    assert walls["passivity_coulomb"] == pytest.approx(2 * friction.min() / sheet["resolution"], rel=1e-9)
    axes = [joint_limit(m, b, SampledLoop()) for m, b in zip(mass, damping)]
    assert walls["exact"] == pytest.approx(min(axes), rel=1e-4)


def test_inscribed_force_equals_the_chebyshev_centre_lp(phantom):
    """max r s.t. +-g_k . c + r |g_k| <= n_k tau_k (SciPy linprog), at a pose where J_v is full."""
    q = np.array([0.3, 0.4, 0.2])
    h = handle_at(phantom, q)
    g = (h.jacobian.T).copy()
    b = RATIO * 0.0286
    rows = np.vstack([np.hstack([g, np.linalg.norm(g, axis=1, keepdims=True)]),
                      np.hstack([-g, np.linalg.norm(g, axis=1, keepdims=True)])])
    lp = linprog([0, 0, 0, -1], A_ub=rows, b_ub=np.concatenate([b, b]), bounds=[(None, None)] * 3 + [(0, None)])
    assert lp.status == 0
    assert inscribed_force(phantom, h, "continuous") == pytest.approx(-lp.fun, rel=1e-7)
