"""Post-evaluation, normalization and RMS selection (seed 001 Tables 7.3-7.5, eq. 7.1-7.4)."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.errors import UserError
from hapticdesign.optimization.rcube.objectives import SEED_EVALUATION_MATERIAL, EvaluationLinks
from hapticdesign.optimization.front_selection import normalize, weighted_rms
from hapticdesign.optimization.rcube.selection import METRIC_NAMES, normalized_indices, post_evaluate, select
from tests.helpers.optimization_seed_tables import table, table_7_2_designs


def seed_metrics() -> dict[str, np.ndarray]:
    t = table("table_7_3")
    return {name: t[:, k + 1] for k, name in enumerate(METRIC_NAMES)}


def test_normalization_reproduces_table_7_4():
    t4 = table("table_7_4")
    m = seed_metrics()
    # mu_v and c_v from Table 7.2's l1 and q_max (eq. 6.8, 6.18): Table 7.3 prints them to 3 digits
    t2 = table("table_7_2")
    q = np.arcsin(60.0 / t2[:, 1])
    m["mu_v"], m["c_v"] = t2[:, 1] * np.cos(q), 1.0 / np.cos(q) ** 2
    tolerances = {"I_f": 0.05, "S_f": 0.0021, "omega_n": 0.0021, "mu_v": 0.006, "c_v": 0.006}
    for k, name in enumerate(METRIC_NAMES):
        # eq. 7.1 gives Table 7.4 to its printed digits; I_f has two significant digits in Table 7.3
        assert np.allclose(normalize(m[name]), t4[:, k + 1], atol=tolerances[name]), name


def test_rms_and_weighted_rms_reproduce_the_seed_choices():
    m = seed_metrics()
    choice = select(m)
    assert choice["rms"] + 1 == 29  # Figure 7.2
    assert {w: c + 1 for w, c in choice["weighted"].items()} == {0.0: 1, 0.25: 2, 0.5: 6, 0.75: 16}  # Table 7.5


def test_selection_on_a_toy_front_with_a_known_answer():
    # three designs: the best frequency, the best manipulability, and one 0.3/0.3 from both ideals
    metrics = {
        "I_f": np.array([1.0, 3.0, 2.0]),
        "S_f": np.array([3.0, 1.0, 2.0]),
        "omega_n": np.array([10.0, 0.0, 7.0]),
        "mu_v": np.array([0.0, 1.0, 0.7]),
        "c_v": np.array([2.0, 1.0, 1.5]),
    }
    n = normalized_indices(metrics)
    assert np.allclose(n["omega_n"], [0.0, 1.0, 0.3]) and np.allclose(n["mu_v"], [1.0, 0.0, 0.3])
    assert np.allclose(n["I_f"], [0.0, 1.0, 0.5])
    choice = select(metrics, weights=(0.0, 2.0))
    assert choice["rms"] == 2  # sqrt(0.09) < sqrt(0.5)
    assert choice["weighted"] == {0.0: 0, 2.0: 2}
    assert weighted_rms(0.3, 0.4, 1.0) == pytest.approx(np.sqrt(0.125))


def test_post_evaluation_kinematic_columns_reproduce_table_7_3():
    rows = [0, 19, 39]
    m = post_evaluate(table_7_2_designs()[rows])
    t = table("table_7_3")[rows]
    assert np.allclose(m["mu_v"], t[:, 4], atol=6e-4)  # eq. 6.8
    assert np.allclose(m["c_v"], t[:, 5], atol=2e-3)  # eq. 6.18
    # the seed's trend: the shortest design is the stiffest and has the highest frequency index
    assert m["S_f"][0] > m["S_f"][1] > m["S_f"][2]
    assert m["omega_n"][0] > m["omega_n"][1] > m["omega_n"][2]
    assert m["I_f"][0] < m["I_f"][1] < m["I_f"][2]


def test_post_evaluation_material_is_explicit_and_steel_reproduces_table_7_3_stiffness():
    """S_f = ||K_C1||_F of all 40 rows of Table 7.3 with structural steel tubes (the seed states only
    D = 20 mm, d = 10 mm, rho = 2000 kg/m^3), within what Table 7.2's rounding of the lengths to 0.1 mm
    allows: +-0.05 mm on each of three lengths, each entering a cantilever stiffness at most as l^-3."""
    links = EvaluationLinks(material=SEED_EVALUATION_MATERIAL)
    assert links.settings() == {"material": "structural steel", "D": 0.02, "d": 0.01, "density": 2000.0,
                                "passive_eliminated": True}
    assert EvaluationLinks().settings()["material"] == "M55J quasi-isotropic"
    m = post_evaluate(table_7_2_designs(), links=links)
    lengths = table("table_7_2")[:, 1:4]
    rounding = 3 * 3 * 0.05 / lengths.min(axis=1)
    assert np.all(np.abs(m["S_f"] / table("table_7_3")[:, 2] - 1.0) <= rounding)
    with pytest.raises(UserError):
        EvaluationLinks(material="unobtainium")
