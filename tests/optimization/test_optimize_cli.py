"""``hapticdesign optimize``: outputs, --json, byte-identical reruns, a Dask cluster, bad input in one line.

Oracles: the files of a second run with the same seed (same bytes), the run in one process (for the cluster),
the other commands that must read ``selected.yaml`` and the device built from the design space at the same
values (same mass matrix), and the escaping of a hostile name.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.analysis.view.skeleton import home_pose
from hapticdesign.devices.design_space import design_space
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.interface.cli import app
from tests.optimization.test_study_run import ISOTROPY, MASS, point, small_study, write_study

runner = CliRunner()
OUTPUTS = ("front.csv", "evaluations.csv", "pareto.png", "pareto.svg", "report.html", "selected.yaml")


def optimize(*args):
    return runner.invoke(app, ["optimize", *map(str, args)])


def files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_the_csv_headers_carry_each_quantitys_unit_and_every_other_row_is_numbers(tmp_path):
    """front.csv and evaluations.csv: one header row, ``name [unit]`` (the device file's length in m, a gear ratio in
    1, the objectives' indices' units, an expression constraint in its variable's unit), then numbers only."""
    import csv

    study = small_study(tmp_path)
    assert optimize(study, "--seed", 2, "--out", tmp_path / "out", "--quiet").exit_code == 0
    quantities = ["l2 [m]", "actuators.q2.gear_ratio [1]", "iso [1]", "mass [kg]", "l2 [m]"]
    with open(tmp_path / "out" / "front.csv", newline="") as handle:
        header, *rows = list(csv.reader(handle))
    assert header == ["design", *quantities] and rows
    assert all(math.isfinite(float(cell)) for row in rows for cell in row)
    with open(tmp_path / "out" / "evaluations.csv", newline="") as handle:
        header = next(csv.reader(handle))
    assert header == ["evaluation", "generation", *quantities, "feasible", "reason"]
    page = (tmp_path / "out" / "report.html").read_text()
    assert "<th>l2 [m]</th>" in page and "<th>mass [kg]</th>" in page


def test_outputs_json_and_the_same_bytes_for_the_same_seed(tmp_path):
    study = small_study(tmp_path)
    first = optimize(study, "--seed", 7, "--out", tmp_path / "a", "--json")
    assert first.exit_code == 0, first.output
    summary = json.loads(first.stdout)
    assert set(summary) == {"front", "evaluations", "selected"}
    assert summary["evaluations"] == len((tmp_path / "a" / "evaluations.csv").read_text().splitlines()) - 1
    for design in summary["front"]:
        assert set(design["variables"]) == {"l2", "actuators.q2.gear_ratio"}
        assert set(design["objectives"]) == {"iso", "mass"}
        assert 0.0 < design["objectives"]["iso"] <= 1.0 and design["objectives"]["mass"] > 0.0
        assert design["variables"]["l2"] <= 0.25
    assert summary["selected"]["rule"].startswith("least RMS")
    assert all((tmp_path / "a" / name).is_file() for name in OUTPUTS)
    page = (tmp_path / "a" / "report.html").read_text()
    assert "The selected design at the workspace centre" in page and "indices at the workspace points" in page
    second = optimize(study, "--seed", 7, "--out", tmp_path / "b", "--json")
    assert second.stdout == first.stdout
    assert files(tmp_path / "a") == files(tmp_path / "b")
    again = optimize(study, "--seed", 7, "--out", tmp_path / "a", "--json")  # a finished run replays its checkpoint
    assert again.stdout == first.stdout and files(tmp_path / "a") == files(tmp_path / "b")


def test_selected_yaml_is_a_device_file_that_other_commands_read(tmp_path):
    study = small_study(tmp_path)
    res = optimize(study, "--seed", 1, "--out", tmp_path / "out", "--json", "--select", "iso=1,mass=0")
    assert res.exit_code == 0, res.output
    selected = json.loads(res.stdout)["selected"]
    path = tmp_path / "out" / "selected.yaml"
    device = load_device_file(path)
    expected = design_space(yaml.safe_load((tmp_path / "arm.yaml").read_text()), selected["variables"]).device(
        selected["variables"])
    q = home_pose(device)
    assert np.array_equal(mass_matrix(device, q), mass_matrix(expected, q))
    for command in (["dynamics", "--device", str(path), "--q", "0.1,0.2", "--json"],
                    ["metrics", "--device", str(path), "--q", "0.1,0.2", "--json"]):
        out = runner.invoke(app, command)
        assert out.exit_code == 0, (command, out.output)
    assert selected["objectives"]["iso"] == max(d["objectives"]["iso"] for d in json.loads(res.stdout)["front"])


def test_the_report_escapes_user_strings(tmp_path):
    hostile = "<script>alert(1)</script>"
    path = write_study(tmp_path, {"l2": [0.12, 0.16]}, [dict(ISOTROPY, name=hostile), MASS], population=4,
                       generations=1, center=point(0.14))
    res = optimize(path, "--seed", 1, "--out", tmp_path / "out")
    assert res.exit_code == 0, res.output
    page = (tmp_path / "out" / "report.html").read_text()
    assert hostile not in page and "&lt;script&gt;alert(1)&lt;/script&gt;" in page


def test_a_dask_cluster_gives_the_same_front(tmp_path):
    from hapticdesign.simulation.campaign import local_cluster

    study = small_study(tmp_path)
    local = optimize(study, "--seed", 2, "--out", tmp_path / "local")
    assert local.exit_code == 0, local.output
    with local_cluster(1, processes=False) as cluster:
        remote = optimize(study, "--seed", 2, "--out", tmp_path / "remote", "--scheduler", cluster.scheduler_address)
    assert remote.exit_code == 0, remote.output
    for name in ("front.csv", "evaluations.csv", "selected.yaml"):
        assert (tmp_path / "local" / name).read_bytes() == (tmp_path / "remote" / name).read_bytes()


def _error(args, message: str, out: Path | None = None) -> None:
    res = optimize(*args)
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], res.stderr
    assert "Traceback" not in res.output
    if out is not None:
        assert not any(out.glob("*.csv")) and not (out / "report.html").exists()


