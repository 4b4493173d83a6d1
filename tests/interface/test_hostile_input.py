"""Hostile and careless input (issue 11): one ``error:`` line on stderr, exit status 2, nothing written.

A catalogue by class: work whose size the user sets (refused above the limits of
:mod:`hapticdesign.workload` unless ``--force``), nonsense settings, inputs that would print NaN or
Infinity as a result, wrong types through the API, and campaign robustness (hostile design names,
corrupt or stray case files, overflowing designs, a second campaign in the same folder).
"""

from __future__ import annotations

import csv
import fcntl
import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import hapticdesign as hd
from hapticdesign.analysis.dynamics.device import coriolis_matrix, mass_matrix
from hapticdesign.errors import UserError
from hapticdesign.interface.cli import app

from tests.helpers.sim_designs import write_designs

runner = CliRunner()
BOUNDARY = ["stability-boundary", "--inertia", "0.04", "--damping", "0.5", "--period", "0.001"]


def one_line_error(args: list[str], fragment: str) -> str:
    """Run the CLI; assert exit 2 and exactly one ``error:`` line containing ``fragment``."""
    result = runner.invoke(app, args)
    assert result.exit_code == 2, (args, result.output)
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), (args, result.stderr)
    assert fragment in lines[0], (fragment, lines[0])
    assert result.stdout == ""
    return lines[0]


# -- work whose size the user sets ----------------------------------------------------------------
WORKLOAD = [
    (["designs", "--count", "100000000"], "above the limit of 100,000 designs; add --force"),
    (["designs", "--count", "1000000", "--method", "de"], "above the limit of 1,000 designs"),
    (["linearize", "--find", "100000000"], "above the limit of 50,000 designs"),
    (["impedance-range", "--duration", "1e9"], "plant steps, above the limit"),
    (["impedance-range", "--step", "1e-12"], "plant steps, above the limit"),
    (["impedance-range", "--method", "linear", "--k-limit", "1000000000"], "plant steps, above the limit"),
    (["impedance-range", "--duration", "1e308", "--step", "1e-308"], "not a finite amount of work"),
    (["transparency", "--sweep", "1e9"], "plant steps, above the limit"),
    (["transparency", "--sweep", "1000"], "of memory, above the limit of 2 GiB"),
    ([*BOUNDARY, "--samples", "10000000000"], "plant steps, above the limit"),
    ([*BOUNDARY, "--substeps", "100000000"], "plant steps, above the limit"),
    ([*BOUNDARY, "--delay", "300", "--samples", "4000"], "rows, above the limit of 600 rows"),
    (["ln", "--region", "q2=-1e7:1e7"], "quadrature points, above the limit"),
    (["ln", "--region", "q2=-1e308:1e308"], "too wide to average over"),
]


