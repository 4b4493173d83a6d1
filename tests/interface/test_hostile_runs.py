"""Hostile and careless input, round three (issue 33): special files and links in output places, altered
checkpoints, a scheduler that is not Dask, far targets, names a format cannot carry, designs that cannot be
evaluated, and messages that name the right thing.

Each case goes through the command line where a user meets it (exit status 2 and one ``error:`` line, or a run
that goes on and says what it did); the oracles are the file system (a pipe is still a pipe, nothing appears
outside the output folder) and a clean run of the same study and seed (the same bytes).
"""

from __future__ import annotations

import http.server
import json
import os
import stat
import threading
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from hapticdesign.errors import UserError
from hapticdesign.files import csv_cell, read_text, write_atomically
from hapticdesign.interface.cli import app
from hapticdesign.optimization.study_file import study_from_mapping
from hapticdesign.simulation import campaign
from tests.optimization.test_study_run import small_study

runner = CliRunner()
ROOT = Path(__file__).resolve().parents[2]
DEVICES = ROOT / "examples" / "devices"
FIVE_BAR = DEVICES / "five-bar.yaml"


def one_error(args: list, fragment: str) -> str:
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.strip().splitlines() if line]
    assert len(lines) == 1 and lines[0].startswith("error:"), result.output
    assert fragment in lines[0], lines[0]
    assert len(lines[0]) < 400, len(lines[0])
    return lines[0]


def files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def changed_study(tmp_path: Path, change) -> Path:
    path = small_study(tmp_path)
    data = yaml.safe_load(path.read_text())
    change(data)
    path.write_text(yaml.safe_dump(data, sort_keys=False, allow_unicode=True))
    return path


# --- data lost, escape: the writer and the folders under --out -------------------------------------------------

@pytest.mark.parametrize("args", [["export", "--device", str(FIVE_BAR), "--out"],
                                  ["designs", "--levels", "0", "--count", "2", "--out"]])
def test_an_output_that_is_a_named_pipe_is_refused_and_left_as_it_is(tmp_path, args):
    pipe = tmp_path / "p.xml"
    os.mkfifo(pipe)
    one_error([*args, pipe], "is a named pipe, not a regular file")
    assert stat.S_ISFIFO(os.lstat(pipe).st_mode)


def test_a_link_to_a_named_pipe_is_refused_and_a_link_to_a_file_is_replaced_not_followed(tmp_path):
    pipe, target, link = tmp_path / "pipe", tmp_path / "target.txt", tmp_path / "link.txt"
    os.mkfifo(pipe)
    (tmp_path / "to-pipe").symlink_to(pipe)
    with pytest.raises(UserError, match="named pipe"):
        write_atomically(tmp_path / "to-pipe", "x")
    target.write_text("kept")
    link.symlink_to(target)
    write_atomically(link, "new")
    assert target.read_text() == "kept" and not link.is_symlink() and link.read_text() == "new"


def test_a_planted_temporary_file_link_is_not_written_through(tmp_path):
    outside = tmp_path / "outside.txt"
    outside.write_text("kept")
    path = tmp_path / "out.txt"
    (tmp_path / f".out.txt.{os.getpid()}.tmp").symlink_to(outside)
    write_atomically(path, "new")
    assert outside.read_text() == "kept" and path.read_text() == "new"


def test_a_symlinked_checkpoint_folder_is_refused_and_nothing_is_written_through_it(tmp_path):
    study = small_study(tmp_path)
    out, outside = tmp_path / "out", tmp_path / "outside"
    out.mkdir()
    outside.mkdir()
    (out / "checkpoint").symlink_to(outside)
    one_error(["optimize", study, "--out", out], f"{out / 'checkpoint'} is a symbolic link")
    assert list(outside.iterdir()) == []


# --- silently wrong: checkpoints ---------------------------------------------------------------------------------

def _halved(data: dict) -> None:
    data["reduced"] = [[v / 2 for v in row] for row in data["reduced"]]


