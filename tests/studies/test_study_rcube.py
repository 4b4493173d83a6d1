"""The ``rcube`` study (seed 001) in its smallest form: the seed's numbers beside ours, maps, optimization."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from hapticdesign.studies import rcube

# end to end: deselect with -m "not slow"; one xdist worker takes every test of the shared smoke studies
# (`make test` runs --dist loadgroup), so that the other worker is not left waiting on their lock
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("smoke-studies")]


def _rows(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_every_step_finished(rcube_study):
    out, summary = rcube_study
    assert {k: v["status"] for k, v in summary["steps"].items()} == {s.key: "done" for s in rcube.steps()}
    html = (out / "report.html").read_text()
    assert all(f'id="{s.key}"' in html for s in rcube.steps())


def test_final_design_against_the_seed(rcube_study):
    _, summary = rcube_study
    n = summary["numbers"]
    assert n["kinematics"]["q_max_deg"] == pytest.approx(32.5, abs=0.05)  # Table 7.2
    assert n["kinematics"]["dexterous_cube"] is True
    assert n["kinematics"]["ik_fk_max_error_m"] < 1e-12
    assert n["final_design"]["link_mass_g"] == pytest.approx(77.7, abs=0.1)  # Table 7.9
    assert n["final_design"]["max_deflection_mm_locked"] < 0.07  # Table 7.9, with the locked K_C*
    m_c = np.array(n["final_design"]["M_C"])
    assert np.allclose(m_c, m_c.T) and np.all(np.linalg.eigvalsh(m_c) > 0)
    assert m_c[0, 0] == pytest.approx(m_c[1, 1]) == pytest.approx(m_c[2, 2])  # eq. 7.6 structure
    k_c = np.array(n["final_design"]["K_C_seed_evaluation"])  # eq. 7.7: 209110, 727, 6495
    assert k_c[0, 0] == pytest.approx(209110, rel=0.01)
    assert k_c[3, 3] == pytest.approx(727, rel=0.01)
    assert k_c[0, 5] == pytest.approx(6495, rel=0.01)


def test_table_7_3_columns_reproduce(rcube_study):
    out, _ = rcube_study
    rows = _rows(out / "tables" / "kinematics_table_7_3.csv")
    assert [r["solution"] for r in rows] == ["1", "20", "40"]
    for r in rows:
        assert float(r["mu_v ours"]) == pytest.approx(float(r["mu_v seed"]), abs=6e-4)
        assert float(r["c_v ours"]) == pytest.approx(float(r["c_v seed"]), abs=6e-4)


def test_maps_and_optimization_files(rcube_study):
    out, summary = rcube_study
    for name in rcube.MAP_METRICS:
        assert (out / "figures" / f"maps_map_{name}.png").stat().st_size > 0
        assert (out / "figures" / f"maps_map_{name}.svg").stat().st_size > 0
    front = _rows(out / "tables" / "optimization_table_7_2_front.csv")
    assert len(front) == summary["numbers"]["optimization"]["front_size"] > 0
    assert all(float(r["total [mm]"]) < 400 for r in front)  # seed §7.1: kept solutions below 400 mm
    selected = summary["numbers"]["optimization"]["selected"]
    assert selected["l1"] + selected["l2"] + selected["l3"] < 0.4
    assert 0 < summary["numbers"]["optimization"]["ratio"] < 1