@pytest.mark.parametrize("args, fragment", WORKLOAD, ids=[" ".join(a) for a, _ in WORKLOAD])
def test_large_work_is_refused_before_it_starts(args, fragment, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("HAPTICDESIGN_FORCE", raising=False)
    one_line_error(args, fragment)
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_force_lifts_a_soft_limit_but_not_a_hard_one(monkeypatch):
    from hapticdesign import workload

    monkeypatch.setattr(workload, "QUADRATURE_POINTS_LIMIT", 10)
    from hapticdesign.analysis.linearity import region

    monkeypatch.setattr(region, "QUADRATURE_POINTS_LIMIT", 10)
    one_line_error(["ln", "--region", "q2=-1:1", "--json"], "add --force")
    ok = runner.invoke(app, ["ln", "--region", "q2=-1:1", "--json", "--force"])
    assert ok.exit_code == 0, ok.output
    assert json.loads(ok.stdout)["ln"] >= 0
    one_line_error(["ln", "--region", "q2=-1e308:1e308", "--force"], "too wide")


def _chain_urdf(path: Path, joints: int) -> Path:
    """A serial chain of general revolute joints (no joint leaves the dynamics)."""
    parts = ['<?xml version="1.0"?>', f'<robot name="chain{joints}">', '<link name="base"/>']
    parent = "base"
    for i in range(1, joints + 1):
        axis = ["1 0 0", "0 1 0", "0 0 1"][i % 3]
        parts.append(f'<joint name="j{i}" type="revolute"><parent link="{parent}"/><child link="l{i}"/>'
                     f'<origin xyz="0.1 0.02 0.05" rpy="0.3 0.2 0.1"/><axis xyz="{axis}"/>'
                     '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
        parts.append(f'<link name="l{i}"><inertial><origin xyz="0.05 0.01 0"/><mass value="0.5"/>'
                     '<inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>')
        parent = f"l{i}"
    path.write_text("\n".join([*parts, "</robot>"]))
    return path


@pytest.mark.parametrize("joints, fragment", [(6, "above the limit of 2 GiB"), (7, "GiB of memory")])
def test_device_whose_exact_basis_explodes_is_refused_before_building(tmp_path, monkeypatch, joints, fragment):
    from hapticdesign import workload

    monkeypatch.delenv("HAPTICDESIGN_FORCE", raising=False)
    monkeypatch.setattr(workload, "physical_memory", lambda: 16 * 2**30)
    urdf = _chain_urdf(tmp_path / "chain.urdf", joints)
    line = one_line_error(["dynamics", "--device", str(urdf), "--q", ",".join(["0"] * joints)], fragment)
    assert f"{joints}-joint device" in line


def test_campaign_workers_are_capped_at_the_cores(tmp_path, monkeypatch):
    monkeypatch.setattr("os.cpu_count", lambda: 2)
    designs = write_designs(tmp_path / "d.csv", rows=[(0.0, {})])
    one_line_error(["campaign", "--designs", str(designs), "--out", str(tmp_path / "o"), "--workers", "64"],
                   "more than the 2 cores")
    assert not (tmp_path / "o").exists()


# -- nonsense settings ----------------------------------------------------------------------------
NONSENSE = [
    (["impedance-range", "--settle-window", "10"], "the settle window (10 s) must be shorter than the simulated time (5 s)"),
    (["impedance-range", "--duration", "0.5"], "settle window (0.5 s) must be shorter than the simulated time (0.5 s)"),
    (["impedance-range", "--duration", "1", "--settle-window", "1"], "(--settle-window, --duration)"),
    (["impedance-range", "--wall-damping", "-1"], "wall damping must be a finite number >= 0, got -1.0 (--wall-damping)"),
    (["impedance-range", "--error-percent", "100"], "must be a finite number between -100 and 100 (exclusive), got 100.0 (--error-percent)"),
    (["impedance-range", "--error-percent", "-100"], "between -100 and 100"),
    (["impedance-range", "--delay", "1000000000"], "must be shorter than the simulated time"),
    (["transparency", "--f0", "5", "--f1", "2"], "0 <= f0 < f1"),
    (["transparency", "--f1", "600"], "beyond the Nyquist frequency 500 Hz"),
    (["transparency", "--f1", "inf"], "must be finite"),
    (["transparency", "--amplitude", "0"], "--amplitude must be a finite, non-zero angle"),
    (["transparency", "--amplitude", "nan"], "--amplitude must be a finite, non-zero angle"),
    (["transparency", "--wall-damping", "-0.5"], "wall damping must be a finite number >= 0, got -0.5 (--wall-damping)"),
    ([*BOUNDARY, "--wall-damping", "-1"], "wall damping must be a finite number >= 0, got -1.0 (--wall-damping)"),
    ([*BOUNDARY, "--compensation", "full", "--error-percent", "150"], "between -100 and 100"),
    ([*BOUNDARY, "--delay", "2000", "--samples", "4000"], "shorter than a quarter of --samples"),
    (["designs", "--seed", "-1"], "--seed"),
    (["linearize", "--seed", "-1", "--find", "2"], "--seed"),
    (["designs", "--count", "0"], "at least 1"),
    (["study", "rcube", "--seed", "-1"], "--seed"),
    (["study", "phantom", "--seed", "-1"], "--seed"),
]


@pytest.mark.parametrize("args, fragment", NONSENSE, ids=[" ".join(a) for a, _ in NONSENSE])
def test_nonsense_settings_are_refused(args, fragment, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    one_line_error(args, fragment)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("content, fragment", [("g: -9.81\n", "gravity must be >= 0"),
                                               ("m2: -1\n", "negative mass"),
                                               ("m2: .inf\n", "finite")])
def test_nonsense_parameters_are_refused(tmp_path, content, fragment):
    params = tmp_path / "p.yaml"
    params.write_text(content)
    one_line_error(["ln", "--params", str(params)], fragment)


# -- no NaN or Infinity as a result ---------------------------------------------------------------
@pytest.mark.parametrize("args, fragment", [
    (["stability-boundary", "--inertia", "1e308", "--damping", "0.5", "--period", "0.001"], "--inertia 1e+308 is outside"),
    (["stability-boundary", "--inertia", "1e12", "--damping", "1e-12", "--period", "1e-12"], "too small to resolve"),
    (["stability-boundary", "--inertia", "1e-6", "--damping", "5", "--period", "0.001"], "raise --substeps"),
    (["dynamics", "--q", "0,0,0", "--qd", "1e308,0,0", "--json"], "not finite"),
])
def test_inputs_that_overflow_are_refused(args, fragment):
    one_line_error(args, fragment)


def test_an_unbounded_boundary_is_null_with_a_note(monkeypatch):
    from hapticdesign.simulation import boundary

    monkeypatch.setattr(boundary, "simulated_boundary", lambda *a, **k: float("inf"))
    result = runner.invoke(app, [*BOUNDARY, "--samples", "400", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)  # strict JSON: no Infinity
    assert out["k_max_simulated"] is None and out["relative_difference"] is None
    assert "unbounded" in out["note"]


@pytest.mark.parametrize("call, fragment", [
    (lambda d: mass_matrix(d.with_params({"m2": -1}), np.zeros(3)), "negative mass"),
    (lambda d: d.with_params({"g": -1.0}), "gravity must be >= 0"),
    (lambda d: d.with_params({"m2": float("nan")}), "finite"),
    (lambda d: d.with_params([("m2", 1.0)]), "mapping"),
    (lambda d: mass_matrix(d, None), "got None"),
    (lambda d: mass_matrix(d, np.zeros((2, 2, 3))), "shape (2, 2, 3)"),
    (lambda d: mass_matrix(d, "abc"), "must be numbers"),
    (lambda d: coriolis_matrix(d, np.zeros(3), None), "joint rates"),
    (lambda d: hd.impedance_range("phantom-3dof", 1), "expected a Device"),
    (lambda d: hd.impedance_range(d, 3), "simulation type must be 1 or 2"),
    (lambda d: hd.impedance_range(d, 1, k_limit=None), "stiffness limit must be a number"),
    (lambda d: hd.transparency(d, 1, "stiff"), "wall stiffness must be a number"),
    (lambda d: hd.transparency(d, 1, config="fast"), "config must be a LoopConfig"),
])
def test_api_refuses_wrong_types_and_values_with_a_user_error(phantom3, call, fragment):
    with pytest.raises(UserError) as caught:
        call(phantom3)
    assert fragment in str(caught.value)


def test_standard_parameters_refuse_negative_masses_set_behind_with_params(phantom3):
    from hapticdesign.model.device import Device

    d = phantom3
    broken = Device(d.name, d.description, d.kinematic, d.builder, {**d.params, "m2": -1.0}, d.damping)
    with pytest.raises(UserError, match="negative mass"):
        mass_matrix(broken, np.zeros(3))


# -- campaign robustness --------------------------------------------------------------------------
def _rename(path: Path, name: str) -> Path:
    rows = list(csv.DictReader(path.open()))
    rows[0]["design"] = name
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return path


@pytest.mark.parametrize("name", ["../../escaped", "/tmp/escaped-abs", ".hidden", "a/b", "x" * 101, "a b"])
def test_campaign_refuses_design_names_that_escape_or_are_not_file_names(tmp_path, name):
    designs = _rename(write_designs(tmp_path / "d.csv", rows=[(0.0, {})]), name)
    out = tmp_path / "deep" / "er" / "o"
    one_line_error(["campaign", "--designs", str(designs), "--out", str(out)], "cannot name a file")
    assert not (tmp_path / "deep").exists() and not Path("/tmp/escaped-abs__impedance__type1.json").exists()


def test_campaign_refuses_a_design_whose_dynamics_overflow_up_front(tmp_path):
    designs = write_designs(tmp_path / "d.csv", rows=[(0.0, {"m2": 1e308})])
    one_line_error(["campaign", "--designs", str(designs), "--out", str(tmp_path / "o")], "overflow")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("address", ["not an address", "tcp://", "http://x:1/y"])
def test_campaign_scheduler_that_is_not_an_address_is_one_line(tmp_path, address):
    designs = write_designs(tmp_path / "d.csv", rows=[(0.0, {})])
    one_line_error(["campaign", "--designs", str(designs), "--out", str(tmp_path / "o"), "--scheduler", address],
                   "is not a Dask scheduler address")
    assert not (tmp_path / "o").exists()


def test_a_second_campaign_in_the_same_folder_is_refused(tmp_path):
    designs = write_designs(tmp_path / "d.csv", rows=[(0.0, {})])
    out = tmp_path / "o"
    out.mkdir()
    with (out / "campaign.lock").open("a") as held:
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        one_line_error(["campaign", "--designs", str(designs), "--out", str(out)], "another campaign is running")
    assert not (out / "cases").exists()


def test_campaign_recomputes_empty_corrupt_and_stray_case_files_and_is_quiet(tmp_path):
    designs = write_designs(tmp_path / "d.csv", rows=[(0.0, {})])
    out = tmp_path / "o"
    args = ["campaign", "--designs", str(designs), "--out", str(out), "--workers", "1", "--k-limit", "20",
            "--duration", "1", "--sweep", "2", "--f1", "5", "--quiet"]
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    assert first.stderr == ""  # no Dask logs, no heartbeat tracebacks after the run
    cases = out / "cases"
    (cases / "x0__impedance__type1.json").write_text("")
    (cases / "x0__impedance__type2.json").write_text('{"design": "x0", "ty')
    record = json.loads((cases / "x0__transparency__type1.json").read_text())
    (cases / "x0__transparency__type1.json").write_text(json.dumps({**record, "design": "stray"}))
    second = runner.invoke(app, [*args[:-1], "--json"])
    assert second.exit_code == 0, second.output
    counts = json.loads(second.stdout)
    assert (counts["run"], counts["skipped"]) == (3, 1)
    assert json.loads((cases / "x0__transparency__type1.json").read_text())["design"] == "x0"


# -- round two (issue 24) -------------------------------------------------------------------------
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"


def _five_bar_with(tmp_path: Path, old: str, new: str) -> Path:
    text = (EXAMPLES / "five-bar.yaml").read_text()
    assert old in text
    path = tmp_path / "five-bar.yaml"
    path.write_text(text.replace(old, new))
    return path


def test_a_far_off_home_of_a_closed_loop_is_refused(tmp_path):
    """The solver follows the loops from home in steps of 0.1 rad: a home of 1e308 rad never ends."""
    device = _five_bar_with(tmp_path, "home: {q1: 2.0, q2: 1.1}", "home: {q1: 1e308, q2: 1.1}")
    one_line_error(["dynamics", "--device", str(device), "--q", "2,1.1"], "home: joint values must lie within +-1000")


@pytest.mark.parametrize("args, fragment", [
    (["--inertia", "1e308", "--damping", "0.5"], "outside the range this computation can resolve"),
    (["--inertia", "1e-300", "--damping", "1e300"], "outside the range this computation can resolve"),
    (["--inertia", "0.04", "--damping", "0.5", "--period", "1e308"], "outside the range this computation can resolve"),
    (["--inertia", "0.04", "--damping", "0.5", "--b-values", "0.1,-1"], "must be finite and >= 0, got -1 (--b-values)"),
])
def test_zwidth_refuses_loops_it_cannot_resolve_and_negative_dampers(args, fragment):
    one_line_error(["zwidth", *args], fragment)


def test_zwidth_api_caps_the_dampers_before_any_work():
    from hapticdesign.errors import InputError
    from hapticdesign.analysis.sampled_loop import SampledLoop
    from hapticdesign.simulation.zwidth import zwidth

    with pytest.raises(InputError, match="give 1 to 1000 virtual dampers, got 10,000,000"):
        zwidth(0.04, 0.5, SampledLoop(), [0.1] * 10**7)


def test_eom_of_a_closed_loop_device_is_refused_not_the_opened_tree():
    """The loop-opened tree's equations drive the passive joints and leave out the closure forces."""
    one_line_error(["eom", "--device", str(EXAMPLES / "five-bar.yaml")], "five-bar has closed loops (passive joints p1, p2)")


def test_dynamics_text_refuses_a_non_finite_result_as_json_does():
    one_line_error(["dynamics", "--q", "0,0,0", "--qd", "1e200,0,0"], "not finite (tau[0])")


def test_symbolic_ln_without_design_variables_is_valid_python(tmp_path):
    """A 1-DOF prismatic joint has constant H and G: LN is 0 and the function takes no variable."""
    device = tmp_path / "slide.yaml"
    device.write_text("name: slide\njoints:\n  - {name: q1, type: prismatic}\nframes:\n"
                      "  - {name: link, parent: base, transforms: [tz: q1]}\nend_effector: link\n"
                      "bodies:\n  - {name: ab, frame: link, m: 0.5, Ixx: 1.0e-4, Iyy: 0.0019, Izz: 0.002}\n")
    args = ["ln", "--device", str(device), "--region", "q1=0:0.1"]
    result = runner.invoke(app, [*args, "--symbolic", "--format", "python"])
    assert result.exit_code == 0, result.output
    namespace: dict = {}
    exec(compile(result.stdout, "generated.py", "exec"), namespace)  # noqa: S102 - the test's own generated file
    numeric = json.loads(runner.invoke(app, [*args, "--json"]).stdout)["ln"]
    assert namespace["linearity_number"]() == pytest.approx(numeric, abs=1e-12)


@pytest.mark.parametrize("call, fragment", [
    (lambda d: d.with_params({"m2": True}), "True is not a number"),
    (lambda d: d.with_params({"m2": np.bool_(False)}), "is not a number"),
    (lambda d: d.with_params({"m2": 1e308, "r2x": 1e308}).check(), "body 2: m r^2 overflows"),
    (lambda d: hd.dynamics_of(d).H(np.zeros(3), np.full(d.standard_parameters().shape, np.nan)), "must be finite"),
    (lambda d: hd.dynamics_of(d).G(np.zeros(3), np.full(d.standard_parameters().shape, np.inf)), "must be finite"),
    (lambda d: _form(d).ln(np.full(d.standard_parameters().shape, np.nan)), "must be finite"),
    (lambda d: _form(d).ln(np.full(d.standard_parameters().shape, 1e200)), "overflows"),
])
def test_api_refuses_booleans_non_finite_and_overflowing_parameters(phantom3, call, fragment):
    with pytest.raises(UserError, match=fragment.replace("^", r"\^")):
        call(phantom3)


def _form(device):
    from hapticdesign.analysis.linearity.form import device_form

    return device_form(device)


def test_campaign_and_library_refuse_a_settle_window_as_long_as_the_run(tmp_path, phantom3):
    from hapticdesign.simulation.config import LoopConfig
    from hapticdesign.simulation.criteria import Criteria, WallProblem

    designs = write_designs(tmp_path / "d.csv", rows=[(0.0, {})])
    one_line_error(["campaign", "--designs", str(designs), "--out", str(tmp_path / "o"), "--duration", "0.5"],
                   "--duration (0.5 s) must be longer than the 0.5 s settle window")
    assert not (tmp_path / "o").exists()
    with pytest.raises(UserError, match="must be shorter than the simulated time"):
        WallProblem(phantom3, criteria=Criteria(settle_window=1.0), config=LoopConfig(duration=1.0))


def test_impedance_range_refuses_a_wall_its_joint_cannot_push():
    """Joint 1 of the Phantom turns about the vertical: it cannot move the handle along z at q = 0."""
    one_line_error(["impedance-range", "--wall-direction", "0,0,1"], "joint 1 does not move the handle along the wall")


def test_a_huge_direction_is_a_direction_not_the_zero_vector():
    from hapticdesign.simulation.config import unit_direction

    assert unit_direction((0.0, 1e308, 0.0)).tolist() == [0.0, 1.0, 0.0]
    assert unit_direction((3e307, 4e307, 0.0)) == pytest.approx([0.6, 0.8, 0.0], abs=1e-15)
    huge, unit = (runner.invoke(app, ["zwidth", "--preset", "phantom-3dof", "--wall-direction", d, "--b-values", "0",
                                      "--json"]) for d in ("0,1e308,0", "0,1,0"))
    assert huge.exit_code == 0, huge.output
    assert json.loads(huge.stdout) == json.loads(unit.stdout)


@pytest.mark.parametrize("method", ["analytic", "fast"])
def test_impedance_range_refuses_a_wall_joint_without_inertia(tmp_path, method):
    """Links 2, 3, 2a and 3a massless: H22 = 0 at the start, no dynamics to bound (a division by zero)."""
    params = tmp_path / "massless.yaml"
    bodies = ("2", "3", "2a", "3a")
    names = [f"{n}{b}" for b in bodies for n in ("m", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")]
    params.write_text("".join(f"{name}: 0\n" for name in names + [f"r{b}{a}" for b in bodies for a in "xyz"]))
    one_line_error(["impedance-range", "--method", method, "--params", str(params), "--joint", "2"],
                   "joint 2 has no inertia at the start pose (H22 = 0)")


def test_analytic_range_of_a_joint_with_inertia_beside_massless_links_is_the_closed_form(tmp_path):
    """Links 2, 3, 2a and 3a massless, the wall on joint 1: joints 2 and 3 follow their paths (held, type 1), so
    their missing inertia does not enter; joint 1 turns body 1 alone, H11 = Iyy1 + m1 r1z^2 (parallel axes,
    0.009 + 0.25 * 0.15^2), and with full inertial compensation and no delay the sampled wall is stable up to
    K* = b^2 / H11 (seed 000 ch. 4; :mod:`hapticdesign.analysis.sampled_loop`'s closed form at c = 1): 17.09, so
    the last stable integer stiffness is 17 N m/rad."""
    params = tmp_path / "massless.yaml"
    bodies = ("2", "3", "2a", "3a")
    names = [f"{n}{b}" for b in bodies for n in ("m", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")]
    params.write_text("".join(f"{name}: 0\n" for name in names + [f"r{b}{a}" for b in bodies for a in "xyz"]))
    result = runner.invoke(app, ["impedance-range", "--method", "analytic", "--params", str(params), "--joint", "1",
                                 "--json"])
    assert result.exit_code == 0, result.output
    p, b1 = hd.preset("phantom-3dof").params, 0.5  # b1: Table 4.1
    h11 = p["Iyy1"] + p["m1"] * (p["r1x"] ** 2 + p["r1z"] ** 2)
    assert json.loads(result.stdout)["k_max"] == math.floor(b1 ** 2 / h11) == 17


def test_rcube_lengths_that_overflow_the_kinematics_are_refused():
    one_line_error(["rcube", "ik", "--l1", "1e308", "--l2", "1e308", "--l3", "1e308", "--position", "0,0,0"],
                   "must be a positive length of at most 1000 m, got 1e+308")


@pytest.mark.parametrize("place", ["cases", "figures"])
def test_campaign_refuses_a_planted_symlink_and_writes_nothing_through_it(tmp_path, place):
    designs = write_designs(tmp_path / "d.csv", rows=[(0.0, {})])
    out, outside = tmp_path / "o", tmp_path / "outside"
    out.mkdir()
    outside.mkdir()
    (out / place).symlink_to(outside)
    one_line_error(["campaign", "--designs", str(designs), "--out", str(out)], f"{out / place} is a symbolic link")
    assert list(outside.iterdir()) == []


def _frames_file(path: Path, frames: int) -> Path:
    lines = ["name: frames", "joints: [{name: q1}]", "frames:", "  - {name: f0, parent: base, transforms: [Rz: q1]}"]
    lines += [f"  - {{name: f{i}, parent: f{i - 1}, transforms: [tx: 0.001]}}" for i in range(1, frames)]
    lines += [f"end_effector: f{frames - 1}", "bodies: [{name: b, frame: f0, m: 0.5, rx: 0.1, Ixx: 1.0e-4, "
              "Iyy: 0.0019, Izz: 0.002}]"]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("command", [["show", "--out", "OUT"], ["dynamics", "--q", "0"], ["ln"], ["eom"]])
def test_devices_above_the_size_limits_are_refused_on_every_path(tmp_path, monkeypatch, command):
    monkeypatch.delenv("HAPTICDESIGN_FORCE", raising=False)
    command = [a.replace("OUT", str(tmp_path / "out")) for a in command]
    frames = _frames_file(tmp_path / "frames.yaml", 1_001)
    one_line_error([*command, "--device", str(frames)], "has 1,001 frames, above the limit of 1,000 frames")
    chain = _chain_urdf(tmp_path / "chain.urdf", 200)
    one_line_error([*command, "--device", str(chain)], "has 200 joints, above the limit of 32 joints")
    assert not (tmp_path / "out").exists()


def test_loops_are_limited_and_force_lifts_the_device_limits(monkeypatch):
    from hapticdesign.workload import WorkloadTooLarge, allow_large, require_device_size

    monkeypatch.delenv("HAPTICDESIGN_FORCE", raising=False)
    with pytest.raises(WorkloadTooLarge, match="has 300 loops, above the limit of 16 loops"):
        require_device_size("the file", 30, 100, 300)
    with allow_large():
        require_device_size("the file", 600, 50_000, 300)


def test_the_probe_of_a_large_tree_is_estimated_before_it_allocates(monkeypatch):
    """200 joints and bodies: the regressor probes alone would take 7.7 GB (they once ran out of memory)."""
    from hapticdesign.analysis.dynamics.model import DynamicsModel
    from hapticdesign.workload import allow_large

    monkeypatch.delenv("HAPTICDESIGN_FORCE", raising=False)
    with allow_large():
        from hapticdesign.devices.urdf import load_urdf

        device = load_urdf(_chain_urdf(Path(__import__("tempfile").mkdtemp()) / "c.urdf", 200))
    with pytest.raises(UserError, match="probing the equations of motion of a 200-joint device"):
        DynamicsModel(device.mechanism)


def test_ctrl_c_is_one_line(monkeypatch):
    from hapticdesign.devices import loading

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(loading, "resolve_device", interrupted)
    result = runner.invoke(app, ["dynamics", "--q", "0,0,0"])
    assert result.exit_code == 130
    assert result.stderr == "error: interrupted\n" and result.stdout == ""


def test_campaign_workers_start_with_ctrl_c_blocked_and_a_ctrl_c_meanwhile_is_kept():
    """Ctrl-C reaches the terminal's whole process group: processes spawned while the campaign defers interrupts
    (as its Dask workers are, by multiprocessing's spawn from a thread started inside) inherit SIGINT blocked and
    never answer it; a SIGINT that arrives meanwhile is raised once the block ends, and the handler returns."""
    import multiprocessing
    import os
    import signal
    import threading

    from hapticdesign.simulation.campaign import deferred_interrupts

    before = signal.getsignal(signal.SIGINT)
    masks: list[bool] = []

    def spawn():
        child = multiprocessing.get_context("spawn").Process(target=_report_blocked, args=(queue,))
        child.start()
        masks.append(queue.get())
        child.join()

    queue = multiprocessing.get_context("spawn").Queue()
    with pytest.raises(KeyboardInterrupt):
        with deferred_interrupts():
            starter = threading.Thread(target=spawn)
            starter.start()
            starter.join()
            os.kill(os.getpid(), signal.SIGINT)  # held: the block goes on to its end
            masks.append(True)
    assert masks == [True, True]
    assert signal.getsignal(signal.SIGINT) is before
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, [])


def _report_blocked(queue) -> None:
    """In a spawned process: whether SIGINT is blocked there."""
    import signal

    queue.put(signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, []))