def _nan(data: dict) -> None:
    data["reduced"] = [[float("nan") for _ in row] for row in data["reduced"]]


def _strings(data: dict) -> None:
    data["reduced"] = [["x" for _ in row] for row in data["reduced"]]


def _not_a_list(data: dict) -> None:
    data["reduced"] = 3


@pytest.mark.parametrize("alter", [_halved, _nan, _strings, _not_a_list])
def test_an_altered_checkpoint_is_evaluated_again_and_the_run_says_so(tmp_path, alter):
    study = small_study(tmp_path)
    clean = runner.invoke(app, ["optimize", str(study), "--seed", "3", "--out", str(tmp_path / "clean")])
    assert clean.exit_code == 0, clean.output
    out = tmp_path / "out"
    assert runner.invoke(app, ["optimize", str(study), "--seed", "3", "--out", str(out)]).exit_code == 0
    path = out / "checkpoint" / "generation-0002.json"
    data = json.loads(path.read_text())
    alter(data)
    path.write_text(json.dumps(data))
    again = runner.invoke(app, ["optimize", str(study), "--seed", "3", "--out", str(out)])
    assert again.exit_code == 0, again.output
    assert f"checkpoint {path} is not trusted" in again.output and "generation 2 is evaluated again" in again.output
    assert "generation 1 " not in again.output  # the unaltered files are trusted
    assert files(out) == files(tmp_path / "clean")  # the front and every output as an unaltered run's


# --- silently wrong: names and values a format cannot carry -------------------------------------------------------

@pytest.mark.parametrize("name", ["a\\x01b", "a\\uFFFEb", "a\\uD800b"])
@pytest.mark.parametrize("command", [["export", "--out", "{tmp}/d.xml"], ["export", "--format", "urdf", "--out",
                                     "{tmp}/d.urdf"], ["spec", "--no-workspace", "--out", "{tmp}/spec"],
                                     ["ik", "--position", "0,0,0.18"]])
def test_names_xml_and_utf8_cannot_carry_are_refused_when_read(tmp_path, name, command):
    text = FIVE_BAR.read_text().replace("name: five-bar", f'name: "{name}"', 1)
    device = tmp_path / "device.yaml"
    device.write_text(text)
    one_error([*(c.format(tmp=tmp_path) for c in command), "--device", device], "which no text of a data file may hold")
    assert not list(tmp_path.glob("d.*")) and not (tmp_path / "spec").exists()


def test_a_keep_filter_without_a_bound_is_refused():
    data = yaml.safe_load((ROOT / "examples" / "studies" / "five-bar-geometry.yaml").read_text())
    data["keep"] = [{"formula": "l1 + l2"}]
    with pytest.raises(UserError, match=r"keep\[0\]: a bound is needed"):
        study_from_mapping(data)


def test_maps_without_an_index_is_refused(tmp_path):
    one_error(["maps", "--device", FIVE_BAR, "--size", "0.02,0,0.02", "--index", "", "--out", tmp_path / "m"],
              "--index: give at least one design index")