def _changed(tmp_path: Path, change) -> Path:
    path = small_study(tmp_path)
    data = yaml.safe_load(path.read_text())
    change(data)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.mark.parametrize("change, message", [
    (lambda d: d["variables"].update(l9=[0.1, 0.2]), "unknown design variable 'l9'"),
    (lambda d: d["variables"].update({"links.nothing.D": [0.01, 0.02]}), "has no link 'nothing'"),
    (lambda d: d["objectives"][0].update(index="beauty"), "unknown index 'beauty'"),
    (lambda d: d["variables"].update(l2=[0.3, 0.1]), "bounds need low < high"),
    (lambda d: d["variables"].update(l2=[float("nan"), 0.1]), "expected a finite number"),
    (lambda d: d["workspace"].update(grid=1) or d["workspace"]["box"].update(size=[0.02, 0, 0.02]), "grid must be at least 2"),
    (lambda d: d.update(device="missing.yaml"), "cannot read device file"),
    (lambda d: d["objectives"][0].update(options={"speed": 1}), "index isotropy: unknown option 'speed'"),
    (lambda d: d["constraints"].append({"index": "kmax", "reduce": "min", ">=": 100.0, "options": {"period": -1.0}}),
     "index kmax: the sample period is a positive number of seconds"),
])
def test_bad_studies_are_one_line(tmp_path, change, message):
    out = tmp_path / "out"
    _error([_changed(tmp_path, change), "--seed", 1, "--out", out], message, out)
    assert not out.exists()


def test_work_above_the_limit_is_refused(tmp_path):
    path = _changed(tmp_path, lambda d: d["algorithm"].update(population=1000, generations=1000))
    _error([path, "--seed", 1, "--out", tmp_path / "out"], "above the limit of")


def test_a_workspace_no_design_reaches_names_the_closest_design(tmp_path):
    far = [3.0 * math.cos(0.7), 0.0, 3.0 * math.sin(0.7)]  # 3 m: beyond any l1 + l2 <= 0.5 m
    path = write_study(tmp_path, {"l2": [0.12, 0.3]}, [ISOTROPY], population=4, generations=2, center=far)
    _error([path, "--seed", 1, "--out", tmp_path / "out"], "no design of 8 reaches the whole workspace; the closest (l2 = ")


@pytest.mark.parametrize("select, message", [("9", "the front has designs 1 to"), ("speed=1", "no objective named 'speed'"),
                                             ("iso=-1", "--select: expected rms")])
def test_bad_selection_is_one_line(tmp_path, select, message):
    _error([small_study(tmp_path), "--seed", 1, "--select", select], message)


