"""``hapticdesign explore OUT`` serves a study's output folder read-only on 127.0.0.1 and computes the card of any
evaluated design: only files inside OUT are answered (a ``..`` path, an absolute path, a link out and another host
are refused); the card of a design off the front carries the numbers of its row of evaluations.csv and maps that
reduce to them; a folder that is not a study's output, a port in use and a tampered front.csv are one line and exit
status 2, with nothing written; Ctrl-C stops the server cleanly.

Oracles: the files the run wrote (evaluations.csv, front.csv, report.html), read here with the csv module and as
bytes, and the file outside OUT that must never be answered.
"""

from __future__ import annotations

import csv
import http.client
import json
import math
import os
import signal
import socket
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app
from hapticdesign.interface.commands.explore_adapter import StudyFolder, server
from hapticdesign.optimization.study_outputs import without_unit
from tests.optimization.test_study_run import ISOTROPY, MASS, point, write_study

runner = CliRunner()
VARIABLES = {"l1": [0.15, 0.25], "l2": [0.1, 0.2]}
BOUND = {"expression": "l1 + l2", "<=": 0.4}  # an expression constraint: some designs are not feasible


@pytest.fixture(scope="module")
def study(tmp_path_factory) -> Path:
    """A small two-objective study run into ``<tmp>/out`` (population 8, 2 generations, a 3 x 3 grid)."""
    folder = tmp_path_factory.mktemp("explore")
    path = write_study(folder, VARIABLES, [ISOTROPY, MASS], population=8, generations=2, center=point(0.2),
                       size=(0.03, 0.0, 0.03), grid=3, constraints=[BOUND])
    result = runner.invoke(app, ["optimize", str(path), "--seed", "1", "--out", str(folder / "out"), "--quiet"])
    assert result.exit_code == 0, result.output
    return folder / "out"


@pytest.fixture(scope="module")
def served(study):
    """The study's folder served in this process (the command's own server), as (host, port)."""
    httpd = server(StudyFolder(study))
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield httpd.server_address
    httpd.shutdown()
    httpd.server_close()


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return [{without_unit(k): v for k, v in row.items()} for row in csv.DictReader(f)]


def _get(address, path: str, host: str | None = None, method: str = "GET") -> tuple[int, bytes]:
    """The status and body of ``path`` sent as it is (no client normalizes it)."""
    connection = http.client.HTTPConnection(*address, timeout=60)
    connection.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
    connection.putheader("Host", host or f"{address[0]}:{address[1]}")
    connection.endheaders()
    response = connection.getresponse()
    body = response.read()
    connection.close()
    return response.status, body


def _snapshot(folder: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns) for p in folder.rglob("*")}


def test_only_files_inside_the_folder_are_served(study, served):
    (study.parent / "secret.txt").write_text("outside")
    (study / "link.txt").symlink_to(study.parent / "secret.txt")
    try:
        status, body = _get(served, "/report.html")
        assert status == 200 and body == (study / "report.html").read_bytes()
        assert _get(served, "/")[1] == body
        assert _get(served, "/designs/design-1.yaml") == (200, (study / "designs" / "design-1.yaml").read_bytes())
        for path in ("/../secret.txt", "/designs/../../secret.txt", "/%2e%2e/secret.txt", "/..%2fsecret.txt",
                     f"/{study.parent / 'secret.txt'}", f"/%2F{str(study.parent / 'secret.txt').lstrip('/')}",
                     f"//{str(study.parent / 'secret.txt').lstrip('/')}", "/link.txt"):
            status, body = _get(served, path)
            assert status in (403, 404) and b"outside" not in body, path
        assert _get(served, "/secret.txt")[0] == 404
        assert _get(served, "/report.html", host="example.com:80")[0] == 403  # a name rebound to 127.0.0.1
        before = _snapshot(study)
        for method in ("POST", "PUT", "DELETE"):
            assert _get(served, "/report.html", method=method)[0] >= 400
        assert _snapshot(study) == before
    finally:
        (study / "link.txt").unlink()


