"""Hostile and careless files: data stays data, nothing runs, nothing hangs, every error is one line.

A catalogue by class (issue 11): code injection through names into every export format, file
formats that expand without bound (YAML aliases, XML entities, deep nesting, huge files), files
that are not UTF-8 text, and output places that cannot be written. Each case goes through the
command line, where a user meets it: exit status 2 and exactly one ``error:`` line.
"""

from __future__ import annotations

import importlib.util
import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hapticdesign.files import MAX_FILE_BYTES, quote
from hapticdesign.interface.cli import app

runner = CliRunner()
ROOT = Path(__file__).resolve().parents[2]
HOSTILE_NAME = 'x"""; import os; os.system("touch {marker}"); """\\\'\n$\\input{{/etc/passwd}}'

ONE_LINK = """\
name: {name}
g: 9.81
joints:
  - {{name: q1, damping: 0.3}}
frames:
  - {{name: link, parent: base, transforms: [Rx: pi/2, Rz: q1]}}
  - {{name: handle, parent: link, transforms: [tx: 0.15]}}
end_effector: handle
bodies:
  - {{name: {body}, frame: link, m: 0.5, rx: 0.1, Ixx: 1.0e-4, Iyy: 0.0019, Izz: 0.002}}
"""

URDF = """<?xml version="1.0"?>
<robot name={name}>
  <link name="base"/>
  <link name="arm"><inertial><mass value="0.5"/><origin xyz="0.1 0 0"/>
    <inertia ixx="1e-4" iyy="2e-3" izz="2e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="{joint}" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint>
</robot>
"""


def _one_error(result, fragment: str) -> None:
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.strip().splitlines() if line]
    assert len(lines) == 1 and lines[0].startswith("error:"), result.output
    assert fragment in lines[0], lines[0]
    assert len(lines[0]) < 400