@pytest.mark.parametrize("name", ['=HYPERLINK("http://x")', "+cmd", "-l1", "@SUM(A1)"])
def test_csv_cells_a_spreadsheet_would_run_are_written_as_text(tmp_path, name):
    study = changed_study(tmp_path, lambda d: d["objectives"][1].update(name=name))
    result = runner.invoke(app, ["optimize", str(study), "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    for table in ("front.csv", "evaluations.csv"):
        header = (tmp_path / "out" / table).read_text().splitlines()[0]
        assert name not in header.replace(f"'{name}", "").replace(f"'{name}".replace('"', '""'), "")
        assert f"'{name[:2]}" in header


def test_numbers_stay_numbers_in_csv_cells():
    assert [csv_cell(v) for v in ("-0.5", "+1e-3", "-inf", "l1", 2.0)] == ["-0.5", "+1e-3", "-inf", "l1", 2.0]
    assert csv_cell("-l1 + l2") == "'-l1 + l2"


# --- hang: a scheduler that is not Dask ----------------------------------------------------------------------------

class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


@pytest.fixture
def web_server():
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Quiet)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"tcp://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def test_a_scheduler_address_at_a_web_server_is_refused_in_one_line(tmp_path, web_server, monkeypatch):
    monkeypatch.setattr(campaign, "SCHEDULER_ANSWER_SECONDS", 1.0)
    one_error(["optimize", small_study(tmp_path), "--scheduler", web_server],
              f"the service at {web_server} did not answer as a Dask scheduler within 1 s")


def test_a_service_that_greets_with_other_bytes_is_refused():
    import socket

    listener = socket.create_server(("127.0.0.1", 0))
    port = listener.getsockname()[1]

    def greet() -> None:
        conn, _ = listener.accept()
        with conn:
            conn.sendall(b"SSH-2.0-OpenSSH_9.6\r\n")  # read as Dask's frame length: about 3.6e18 bytes

    thread = threading.Thread(target=greet, daemon=True)
    thread.start()
    with pytest.raises(UserError, match="did not answer as a Dask scheduler"):
        campaign.check_dask_answers(f"127.0.0.1:{port}", seconds=5.0)
    thread.join()
    listener.close()


# --- tracebacks: far targets and other readers ------------------------------------------------------------------

def test_far_targets_are_refused_at_the_readers_of_positions(tmp_path):
    limit = "a handle position is 3 finite numbers within +-1000 m"
    one_error(["ik", "--device", FIVE_BAR, "--position", "1e308,0,0.18"], limit)
    one_error(["maps", "--device", FIVE_BAR, "--size", "1e308,0,1e308", "--out", tmp_path / "m"], limit)
    far_home = tmp_path / "far-home.yaml"
    far_home.write_text(FIVE_BAR.read_text().replace("home: {q1: 2.0, q2: 1.1}", "home: {position: [1e308, 0, 0.18]}"))
    one_error(["ik", "--device", far_home, "--position", "0,0,0.18"], f"home.position: {limit}")
    study = changed_study(tmp_path, lambda d: d["workspace"]["box"].update(center=[1e308, 0.0, 0.1]))
    one_error(["optimize", study], f"workspace: {limit}")


@pytest.mark.parametrize("change, fragment", [
    (lambda d: d.update(device="arm\0.yaml"), "'arm\\x00.yaml' holds the character U+0000"),
    (lambda d: d.update(device=["arm.yaml"]), "device: Input should be a valid string"),
    (lambda d: d["objectives"].append({"name": "k", "index": "kmax", "options": {"period": 1e308}, "reduce": "min",
                                       "sense": "max"}), "the sample period is a positive number of seconds, at most 1 s"),
    (lambda d: d["variables"].update({"k" * 100_000: [0.0, 1.0]}), "unknown design variable 'kkkk"),
])
def test_study_files_of_careless_values_are_one_line(tmp_path, change, fragment):
    one_error(["optimize", changed_study(tmp_path, change)], fragment)


def test_a_study_whose_device_file_is_a_list_is_one_line(tmp_path):
    study = small_study(tmp_path)
    (tmp_path / "arm.yaml").write_text("- a\n- b\n")
    one_error(["optimize", study], "arm.yaml: expected a mapping (name: value) at the top level")


def test_a_file_name_with_a_nul_byte_is_one_line():
    with pytest.raises(UserError, match="a file name holds no NUL character"):
        read_text("arm\0.yaml", "device file")


def test_a_selection_of_a_digit_that_is_not_a_number_is_one_line(tmp_path):
    one_error(["optimize", small_study(tmp_path), "--select", "²"], "--select: expected rms")


# --- a study that cannot run: designs that cannot be evaluated ------------------------------------------------------

def _rcube_study(tmp_path: Path) -> Path:
    """The example's R-CUBE synthesis with constraint C2 alone, a short run, and its first run's l2 bounds wider than
    the variable's (down to -0.5 m)."""
    data = yaml.safe_load((ROOT / "examples" / "studies" / "rcube-synthesis.yaml").read_text())
    data["device"] = str(DEVICES / "rcube.yaml")
    data["constraints"] = [c for c in data["constraints"] if c["options"]["point"] == "C2"]
    data.pop("keep")
    algorithm = data["algorithm"]
    algorithm.update(population=8, generations=2, start={**algorithm["start"], "starts": 2})
    algorithm["runs"][0]["l2"] = [-0.5, 0.5]
    path = tmp_path / "rcube.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_designs_that_cannot_be_evaluated_are_infeasible_with_their_reason(tmp_path):
    """Run bounds wider than the variable's let l2 go negative; the R-CUBE's constraint C2 alone lets designs
    through whose passive links miss a point: both are infeasible rows of evaluations.csv, the study goes on."""
    study = _rcube_study(tmp_path)
    result = runner.invoke(app, ["optimize", str(study), "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    rows = (tmp_path / "out" / "evaluations.csv").read_text()
    assert "l2 must be a positive length of at most 1000 m, got -" in rows
    assert "is unreachable by the passive links" in rows


# --- messages --------------------------------------------------------------------------------------------------------

def test_keep_removing_every_design_says_so(tmp_path):
    study = changed_study(tmp_path, lambda d: d.update(keep=[{"formula": "l2", "<=": 0.01}]))
    one_error(["optimize", study], "designs meet the constraints, but the keep filters remove every one; the "
                                   "closest (")


def test_a_formula_that_is_nan_is_named(tmp_path):
    data = yaml.safe_load((ROOT / "examples" / "studies" / "rcube-synthesis.yaml").read_text())
    data["device"] = str(DEVICES / "rcube.yaml")
    data["parameters"]["l1"] = "sqrt(-1 - q_max)"
    path = tmp_path / "nan.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    one_error(["optimize", path], "parameters.l1: 'sqrt(-1 - q_max)' is nan")


def test_an_option_given_nan_is_named_as_not_a_number():
    one_error(["spec", "--device", FIVE_BAR, "--rate", "nan"], "'--rate': 'nan' is not a number")


def test_an_overflowing_rotor_inertia_names_its_actuator(tmp_path):
    device = tmp_path / "motors.yaml"
    text = (DEVICES / "phantom-3dof-motors.yaml").read_text()
    device.write_text(text.replace("rotor_inertia: 1.08e-6, gear_ratio: 13.3", "rotor_inertia: 1e308, gear_ratio: 13.3"))
    one_error(["dynamics", "--device", device, "--q", "0,0,0"], "actuators[0]: the actuator of theta1: rotor_inertia")


def test_rcube_tolerance_names_an_output_place_it_cannot_use_before_any_note(tmp_path):
    place = tmp_path / "a-file"
    place.write_text("")
    one_error(["rcube", "tolerance", "--samples", "2", "--grid", "2", "--out", place], f"{place} is not a folder")


def test_a_long_key_is_cut_in_the_message(tmp_path):
    study = changed_study(tmp_path, lambda d: d["objectives"][0].update({"k" * 100_000: 1}))
    line = one_error(["optimize", study], "objectives[0].'kkk")
    assert len(line) < 200


def test_keep_with_both_sides_unbounded_is_one_line(tmp_path):
    study = changed_study(tmp_path, lambda d: d.update(keep=[{"formula": "l2", "<=": None}]))
    one_error(["optimize", study], "a bound is needed")



@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_rcube_tolerance_names_a_read_only_output_folder_before_any_note(tmp_path):
    place = tmp_path / "read-only"
    place.mkdir()
    place.chmod(0o555)
    one_error(["rcube", "tolerance", "--samples", "2", "--grid", "2", "--out", place], f"cannot write into {place}")