@pytest.mark.parametrize("select, message", [("0", "front design 0: a front design is numbered from 1"),
                                             ("999999", "the study evaluates at most"),
                                             ("nope=1", "no objective named 'nope'")])
def test_a_bad_selection_is_refused_before_any_design_is_evaluated(tmp_path, select, message):
    out = tmp_path / "out"
    _error([small_study(tmp_path), "--seed", 1, "--out", out, "--select", select], message, out)
    assert not (out / "checkpoint").exists()  # no generation was evaluated


def test_another_study_in_the_same_folder_is_refused(tmp_path):
    study = small_study(tmp_path)
    assert optimize(study, "--seed", 1, "--out", tmp_path / "out").exit_code == 0
    _error([study, "--seed", 2, "--out", tmp_path / "out"], "holds a run of another study or seed")


def test_the_selected_designs_sheet_is_taken_where_the_study_evaluated_it(tmp_path):
    """Issue 35: selected.yaml names the point where the selected design has its weakest wall over the study's
    points, and ``spec`` at that pose (one design, one pose, every direction searched) gives the study's batched
    ``kmax`` objective there; a sheet at home, outside the study's box, would read another pose's wall."""
    wall = {"name": "wall", "index": "kmax", "reduce": "min", "sense": "max"}
    study = write_study(tmp_path, {"l2": [0.09, 0.3], "actuators.q2.gear_ratio": {"values": [4.0, 8.0, 16.0]}},
                        [ISOTROPY, wall], population=8, generations=3, center=point(0.15), size=(0.03, 0.0, 0.03),
                        grid=3)
    arm = yaml.safe_load((tmp_path / "arm.yaml").read_text())
    arm["joints"] = [{"name": "q1", "damping": 0.002}, {"name": "q2", "damping": 0.003}]  # a wall needs damping
    del arm["links"]  # a rigid arm: its thin links behind undamped rotors leave no stable wall (RIGID_LINKS)
    (tmp_path / "arm.yaml").write_text(yaml.safe_dump(arm))
    res = optimize(study, "--seed", 2, "--out", tmp_path / "out", "--json")
    assert res.exit_code == 0, res.output
    weakest = json.loads(res.stdout)["selected"]["objectives"]["wall"]
    assert weakest > 1.0
    selected = tmp_path / "out" / "selected.yaml"
    line, = [t for t in selected.read_text().splitlines() if t.startswith("# min kmax over the study's points")]
    assert float(line.split(" = ")[1].split()[0]) == pytest.approx(weakest, rel=1e-5)
    q = line.rsplit("--q ", 1)[1]
    sheet = runner.invoke(app, ["spec", "--device", str(selected), "--q", q, "--json", "--no-simulate",
                                "--no-workspace"])
    assert sheet.exit_code == 0, sheet.output
    assert json.loads(sheet.stdout)["renderable_stiffness"]["exact"] == pytest.approx(weakest, rel=1e-6)


def _wall_study(tmp_path: Path, variables: dict, wall: float, damping: float) -> Path:
    """The planar arm with ``damping`` (N m s/rad) on both joints, a study of ``variables`` for the least apparent
    mass under ``min_kmax >= wall`` (1 kHz, one sample of delay), at one point."""
    path = write_study(tmp_path, variables, [MASS], population=4, generations=2,
                       constraints=[{"index": "kmax", "reduce": "min", ">=": wall}])
    arm = yaml.safe_load((tmp_path / "arm.yaml").read_text())
    for joint in arm["joints"]:
        joint["damping"] = damping
    del arm["links"]  # RIGID_LINKS
    (tmp_path / "arm.yaml").write_text(yaml.safe_dump(arm))
    return path


RIGID_LINKS = """The wall tests take the planar arm without its links' sections: with them the wall's loop has the links'
compliance between the rotors (1e-6 and 2e-6 kg m^2, no motor damping) and the handle, a drive resonance the joint
damping barely damps, and no spring is stable (``spec`` of the arm with 0.01 N m s/rad per joint: exact 0 N/m with its
links, 328.2 N/m without;
docs/simulation.md, *The links' own compliance*). These tests are about the walls' warnings and poses, not that."""


MOTOR_TORQUE = {"actuators.q1.torque_continuous": [0.02, 0.05]}


