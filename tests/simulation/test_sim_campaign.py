"""Campaigns: design-file checks, a Dask LocalCluster run, resumption, tables and figures."""

import csv
import json
from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app
from hapticdesign.simulation.campaign import CampaignOptions, read_designs, run_campaign
from hapticdesign.simulation.paths import Chirp
from tests.helpers.sim_designs import write_designs

pytestmark = pytest.mark.slow  # end to end: deselect with -m "not slow"

QUICK = CampaignOptions(k_limit=60, chirp=Chirp(0.3, 0.1, 6.0, 10.0), duration=3.0)


def test_design_file_errors(tmp_path):
    with pytest.raises(UserError, match="missing columns ln_H"):
        read_designs(write_designs(tmp_path / "a.csv", drop="ln_H"))
    with pytest.raises(UserError, match="missing columns Ixy3a"):
        read_designs(write_designs(tmp_path / "b.csv", drop="Ixy3a"))
    with pytest.raises(UserError, match="row 1"):
        read_designs(write_designs(tmp_path / "c.csv", edit={"m2": -0.1}))
    result = CliRunner().invoke(app, ["campaign", "--designs", str(tmp_path / "a.csv"), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2 and "missing columns" in result.output


@pytest.fixture(scope="module")
def cluster():
    from hapticdesign.simulation.campaign import local_cluster

    with local_cluster(2) as c:
        yield c


def test_campaign_on_local_cluster_resumes_and_summarizes(tmp_path, cluster):
    designs = write_designs(tmp_path / "designs.csv")
    out = tmp_path / "out"
    first = run_campaign(designs, out, QUICK, scheduler=cluster.scheduler_address)
    assert first == {"cases": 16, "run": 16, "skipped": 0}
    before = (out / "results.csv").read_text()
    (out / "cases" / "x2__impedance__type2.json").unlink()
    second = run_campaign(designs, out, QUICK, scheduler=cluster.scheduler_address)
    assert second == {"cases": 16, "run": 1, "skipped": 15}
    assert (out / "results.csv").read_text() == before  # deterministic: same numbers after resuming
    rows = list(csv.DictReader((out / "results.csv").open()))
    k1 = {r["design"]: float(r["k_max_type1"]) for r in rows}
    # the LN = 0 design gives the same result in both types (seed §4.1.4.2), and K_max < b^2 / H11
    assert rows[0]["k_max_type1"] == rows[0]["k_max_type2"]
    assert rows[0]["bandwidth_hz_type1"] == rows[0]["bandwidth_hz_type2"]
    assert k1["x0"] < 0.25 / 0.039031 < k1["x0"] + 1
    summary = list(csv.DictReader((out / "summary.csv").open()))
    level0 = [r for r in summary if r["level"] == "0.0" and r["criterion"] == "impedance"]
    assert float(level0[0]["agreement_share"]) == 1.0
    values = [k1["x0"], k1["x1"]]
    assert float(level0[0]["mean"]) == pytest.approx(np.mean(values))
    for name in ("impedance_beeswarm_type1", "impedance_type1_vs_type2", "transparency_agreement",
                 "transparency_frequency_response"):
        assert (out / "figures" / f"{name}.png").stat().st_size > 1000
        assert (out / "figures" / f"{name}.svg").exists()
    case = json.loads((out / "cases" / "x0__transparency__type1.json").read_text())
    assert case["bandwidth_hz"] == pytest.approx(4 / (2 * np.pi * 0.5), rel=0.05)
    with pytest.raises(UserError, match="other designs or settings"):
        run_campaign(designs, out, CampaignOptions(k_limit=10), scheduler=cluster.scheduler_address)


def test_analytic_campaign_equals_the_simulated_one_where_exact(tmp_path, cluster):
    """``method="analytic"``: no loop is run; on the LN = 0 designs (x0, x1) both criteria equal the
    simulated campaign's in both types, every type-1 case too (joint 1: exact for any design), and every
    impedance case of type 2 (joint 1's loop along the driven motion is linear time-varying, exactly)."""
    designs = write_designs(tmp_path / "designs.csv")
    simulated, analytic = tmp_path / "sim", tmp_path / "an"
    run_campaign(designs, simulated, QUICK, scheduler=cluster.scheduler_address)
    run_campaign(designs, analytic, replace(QUICK, method="analytic"), scheduler=cluster.scheduler_address)
    for design in ("x0", "x1", "x2", "x3"):
        for criterion in ("impedance", "transparency"):
            for sim_type in (1, 2) if design in ("x0", "x1") or criterion == "impedance" else (1,):
                name = f"{design}__{criterion}__type{sim_type}.json"
                a, s = (json.loads((out / "cases" / name).read_text()) for out in (analytic, simulated))
                assert a["method"] == "analytic" and a["value"] == pytest.approx(s["value"], abs=1e-6)
    case = json.loads((analytic / "cases" / "x2__transparency__type2.json").read_text())
    assert case["analytic_exact"] is False and case["steady_bandwidth_hz"] > 0


def test_realistic_conditions_reach_every_case(tmp_path, cluster):
    """``CampaignOptions(conditions=...)``: delay and per-group modelling error with seeded signs apply to
    every case. Each case equals the engine called directly under the same conditions, and a sample of
    delay lowers every stable range (the Z-width shrinks with delay, Gil et al. 2004)."""
    from hapticdesign.devices.registry import preset
    from hapticdesign.analysis.sampled_loop import SampledLoop
    from hapticdesign.simulation.config import Compensator, LoopConfig
    from hapticdesign.simulation.impedance import impedance_range

    designs = write_designs(tmp_path / "designs.csv")
    conditions = LoopConfig(loop=SampledLoop.seed(delay=1),
                            compensator=Compensator(group_errors=(("mass", 5.0), ("inertia", 5.0)), error_seed=3))
    real = replace(QUICK, method="analytic", conditions=conditions)
    run_campaign(designs, tmp_path / "real", real, scheduler=cluster.scheduler_address)
    run_campaign(designs, tmp_path / "ideal", replace(QUICK, method="analytic"), scheduler=cluster.scheduler_address)
    for d in read_designs(designs):
        device = preset("phantom-3dof").with_params(d.params)
        for sim_type in (1, 2):
            name = f"{d.name}__impedance__type{sim_type}.json"
            got, ideal = (json.loads((tmp_path / run / "cases" / name).read_text()) for run in ("real", "ideal"))
            direct = impedance_range(device, sim_type, config=replace(conditions, duration=QUICK.duration),
                                     k_limit=QUICK.k_limit, method="analytic")
            assert got["value"] == direct.k_max
            assert got["value"] < ideal["value"]
    with pytest.raises(UserError, match="no encoder quantization"):
        CampaignOptions(method="analytic", conditions=LoopConfig(counts=4096))


def test_campaign_command_takes_the_conditions(tmp_path):
    designs = write_designs(tmp_path / "designs.csv")
    bad = CliRunner().invoke(app, ["campaign", "--designs", str(designs), "--out", str(tmp_path / "o"),
                                   "--group-errors", "masses=5"])
    assert bad.exit_code == 2 and "unknown error group 'masses'" in bad.output
    bad = CliRunner().invoke(app, ["campaign", "--designs", str(designs), "--out", str(tmp_path / "o"),
                                   "--method", "analytic", "--coulomb", "0.01,0.01,0.01"])
    assert bad.exit_code == 2 and "no Coulomb friction" in bad.output
