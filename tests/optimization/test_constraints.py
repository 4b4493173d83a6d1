"""Constraints 1-8 (seed 001 eq. 6.24-6.52) against the mechanism's own inverse kinematics and
against the seed's Table 7.2."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.rcube.kinematics import inverse_kinematics, passive_reach
from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.optimization.rcube.constraints import (
    ERGONOMIC_POINTS,
    PASSIVE_POINTS,
    CubeWorkspace,
    constraint_values,
    critical_points,
    elbow_cosine,
    link1_length,
    world_point,
)
from tests.helpers.optimization_seed_tables import table, table_7_2_designs


def test_constraint_1_reproduces_table_7_2_angles():
    t = table("table_7_2")
    # l1 sin q_max = 60 mm (eq. 6.23-6.24): the printed l1 from the printed angle, to the printed rounding
    assert np.allclose(link1_length(np.radians(t[:, 5])) * 1e3, t[:, 1], atol=0.35)


@pytest.mark.parametrize("x", [(0.567, 0.0741, 0.1218), (0.45, 0.09, 0.135), (0.6, 0.1, 0.16)])
def test_passive_constraints_match_the_inverse_kinematics(x):
    q, l2, l3 = x
    l1 = float(link1_length(q))
    g = RCubeGeometry(l1, l2, l3)
    G = constraint_values(np.array([x]))[0]
    for k, name in enumerate(PASSIVE_POINTS):
        # eq. 6.45-6.49 in closed form against cos q_13 of chain 1 at the same platform position (eq. 5.39)
        c3 = passive_reach(g, world_point(name, q, l1))[0]
        assert G[k] == pytest.approx(c3**2 - 1.0, abs=1e-12)


def test_ergonomic_constraint_matches_the_inverse_kinematics():
    # Table 7.2 Sol. 20: reachable at C1 and B1 by every chain, so the library's IK applies
    x = table_7_2_designs()[19]
    l1 = float(link1_length(x[0]))
    g = RCubeGeometry(l1, x[1], x[2])
    G = constraint_values(x[None])[0]
    for k, name in enumerate(ERGONOMIC_POINTS):
        q = inverse_kinematics(g, world_point(name, x[0], l1))
        assert G[5 + k] == pytest.approx(np.sin(q[0, 1] + q[0, 2]), abs=1e-12)


def test_critical_points_closed_forms():
    q = 0.5
    l1, v = 0.06 / np.sin(q), 0.065
    p = critical_points(q)
    assert np.allclose(p["C2"], (l1 + v, -v)) and np.allclose(p["C5"], (l1 - v, 0.0))
    # B5: r_y = l1 - l1 cos q_max = 60/sin - 60 cot (eq. 6.44, 6.49)
    assert np.allclose(p["B5"][1], 0.06 / np.sin(q) - 0.06 / np.tan(q))


def test_table_7_2_solutions_are_feasible_within_the_printed_rounding():
    G = constraint_values(table_7_2_designs())
    # Constraints 3, 4, 6, 7 hold for all 40 seed solutions
    assert np.all(G[:, [0, 1, 3, 4]] < 0.0)
    # Constraint 5 (C5) and 8 (C1) are active on the short end of the front: the seed's values sit
    # within 1.1 % of cos^2 q_3 = 1 and within sin(q_2 + q_3) = 0.009 of the bound
    assert np.all(G[:, 2] < 0.011) and np.all(G[:, 5] < 0.009) and np.all(G[:, 6] < 0.0)
    assert (G[:, 2] > 0).sum() == 2


def test_printed_sign_of_eq_6_48_would_reject_every_seed_solution():
    x = table_7_2_designs()
    q, l2, l3 = x[:, 0], x[:, 1], x[:, 2]
    l1 = 0.06 / np.sin(q)
    printed = elbow_cosine(l1 + 0.065, l1 + 0.06 / np.tan(q) + 0.065, l2, l3) ** 2
    assert np.all(printed > 1.0)


def test_workspace_validation():
    from hapticdesign.errors import UserError

    with pytest.raises(UserError):
        CubeWorkspace(side=-0.1)
    with pytest.raises(UserError):
        CubeWorkspace(side=0.12, virtual_side=0.1)