def test_a_card_off_the_front_has_its_row_of_evaluations_csv(study, served):
    rows = _rows(study / "evaluations.csv")
    front = {tuple(r[v] for v in VARIABLES) for r in _rows(study / "front.csv")}
    off = [r for r in rows if tuple(r[v] for v in VARIABLES) not in front]
    assert any(r["feasible"] == "yes" for r in off) and any(r["feasible"] == "no" for r in off)
    for row in off:
        status, body = _get(served, f"/api/card?evaluation={row['evaluation']}")
        assert status == 200, body
        card = json.loads(body)
        assert card["evaluation"] == int(row["evaluation"]) and card["generation"] == int(row["generation"])
        assert card["variables"] == {v: float(row[v]) for v in VARIABLES}
        objectives = {k: None if row[k] == "" else float(row[k]) for k in ("iso", "mass")}
        assert card["objectives"] == objectives
        assert card["constraints"] == [None if row["l1 + l2"] == "" else float(row["l1 + l2"])]
        assert (card["feasible"], card["reason"]) == (row["feasible"] == "yes", row["reason"])
        assert card["file"] == f"evaluation-{row['evaluation']}.yaml" and "l1" in card["text"]
        if objectives["iso"] is not None:  # the maps reduce to its objectives: the least isotropy, the mean mass
            assert min(card["maps"]["isotropy"]["values"]) == objectives["iso"]
            mass = card["maps"]["apparent_mass"]["values"]
            assert math.fsum(mass) / len(mass) == pytest.approx(objectives["mass"], rel=1e-13)
            assert card["picture"] is not None


def test_a_served_cards_spec_summary_is_what_spec_says_of_its_device_file(study, served, tmp_path):
    """Oracle: ``hapticdesign spec --json`` on the device file the card offers (its text saved as the card names it),
    the card's own first command, without the workspace cube and the simulation the summary leaves out."""
    front = {tuple(r[v] for v in VARIABLES) for r in _rows(study / "front.csv")}
    row = next(r for r in _rows(study / "evaluations.csv")
               if r["feasible"] == "yes" and tuple(r[v] for v in VARIABLES) not in front)
    status, body = _get(served, f"/api/card?evaluation={row['evaluation']}")
    assert status == 200, body
    card = json.loads(body)
    assert card["commands"][0]["command"] == f"hapticdesign spec --device {card['file']}"
    (tmp_path / card["file"]).write_text(card["text"])
    done = runner.invoke(app, ["spec", "--device", str(tmp_path / card["file"]), "--json", "--no-workspace",
                               "--no-simulate"])
    assert done.exit_code == 0, done.output
    sheet = json.loads(done.stdout)
    assert [r["name"] for r in card["spec"]] == ["force_continuous", "force_peak", "resolution", "apparent_mass.min",
                                                  "apparent_mass.max", "renderable_stiffness.exact",
                                                  "renderable_stiffness.exact_with_hand"]
    for r in card["spec"]:
        expected = sheet
        for key in r["name"].split("."):
            expected = expected[key]
        assert r["value"] == (None if expected is None or not math.isfinite(expected) else expected), r["name"]
        assert r["unit"] == sheet["units"][r["name"].split(".")[0]]


def test_a_card_is_asked_for_by_an_evaluation_number(study, served):
    count = len(_rows(study / "evaluations.csv"))
    for query in ("", "?evaluation=0", f"?evaluation={count + 1}", "?evaluation=1.0", "?evaluation=-1",
                  "?evaluation=1&evaluation=2", "?evaluation=1&x=2", "?evaluation=%31%00"):
        status, body = _get(served, "/api/card" + query)
        assert status == 400 and "evaluation=N" in json.loads(body)["error"], query


def _explore(*args) -> tuple[int, str, str]:
    result = runner.invoke(app, ["explore", *map(str, args)])
    return result.exit_code, result.stdout, result.stderr


