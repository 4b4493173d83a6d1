"""The command line as a whole (issue 7, "Feel"): every command takes --json and --quiet, prints one JSON
object with --json, answers a bad input with one ``error:`` line and exit status 2, and ``--help`` reads as
a table of contents. The new JSON outputs are checked against the engines they report on."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import typer
from typer.testing import CliRunner

from hapticdesign.analysis.dynamics.device import gravity, mass_matrix
from hapticdesign.interface.cli import CONTENTS, app

runner = CliRunner()

SEED_DESIGN = {"Ixx2": 0.00982641}  # eq. 3.33's link 2: breaks the triangle inequality (a consistency warning)

RCUBE_FILE = Path(__file__).resolve().parents[2] / "examples" / "devices" / "rcube.yaml"


def _commands(group=None, path=()):
    """Every leaf command of the application as (path, click command), sub-apps included."""
    group = group or typer.main.get_command(app)
    for name, command in group.commands.items():
        if hasattr(command, "commands"):
            yield from _commands(command, (*path, name))
        else:
            yield (*path, name), command


COMMANDS = dict(_commands())


def _options(command) -> dict[str, object]:
    return {name: p for p in command.params for name in (*p.opts, *p.secondary_opts)}


def _invoke(args, **kwargs):
    result = runner.invoke(app, [str(a) for a in args], **kwargs)
    assert "Traceback" not in result.output
    return result


def test_the_walk_finds_every_area():
    paths = {" ".join(p) for p in COMMANDS}
    assert {"dynamics", "eom", "ln", "linearize", "designs", "campaign", "rcube ik", "rcube maps",
            "rcube optimize", "study phantom", "study rcube", "demo"} <= paths


@pytest.mark.parametrize("path", list(COMMANDS), ids=" ".join)
def test_every_command_takes_json_and_quiet_with_one_meaning(path):
    options = _options(COMMANDS[path])
    reference = _options(COMMANDS[("dynamics",)])
    for name in ("--json", "--quiet"):
        assert name in options, f"{' '.join(path)} lacks {name}"
        assert options[name].help == reference[name].help
    for name in ("--preset", "--device", "--params", "--strict"):
        if name in options:
            assert options[name].help == reference[name].help, f"{' '.join(path)} {name}"
    if "--seed" in options:
        seed = _options(COMMANDS[("linearize",)])["--seed"]
        assert options["--seed"].default == 1 and options["--seed"].help == seed.help


def test_one_name_per_concept():
    """No command spells a shared concept differently (``--output`` for ``--out``, ``--random-seed``, ...)."""
    synonyms = {"--output", "--output-dir", "--outdir", "--out-dir", "--random-seed", "--rng-seed", "--silent",
                "--no-progress", "--as-json", "--fmt", "--device-file", "--params-file", "--preset-name"}
    used = {name for command in COMMANDS.values() for name in _options(command)}
    assert not used & synonyms


# One fast invocation per command; the studies and the demo run in tests/studies (smoke scale, --json).
SLOW = {("study", "phantom"), ("study", "rcube"), ("study", "device"), ("demo",)}


def _one_design(tmp: Path) -> Path:
    """A design file with the built-in design, as `designs` writes it."""
    from hapticdesign.devices.registry import preset

    device = preset("phantom-3dof")
    names = device.inertial_names()
    path = tmp / "one_design.csv"
    path.write_text("design,level,ln,ln_H,ln_C,ln_G," + ",".join(names) + "\n"
                    + "d1,0,0,0,0,0," + ",".join(repr(float(device.params.get(k, 0.0))) for k in names) + "\n")
    return path


def _tiny_study(tmp: Path) -> Path:
    """A study of examples/devices/five-bar.yaml: one variable, one point, 4 designs, 1 generation."""
    path = tmp / "study.yaml"
    path.write_text(f"device: {json.dumps(str(RCUBE_FILE.parent / 'five-bar.yaml'))}\n"
                    "variables: {l1: [0.09, 0.11]}\n"
                    "workspace: {box: {center: [0.0, 0.0, 0.18], size: [0, 0, 0]}, grid: 1}\n"
                    "objectives: [{index: isotropy, reduce: min, sense: max}]\n"
                    "algorithm: {population: 4, generations: 1}\n")
    return path


def _json_cases(tmp: Path) -> dict[tuple[str, ...], list]:
    return {
        ("optimize",): [_tiny_study(tmp), "--seed", "1"],
        ("dynamics",): ["--q", "0.1,0.2,0.3"],
        ("eom",): ["--symbolic", "none", "--part", "G"],
        ("ln",): [],
        ("linearize",): [],
        ("designs",): ["--levels", "0,1", "--count", "2", "--out", tmp / "designs.csv"],
        ("impedance-range",): ["--duration", "0.6", "--k-limit", "4"],
        ("transparency",): ["--sweep", "1", "--f1", "2"],
        ("stability-boundary",): ["--inertia", "0.01", "--damping", "0.1", "--period", "0.001", "--samples", "400"],
        ("metrics",): ["--q", "0.1,0.5,0.3"],
        ("stiffness",): ["--device", RCUBE_FILE, "--wrench", "0,0,-5"],
        ("ik",): ["--device", RCUBE_FILE.parent / "falcon.yaml", "--position", "0,0,0.11"],
        ("spec",): ["--device", RCUBE_FILE.parent / "haply-2diy.yaml", "--no-workspace"],
        ("export",): ["--device", RCUBE_FILE.parent / "five-bar.yaml", "--out", tmp / "five-bar.xml"],
        ("rcube", "ik"): ["--position", "0.11,0.1,0.12"],
        ("rcube", "fk"): ["--q1", "0.1", "--q2", "0", "--q3", "-0.1"],
        ("rcube", "stiffness"): [],
        ("rcube", "mass"): [],
        ("rcube", "metrics"): [],
        ("rcube", "cross-section"): ["--quick"],
        ("rcube", "plies"): ["--quick"],
        ("rcube", "synthesize"): ["--quick"],
        ("rcube", "optimize"): ["--quick"],
        ("rcube", "fem"): ["--position", "0.1117,0.1117,0.1117"],
        ("zwidth",): ["--inertia", "0.01", "--damping", "0.5", "--b-values", "0,0.1"],
        ("robustness",): ["--designs", _one_design(tmp), "--errors", "0,5"],
        ("show",): ["--out", tmp / "view"],
        ("rcube", "tolerance"): ["--samples", "5", "--seed", "1"],
        ("maps",): ["--device", RCUBE_FILE.parent / "five-bar.yaml", "--size", "0.02,0,0.02", "--grid", "2", "--out",
                    tmp / "maps"],
    }


OWN_TESTS = {("campaign",), ("rcube", "maps"), ("explore",)}  # checked below or in their own tests (explore serves)


@pytest.mark.parametrize("path", [p for p in COMMANDS if p not in SLOW | OWN_TESTS], ids=" ".join)
def test_json_is_one_object_on_stdout(tmp_path, path):
    cases = _json_cases(tmp_path)
    assert path in cases, f"add a fast --json invocation of {' '.join(path)}"
    result = _invoke([*path, *cases[path], "--json"])
    assert result.exit_code == 0, result.output
    assert isinstance(json.loads(result.stdout), dict)
    assert result.stderr == ""  # no progress bar and no note off a terminal


def test_eom_json_equations_evaluate_to_the_numeric_model(phantom3):
    """Each entry of ``eom --json`` (text) is H or G of the numeric model at a pose; LaTeX has the same keys."""
    text = json.loads(_invoke(["eom", "--symbolic", "none", "--part", "all", "--format", "text", "--json"]).stdout)
    latex = json.loads(_invoke(["eom", "--symbolic", "none", "--part", "all", "--json"]).stdout)
    assert text["device"] == "phantom-3dof" and latex["format"] == "latex"
    assert list(text["equations"]) == list(latex["equations"])
    q = np.array([0.3, -0.7, 1.1])
    subs = {sp.Symbol(f"theta{k + 1}"): q[k] for k in range(3)}
    H = [[float(sp.sympify(text["equations"][f"H_{i}_{j}"]).subs(subs)) for j in (1, 2, 3)] for i in (1, 2, 3)]
    G = [float(sp.sympify(text["equations"][f"G_{i}"]).subs(subs)) for i in (1, 2, 3)]
    assert np.allclose(H, mass_matrix(phantom3, q), atol=1e-12) and np.allclose(G, gravity(phantom3, q), atol=1e-12)
    python = json.loads(_invoke(["eom", "--format", "python", "--json"]).stdout)
    compile(python["source"], "eom", "exec")


def test_linearize_json_constant_h_and_found_designs(tmp_path, phantom3):
    """The default design is fully linear: its H is the reported constant at every pose (eq. 3.27), and the
    designs of ``--find`` have LN = 0 when evaluated again by ``ln``."""
    out = json.loads(_invoke(["linearize", "--find", "2", "--seed", "3", "--json"]).stdout)
    assert out["linear_possible"] and len(out["conditions"]) == 15 and len(out["free_parameters"]) == 35
    for q in np.random.default_rng(0).uniform(0, 2 * np.pi, (3, 3)):
        assert np.allclose(out["constant_H"], mass_matrix(phantom3, q), atol=1e-12)
    assert out["ln"] < 1e-12 and out["designs"]["count"] == 2 and out["designs"]["max_ln"] < 1e-12
    for k, design in enumerate(out["designs"]["values"]):
        path = tmp_path / f"d{k}.json"
        path.write_text(json.dumps(design))
        assert json.loads(_invoke(["ln", "--params", path, "--json"]).stdout)["ln"] < 1e-12


def test_linearize_json_six_dof_verdict(tmp_path):
    """6-DOF: no realizable LN = 0 design; the reported practical minimum is the LN of the reported design."""
    out = json.loads(_invoke(["linearize", "--preset", "phantom-6dof", "--json"]).stdout)
    verdict = out["verdict"]
    assert not out["linear_possible"] and verdict["certificate"]["bodies"] and verdict["exact"]
    minimum = verdict["minimum_ln"]
    assert 0 < minimum["lower_bound"] <= minimum["ln"] * (1 + 1e-9)
    assert 0 < verdict["scaled_minimum_ln"] < minimum["ln"]
    path = tmp_path / "min.json"
    path.write_text(json.dumps(minimum["design"]))
    again = json.loads(_invoke(["ln", "--preset", "phantom-6dof", "--params", path, "--json"]).stdout)
    assert again["ln"] == pytest.approx(minimum["ln"], rel=1e-8)


def test_designs_json_counts_and_ranges_match_the_file(tmp_path):
    csv_path = tmp_path / "d.csv"
    out = json.loads(_invoke(["designs", "--levels", "0,0.1", "--count", "3", "--out", csv_path, "--json"]).stdout)
    with csv_path.open() as f:
        rows = list(csv.DictReader(f))
    assert out["path"] == str(csv_path)
    for entry in out["levels"]:
        lns = [float(r["ln"]) for r in rows if float(r["level"]) == entry["level"]]
        assert entry["count"] == len(lns) == 3
        assert (entry["ln_min"], entry["ln_max"]) == (min(lns), max(lns))
    assert [e["level"] for e in out["levels"]] == [0.0, 0.1]
    design = {k: float(v) for k, v in rows[-1].items() if not k.startswith(("level", "ln"))}
    params = tmp_path / "p.json"
    params.write_text(json.dumps(design))
    again = json.loads(_invoke(["ln", "--params", params, "--json"]).stdout)
    assert again["ln"] == pytest.approx(float(rows[-1]["ln"]), rel=1e-9)


def test_campaign_json_lists_its_files_and_summary(tmp_path):
    designs = tmp_path / "d.csv"
    assert _invoke(["designs", "--levels", "0", "--count", "1", "--out", designs, "--quiet"]).exit_code == 0
    result = _invoke(["campaign", "--designs", designs, "--out", tmp_path / "c", "--workers", "1", "--k-limit", "4",
                      "--duration", "0.6", "--sweep", "1", "--f1", "2", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert (out["cases"], out["run"], out["skipped"]) == (4, 4, 0)
    assert all(Path(p).is_file() for p in out["tables"] + out["figures"]) and out["figures"]
    index = Path(out["index"]).read_text()
    assert all(f'href="{Path(p).relative_to(tmp_path / "c").as_posix()}"' in index for p in out["tables"] + out["figures"])
    with Path(out["tables"][1]).open() as f:
        rows = list(csv.DictReader(f))
    assert len(out["summary"]) == len(rows) == 4  # one level x two criteria x two types
    for entry, row in zip(out["summary"], rows):
        assert entry["n"] == int(row["n"]) == 1 and entry["criterion"] == row["criterion"]


def test_rcube_maps_json_lists_the_images(tmp_path):
    from hapticdesign.analysis.rcube.metrics import METRIC_NAMES

    out = json.loads(_invoke(["rcube", "maps", "--out", tmp_path, "--n", "3", "--json"]).stdout)
    assert len(out["files"]) == 3 * len(METRIC_NAMES)
    assert all(Path(f).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for f in out["files"])


def test_progress_only_on_a_terminal_without_quiet(tmp_path, monkeypatch):
    """On a terminal the bars go to stderr, never stdout; --quiet silences them."""
    from rich.console import Console

    monkeypatch.setattr(Console, "is_terminal", property(lambda self: True))
    shown = _invoke(["rcube", "maps", "--out", tmp_path / "a", "--n", "3"])
    assert shown.exit_code == 0 and "planes" in shown.stderr
    assert shown.stdout.startswith("wrote ") and shown.stdout.count("\n") == 1
    quiet = _invoke(["rcube", "maps", "--out", tmp_path / "b", "--n", "3", "--quiet"])
    assert quiet.exit_code == 0 and quiet.stderr == ""


@pytest.mark.parametrize("path", [("dynamics",), ("eom",), ("ln",), ("linearize",), ("impedance-range",)], ids=" ".join)
def test_quiet_silences_consistency_warnings(tmp_path, path):
    params = tmp_path / "p.json"
    params.write_text(json.dumps(SEED_DESIGN))
    args = [*path, *_json_cases(tmp_path)[path], "--params", params, "--json"]
    loud, quiet = _invoke(args), _invoke([*args, "--quiet"])
    assert loud.exit_code == quiet.exit_code == 0
    assert loud.stderr.startswith("warning:") and "triangle" in loud.stderr
    assert quiet.stderr == "" and json.loads(quiet.stdout) == json.loads(loud.stdout)


def _bad_inputs(tmp: Path) -> dict[tuple[str, ...], list]:
    a_file = tmp / "a-file"
    a_file.write_text("not a folder")
    return {
        ("dynamics",): ["--q", "1,2"],
        ("ik",): ["--device", RCUBE_FILE.parent / "falcon.yaml", "--position", "0.5,0,0"],
        ("spec",): ["--device", RCUBE_FILE.parent / "haply-2diy.yaml", "--q", "1", "--no-workspace"],
        ("export",): ["--device", RCUBE_FILE.parent / "five-bar.yaml", "--out", a_file / "m.xml"],
        ("eom",): ["--format", "pdf"],
        ("ln",): ["--region", "q3=2:1"],
        ("linearize",): ["--find", "-1"],
        ("designs",): ["--levels", "x", "--out", tmp / "d.csv"],
        ("impedance-range",): ["--type", "3"],
        ("transparency",): ["--band", "-1"],
        ("stability-boundary",): ["--inertia", "1", "--damping", "1", "--period", "0.001", "--samples", "10"],
        ("campaign",): ["--designs", tmp / "missing.csv", "--out", tmp / "c"],
        ("metrics",): ["--q", "0,0,1.5707963267948966"],
        ("stiffness",): ["--device", RCUBE_FILE, "--wrench", "1,2"],
        ("demo",): ["--out", a_file],
        ("rcube", "ik"): ["--position", "1,2"],
        ("rcube", "fk"): ["--q1", "0", "--q2", "0", "--q3", "0", "--l1", "-0.1"],
        ("rcube", "stiffness"): ["--plies", "1,2"],
        ("rcube", "mass"): ["--outer", "0.01,0.01"],
        ("rcube", "metrics"): ["--position", "a,b,c"],
        ("rcube", "maps"): ["--out", tmp / "m", "--n", "1"],
        ("rcube", "optimize"): ["--quick", "--bounds", "x"],
        ("rcube", "synthesize"): ["--quick", "--bounds", "1,2;3"],
        ("rcube", "cross-section"): ["--quick", "--population", "0"],
        ("rcube", "plies"): ["--quick", "--l1", "-0.1"],
        ("rcube", "fem"): ["--position", "1,2"],
        ("zwidth",): ["--inertia", "0.01", "--damping", "0.5", "--velocity", "filtered"],
        ("robustness",): ["--designs", tmp / "missing.csv"],
        ("show",): ["--q", "1,2"],
        ("rcube", "tolerance"): ["--samples", "-1"],
        ("study", "phantom"): ["--out", a_file],
        ("study", "rcube"): ["--out", a_file],
        ("study", "device"): ["--device", tmp / "missing.yaml", "--out", tmp / "s"],
        ("maps",): ["--device", RCUBE_FILE.parent / "five-bar.yaml", "--size", "0.1,0,0", "--out", tmp / "m"],
        ("optimize",): [tmp / "missing-study.yaml", "--out", tmp / "o"],
        ("explore",): [a_file],
    }


def _one_line_error(result) -> None:
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("error:") and result.stderr.count("\n") == 1, result.stderr
    assert result.stdout == ""


@pytest.mark.parametrize("path", list(COMMANDS), ids=" ".join)
def test_bad_input_is_one_line_and_exit_2(tmp_path, path):
    cases = _bad_inputs(tmp_path)
    assert path in cases, f"add a bad input of {' '.join(path)}"
    _one_line_error(_invoke([*path, *cases[path], "--json"]))


@pytest.mark.parametrize("path", list(COMMANDS), ids=" ".join)
def test_usage_mistakes_are_one_line_too(path):
    result = _invoke([*path, "--no-such-option"])
    _one_line_error(result)
    assert "--no-such-option" in result.stderr and f"hapticdesign {' '.join(path)} --help" in result.stderr


def test_units_survive_in_help():
    """Square brackets are text in help (a markup mode that eats ``[s]`` would drop every unit)."""
    result = _invoke(["impedance-range", "--help"], env={"COLUMNS": "250"})
    assert "[s]" in result.stdout and "[rad]" in result.stdout and "[N m/rad" in result.stdout


def test_help_reads_as_a_table_of_contents():
    result = _invoke(["--help"])
    assert result.exit_code == 0
    sections = list(dict.fromkeys(CONTENTS.values()))
    positions = [result.stdout.index(title) for title in sections]
    assert positions == sorted(positions)
    top = typer.main.get_command(app)
    for name in top.list_commands(None):
        help_text = top.commands[name].help or ""
        assert any(mark in help_text for mark in ("seed", "eq.", "§")), name
    for path, command in COMMANDS.items():
        first_line = (command.help or "").strip().splitlines()[0]
        assert any(mark in first_line.lower() for mark in ("seed", "eq.", "§", "table", "figure")), path