@pytest.mark.parametrize("damping, wall", [(0.0, 1.0), (0.01, 1e6)])
def test_a_wall_no_design_can_render_is_a_warning_before_the_run(tmp_path, damping, wall):
    """A variable kmax does not read (a motor's continuous torque) leaves every design with the device file's wall
    limit: without damping no sampled spring is stable (the passivity bound 2b/T is 0), and with 0.01 N m s/rad
    per joint 1e6 N/m is thousands of times the handle's damping scale b / (l^2 T) = 0.01 / (0.2^2 1e-3) =
    250 N/m. The
    warning comes before the run, whose empty front then names the constraint."""
    res = optimize(_wall_study(tmp_path, MOTOR_TORQUE, wall, damping), "--seed", 1)
    assert res.exit_code == 2, res.output
    lines = [line for line in res.stderr.strip().splitlines() if not line.startswith("generations: ")]  # progress
    assert len(lines) == 2 and "Traceback" not in res.output, res.stderr
    assert res.stderr.startswith(f"warning: study.yaml: no design can meet min_kmax >= {wall:g} N/m: every design's")
    assert lines[1].startswith("error: no design of 8 meets the constraints") and "min_kmax" in lines[1]


def test_a_wall_within_reach_or_a_study_of_the_geometry_has_no_warning(tmp_path):
    """Below the device's wall limit nothing is said; nor when a variable changes the geometry (the handle's
    damping and mass follow it, so no bound holds for every design before the run)."""
    low = optimize(_wall_study(tmp_path, MOTOR_TORQUE, 1.0, 0.01), "--seed", 1)
    assert low.exit_code == 0 and "warning" not in low.stderr, low.output
    geometry = optimize(_wall_study(tmp_path, {"l2": [0.1, 0.3]}, 1e6, 0.01), "--seed", 1)
    assert geometry.exit_code == 2 and "warning" not in geometry.stderr and "meets the constraints" in geometry.stderr



DRIVES = {"rigid": (False, False), "links": (True, False), "transmissions": (False, True),
          "transmissions and links": (True, True)}
"""What the planar arm's device file holds, by the drive it makes (the oracle): (its links' sections, its actuators'
transmission_stiffness, 3000 N m/rad each)."""


@pytest.mark.parametrize("drive", DRIVES)
def test_a_study_of_kmax_says_which_compliance_its_drive_includes(tmp_path, drive):
    """Issue 41: a study reporting kmax says once which compliance between the motors and the handle it took, as the
    device file's fields decide it (links with sections, actuators with transmission_stiffness, neither: rigid): in
    --json, the text answer, selected.yaml, the report's study section and the explorer's objective; a study without
    kmax says nothing of it."""
    wall = {"name": "wall", "index": "kmax", "reduce": "min", "sense": "max"}
    study = write_study(tmp_path, {"l2": [0.09, 0.3]}, [ISOTROPY, wall], population=4, generations=2,
                        center=point(0.15))
    arm = yaml.safe_load((tmp_path / "arm.yaml").read_text())
    arm["joints"] = [{"name": "q1", "damping": 0.002}, {"name": "q2", "damping": 0.003}]
    links, transmissions = DRIVES[drive]
    if not links:
        del arm["links"]
    for actuator in arm["actuators"] if transmissions else []:
        actuator["transmission_stiffness"] = 3000.0
    (tmp_path / "arm.yaml").write_text(yaml.safe_dump(arm))
    res = optimize(study, "--seed", 1, "--out", tmp_path / "out", "--json")
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["compliance"] == {"kmax": drive}
    line = f"kmax: drive compliance: {drive}"
    text = optimize(study, "--seed", 1, "--out", tmp_path / "out", "--quiet")
    assert text.exit_code == 0 and text.stdout.splitlines().count(line) == 1, text.output
    assert f"# {line}\n" in (tmp_path / "out" / "selected.yaml").read_text()
    page = (tmp_path / "out" / "report.html").read_text()
    assert page.count(f'<p id="compliance">{line} (') == 1
    data = json.loads(page.split('id="explorer-data">', 1)[1].split("</script>", 1)[0])
    assert data["objectives"][1]["about"].endswith(f"; drive compliance: {drive}")
    (tmp_path / "plain").mkdir()
    plain = write_study(tmp_path / "plain", {"l2": [0.09, 0.3]}, [ISOTROPY], population=4, generations=2,
                        center=point(0.15))
    other = optimize(plain, "--seed", 1, "--json")
    assert other.exit_code == 0 and "compliance" not in json.loads(other.stdout), other.output