def _one_line_error(code: int, stdout: str, stderr: str, words: str) -> None:
    assert code == 2 and stdout == "" and "Traceback" not in stderr
    assert stderr.startswith("error: ") and stderr.count("\n") == 1 and words in stderr, stderr


def test_a_folder_that_is_not_a_study_output_is_one_line(study, tmp_path):
    _one_line_error(*_explore(tmp_path / "missing"), "is not a folder")
    _one_line_error(*_explore(study / "front.csv"), "is not a folder")
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "report.html").write_text("<p>")
    _one_line_error(*_explore(tmp_path / "other"), "is not a study's output folder")
    assert [p.name for p in (tmp_path / "other").iterdir()] == ["report.html"]


def test_a_port_in_use_is_one_line(study):
    taken = socket.socket()
    taken.bind(("127.0.0.1", 0))
    taken.listen()
    try:
        before = _snapshot(study)
        _one_line_error(*_explore(study, "--port", taken.getsockname()[1]), "is in use")
        assert _snapshot(study) == before
    finally:
        taken.close()


def _tampered(study: Path, folder: Path, edit) -> Path:
    """A copy of the study's folder whose front.csv's text went through ``edit``."""
    copy = folder / "copy"
    copy.mkdir()
    for name in ("report.html", "evaluations.csv", "study.json"):
        (copy / name).write_bytes((study / name).read_bytes())
    (copy / "front.csv").write_text(edit((study / "front.csv").read_text()))
    return copy


@pytest.mark.parametrize("edit, words", [
    (lambda text: text.replace(text.splitlines()[1].split(",")[1], "abc", 1), "'abc', not a finite number"),
    (lambda text: text.replace(text.splitlines()[1].split(",")[2], "nan", 1), "'nan', not a finite number"),
    (lambda text: text.replace(text.splitlines()[1].split(",")[3], "", 1), "'', not a finite number"),
    (lambda text: text.replace("iso", "isotropy", 1), "its header"),
    (lambda text: "\n".join(line.rsplit(",", 1)[0] for line in text.splitlines()) + "\n", "its header"),
    (lambda text: text.replace("\n2,", "\n7,", 1), "is numbered '7'"),
    (lambda text: text.splitlines()[0] + "\n", "has no design"),
], ids=["text", "nan", "blank", "renamed", "column-dropped", "renumbered", "no-row"])
def test_a_tampered_front_csv_is_one_line(study, tmp_path, edit, words):
    copy = _tampered(study, tmp_path, edit)
    before = _snapshot(copy)
    _one_line_error(*_explore(copy), words)
    assert _snapshot(copy) == before


def test_the_command_prints_its_address_and_stops_on_ctrl_c(study):
    command = [sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "explore", str(study),
               "--json"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    try:
        answer = json.loads(process.stdout.readline())
        host, port = answer["address"].removeprefix("http://").split("/")[0].split(":")
        assert host == "127.0.0.1" and answer["address"].endswith("/report.html") and answer["cards"] is True
        assert answer["evaluations"] == len(_rows(study / "evaluations.csv"))
        assert _get((host, int(port)), "/report.html")[0] == 200
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == 0 and out == "" and err == "stopped\n"


def test_a_damaged_study_copy_is_one_line_and_a_missing_one_leaves_the_front_s_cards(study, tmp_path):
    copy = _tampered(study, tmp_path, lambda text: text)
    (copy / "study.json").write_text('{"study": {"name": "../study.yaml", "text": ""}}')
    _one_line_error(*_explore(copy), "not the copy of a study")
    (copy / "study.json").unlink()
    folder = StudyFolder(copy)  # an output written before study.json: served, without cards off the front
    assert folder.bound is None and "study.json" in folder.why
    httpd = server(folder)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    try:
        status, body = _get(httpd.server_address, "/api/card?evaluation=1")
        assert status == 404 and "study.json" in json.loads(body)["error"]
    finally:
        httpd.shutdown()
        httpd.server_close()