def _import(path: Path):
    spec = importlib.util.spec_from_file_location(f"generated_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def hostile_device(tmp_path) -> tuple[Path, Path]:
    marker = tmp_path / "PWNED"
    name = json.dumps(HOSTILE_NAME.format(marker=marker))  # a valid YAML string holding quotes and newlines
    path = tmp_path / "evil.yaml"
    path.write_text(ONE_LINK.format(name=name, body="ab"))
    return path, marker


@pytest.mark.parametrize("args", [["eom", "--format", "python"], ["eom", "--format", "python", "--symbolic", "mab"],
                                  ["ln", "--symbolic", "--format", "python"]])
def test_generated_python_from_a_hostile_device_name_runs_nothing(hostile_device, tmp_path, args):
    device, marker = hostile_device
    result = runner.invoke(app, [*args, "--device", str(device)])
    assert result.exit_code == 0, result.output
    source = tmp_path / "generated.py"
    source.write_text(result.stdout)
    module = _import(source)  # a 1-DOF device's code imports (the docstring holds the escaped name)
    assert not marker.exists()
    assert "import os" in module.__doc__  # the name is kept, as text
    assert callable(getattr(module, "equations", None) or getattr(module, "linearity_number", None))


@pytest.mark.parametrize("args", [["eom", "--format", "latex"], ["eom", "--format", "text"],
                                  ["ln", "--symbolic", "--format", "latex"], ["ln", "--symbolic", "--format", "text"]])
def test_latex_and_text_exports_carry_no_user_markup(hostile_device, args):
    device, _ = hostile_device
    result = runner.invoke(app, [*args, "--device", str(device)])
    assert result.exit_code == 0, result.output
    assert "\\input" not in result.stdout and "import os" not in result.stdout


@pytest.mark.parametrize("body", ["'a,b'", "'m); import os #'", "'a b'", "'x\\\\input'"])
def test_body_names_that_could_become_code_are_refused(tmp_path, body):
    path = tmp_path / "bad.yaml"
    path.write_text(ONE_LINK.format(name="ok", body=body))
    _one_error(runner.invoke(app, ["eom", "--device", str(path), "--format", "python"]), "bodies[0].name")


def test_urdf_robot_name_is_text_and_joint_names_must_be_identifiers(tmp_path):
    marker = tmp_path / "PWNED"
    robot = quote_attr(HOSTILE_NAME.format(marker=marker))
    good = tmp_path / "evil.urdf"
    good.write_text(URDF.format(name=robot, joint="q1"))
    result = runner.invoke(app, ["eom", "--device", str(good), "--format", "python"])
    assert result.exit_code == 0, result.output
    (tmp_path / "g.py").write_text(result.stdout)
    _import(tmp_path / "g.py")
    assert not marker.exists()
    bad = tmp_path / "bad.urdf"
    bad.write_text(URDF.format(name='"r"', joint="q1); import os #"))
    _one_error(runner.invoke(app, ["eom", "--device", str(bad)]), "must be an identifier")


def quote_attr(text: str) -> str:
    return '"' + text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;").replace("\n", "&#10;") + '"'


def test_urdf_entities_are_refused(tmp_path):
    bomb = tmp_path / "bomb.urdf"
    bomb.write_text('<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;">]>\n'
                    + URDF.split("\n", 1)[1].format(name='"&b;"', joint="q1"))
    _one_error(runner.invoke(app, ["ln", "--device", str(bomb)]), "entities are not allowed")


ALIAS_BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{chr(98 + k)}: &{chr(98 + k)} [*{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, "
    f"*{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}]\n" for k in range(8)) + "m2: *i\n"


def test_yaml_alias_bomb_in_parameters_is_refused_at_once(tmp_path):
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text(ALIAS_BOMB)
    _one_error(runner.invoke(app, ["ln", "--params", str(bomb)]), "aliases")


def test_an_alias_in_a_device_file_is_refused(tmp_path):
    path = tmp_path / "alias.yaml"
    path.write_text(ONE_LINK.format(name="ok", body="ab").replace("g: 9.81", "g: &grav 9.81\nnote: *grav"))
    _one_error(runner.invoke(app, ["ln", "--device", str(path)]), "aliases")


@pytest.mark.parametrize("suffix, text", [
    (".json", "[" * 100_000 + "]" * 100_000),
    (".yaml", "a: " + "[" * 5000 + "]" * 5000),
    (".toml", "a = " + "[" * 5000 + "]" * 5000),
])
def test_deeply_nested_files_are_one_line(tmp_path, suffix, text):
    path = tmp_path / f"deep{suffix}"
    path.write_text(text)
    result = runner.invoke(app, ["ln", "--params", str(path)])
    _one_error(result, str(path))


def test_huge_files_are_refused_before_reading(tmp_path):
    path = tmp_path / "huge.json"
    with open(path, "wb") as handle:
        handle.seek(MAX_FILE_BYTES + 1)
        handle.write(b"}")
    _one_error(runner.invoke(app, ["ln", "--params", str(path)]), "limited to 20 MB")


def test_messages_quote_little_of_a_long_value(tmp_path):
    path = tmp_path / "long.yaml"
    path.write_text("m2: '" + "x" * 100_000 + "'\n")
    result = runner.invoke(app, ["ln", "--params", str(path)])
    _one_error(result, "m2")
    assert len(result.output) < 300
    assert len(quote("y" * 10_000)) <= 60


BINARY = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR"
LATIN1 = "m2: 0.2  # caf\u00e9\n".encode("latin-1")


@pytest.mark.parametrize("content, fragment", [(BINARY, "binary file"), (LATIN1, "not UTF-8 text")])
@pytest.mark.parametrize("args, name", [
    (["ln", "--params"], "p.yaml"),
    (["ln", "--device"], "d.yaml"),
    (["ln", "--device"], "d.toml"),
    (["ln", "--device"], "d.json"),
    (["ln", "--device"], "d.urdf"),
    (["ln", "--weights"], "w.yaml"),
    (["rcube", "stiffness", "--design"], "r.yaml"),
    (["study", "device", "--out", "OUT", "--device"], "s.yaml"),
    (["campaign", "--out", "OUT", "--designs"], "c.csv"),
    (["robustness", "--designs"], "r.csv"),
])
def test_non_text_files_are_one_line_for_every_reader(tmp_path, content, fragment, args, name):
    path = tmp_path / name
    path.write_bytes(content)
    args = [a.replace("OUT", str(tmp_path / "out")) for a in args]
    _one_error(runner.invoke(app, [*args, str(path)]), fragment)


def test_yaml_exponent_numbers_are_numbers(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("m2: 1e-1\n")
    result = runner.invoke(app, ["dynamics", "--params", str(path), "--q", "0,0.3,0.2", "--json"])
    assert result.exit_code == 0, result.output
    expected = runner.invoke(app, ["dynamics", "--params", str(_write(tmp_path / "q.yaml", "m2: 0.1\n")),
                                   "--q", "0,0.3,0.2", "--json"])
    assert json.loads(result.stdout)["H"] == json.loads(expected.stdout)["H"]


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def test_an_output_that_is_a_directory_is_one_line(tmp_path):
    target = tmp_path / "designs.csv"
    target.mkdir()
    _one_error(runner.invoke(app, ["designs", "--levels", "0", "--count", "1", "--out", str(target)]), "directory")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_output_folder_is_one_line_and_leaves_nothing(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        _one_error(runner.invoke(app, ["designs", "--levels", "0", "--count", "1", "--out", str(folder / "d.csv")]),
                   "cannot write")
        assert list(folder.iterdir()) == []
    finally:
        folder.chmod(stat.S_IRWXU)


def test_a_full_stdout_is_one_line():
    cli = Path(sys.executable).with_name("hapticdesign")
    with open("/dev/full", "w") as full:
        done = subprocess.run([str(cli), "dynamics", "--q", "0,0,0", "--json"], stdout=full, stderr=subprocess.PIPE,
                              text=True, timeout=300)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == ["error: cannot write the output: No space left on device"]


def test_non_finite_results_are_not_printed_as_json():
    from hapticdesign.errors import UserError
    from hapticdesign.files import dumps_json

    with pytest.raises(UserError, match=r"not finite \(H\[1\]\)"):
        dumps_json({"H": [1.0, float("nan")]})
    assert dumps_json({"H": [1.0, 2.0]}) == '{"H": [1.0, 2.0]}'


@pytest.mark.parametrize("body, fragment", [
    ("l1: abc", "l1 must be a number"),
    ("sigma: x", "sigma must be -1 or 1"),
    ("links: [{D: 0.02, d: 0.01, plies: 5}, {D: 0.02, d: 0.01, plies: 5}, {D: 0.02, d: 0.01, plies: 5}]",
     "plies must be four whole numbers"),
    ("colour: red", "unknown key(s) 'colour'"),
    ("density: -5", "density must be a positive finite number"),
    ("l2: .nan", "l2 must be a positive finite number"),
    ("links: [1, 2, 3]", "a link entry is a mapping"),
])
def test_rcube_design_files_are_validated(tmp_path, body, fragment):
    path = _write(tmp_path / "design.yaml", body + "\n")
    _one_error(runner.invoke(app, ["rcube", "stiffness", "--design", str(path)]), fragment)


def test_rcube_fk_refuses_a_pose_the_passive_links_cannot_reach():
    args = ["rcube", "fk", "--q1", "1.5", "--q2", "-1.5", "--q3", "1.5", "--l2", "0.02", "--l3", "0.02"]
    _one_error(runner.invoke(app, args), "cannot reach")
    assert runner.invoke(app, ["rcube", "fk", "--q1", "0.1", "--q2", "0", "--q3", "-0.1"]).exit_code == 0


@pytest.mark.parametrize("command", [["dynamics"], ["eom"], ["metrics"], ["show"], ["study", "device"], ["ln"],
                                     ["impedance-range"], ["rcube", "optimize"], ["rcube", "maps"]])
def test_commands_whose_work_can_grow_take_force(command):
    """Every command whose work a user's numbers or files can make large lifts the limits with --force."""
    result = runner.invoke(app, [*command, "--help"], env={"COLUMNS": "200"})
    assert result.exit_code == 0 and "--force" in result.output


@pytest.mark.parametrize("name", ["pipe.yaml", "zero.yaml", "random.urdf", "link.yaml"])
def test_pipes_and_devices_are_refused_without_reading(tmp_path, name):
    """A named pipe would block the read until a writer comes, /dev/zero and /dev/urandom never end:
    the file type is checked first (through a symlink too), and nothing of them is read."""
    path = tmp_path / name
    if name == "pipe.yaml":
        os.mkfifo(path)
        fragment = "named pipe"
    elif name == "link.yaml":
        os.mkfifo(tmp_path / "fifo")
        path.symlink_to(tmp_path / "fifo")
        fragment = "named pipe"
    else:
        path.symlink_to("/dev/zero" if name == "zero.yaml" else "/dev/urandom")
        fragment = "a device, not a regular file"
    _one_error(runner.invoke(app, ["ln", "--device", str(path)]), fragment)
    if path.suffix == ".yaml":
        _one_error(runner.invoke(app, ["ln", "--params", str(path)]), fragment)


def test_the_size_cap_counts_what_is_read(tmp_path, monkeypatch):
    """The cap holds on the bytes read, not on the size the file system reports (which is 0 for
    many special files): a file that reports a small size but holds more is still refused."""
    import hapticdesign.files as files

    path = tmp_path / "p.yaml"
    path.write_text("m2: 0.1\n" + "#" * 100 + "\n")
    monkeypatch.setattr(files, "MAX_FILE_BYTES", 50)
    with pytest.raises(files.UserError, match="larger than"):
        files.read_text(path)


@pytest.mark.parametrize("nu", ["-1", "0.5", "-3"])
def test_a_poisson_ratio_outside_the_isotropic_bounds_is_one_line(tmp_path, nu):
    """G = E / (2 (1 + nu)) divides by zero at nu = -1; a stable isotropic solid has -1 < nu < 0.5."""
    path = tmp_path / "elastic.yaml"
    path.write_text(ONE_LINK.format(name="ok", body="ab") + "links:\n  - {name: l, from: link, to: handle, "
                    f"section: {{shape: tube, D: 0.01, d: 0.008}}, material: {{E: 2.0e11, nu: {nu}}}}}\n")
    _one_error(runner.invoke(app, ["ln", "--device", str(path)]), "Poisson's ratio nu must lie in (-1, 0.5)")


def test_identical_runs_write_identical_svg_bytes(tmp_path):
    """matplotlib salts SVG ids at random and dates the file unless told otherwise: the same inputs
    must give the same bytes (PNG and SVG)."""
    for name in ("a", "b"):
        result = runner.invoke(app, ["zwidth", "--inertia", "0.04", "--damping", "0.5", "--points", "3",
                                     "--out", str(tmp_path / name), "--quiet"])
        assert result.exit_code == 0, result.output
    for suffix in (".svg", ".png"):
        first, second = ((tmp_path / n / "zwidth").with_suffix(suffix).read_bytes() for n in ("a", "b"))
        assert first == second
    svg = (tmp_path / "a" / "zwidth.svg").read_text()
    assert "<dc:date>" not in svg and "<svg" in svg


def test_rcube_design_file_tolerances_are_read_as_promised(tmp_path):
    """docs/rcube.md and --design's help promise ``tolerances: {l1, l2, l3, joint_offset}``."""
    path = _write(tmp_path / "design.yaml", "l1: 0.12\ntolerances: {l1: 0.0005, l2: 0.0002, l3: 0.001, "
                                             "joint_offset: 0.0001}\n")
    result = runner.invoke(app, ["rcube", "tolerance", "--design", str(path), "--samples", "2", "--grid", "2", "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["tolerances"] == {"lengths": [0.0005, 0.0002, 0.001], "joint_offset": 0.0001}
    assert runner.invoke(app, ["rcube", "stiffness", "--design", str(path)]).exit_code == 0  # the design reads it too


@pytest.mark.parametrize("body, fragment", [("tolerances: {l1: -1}", "tolerances.l1 must be a non-negative length"),
                                            ("tolerances: {l4: 1}", "tolerances: unknown key(s) 'l4'"),
                                            ("tolerances: {l2: yes}", "tolerances.l2 must be a non-negative length")])
def test_rcube_tolerances_are_validated_before_any_note(tmp_path, body, fragment):
    path = _write(tmp_path / "design.yaml", body + "\n")
    _one_error(runner.invoke(app, ["rcube", "tolerance", "--design", str(path), "--samples", "2", "--grid", "2"]),
               fragment)


def test_a_study_report_folder_that_cannot_be_written_is_named_before_the_banner():
    _one_error(runner.invoke(app, ["study", "rcube", "--out", "/proc/hapticdesign-report"]),
               "--out /proc/hapticdesign-report: cannot write the report there")
