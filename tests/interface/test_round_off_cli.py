"""Numbers below the computation's precision are printed as 0, and `dynamics` defaults to the home pose."""

import json
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from hapticdesign.interface.cli import app

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()


def _json(*args: str) -> dict:
    result = runner.invoke(app, [*args, "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_the_phantoms_mass_matrix_has_exact_zeros_off_its_block():
    """Cavusoglu & Feygin's closed form of the 3-DOF Phantom: H = [[h11, 0, 0], [0, h22, h23], [0, h23, h33]]
    at every pose (the base rotation decouples); the computed round-off (about 1e-18) is printed as 0."""
    out = _json("dynamics", "--preset", "phantom-3dof", "--q", "0.1,0.2,0.3", "--qd", "1,0,0")
    H = np.array(out["H"])
    assert H[0, 1] == H[0, 2] == H[1, 0] == H[2, 0] == 0.0
    assert min(abs(H[0, 0]), abs(H[1, 1]), abs(H[1, 2]), abs(H[2, 2])) > 1e-3
    assert "1e-12" in out["units"]["round_off"]


def test_stiffness_of_the_rcube_file_has_the_zeros_of_rcube_stiffness():
    """The device file's VJM and the built-in R-CUBE's agree, zeros included: K_C at home couples each
    translation with one rotation only (seed 001 eq. 5.121-5.123)."""
    from_file = np.array(_json("stiffness", "--device", str(ROOT / "examples" / "devices" / "rcube.yaml"))["K_C"])
    built_in = np.array(_json("rcube", "stiffness")["K_C"])
    assert np.array_equal(from_file == 0.0, built_in == 0.0)
    assert np.count_nonzero(from_file) == 12
    np.testing.assert_allclose(from_file, built_in, rtol=1e-6)


def test_dynamics_without_q_is_at_home_as_spec():
    falcon = str(ROOT / "examples" / "devices" / "falcon.yaml")
    sheet = _json("spec", "--device", falcon, "--no-workspace")
    home = sheet["q"]
    assert sheet["handle"][:2] == [0.0, 0.0]  # on the axis of the Falcon's threefold symmetry (y was -1.7e-18)
    at_home = _json("dynamics", "--device", falcon)
    assert at_home["q"] == home
    explicit = _json("dynamics", "--device", falcon, "--q", ",".join(repr(v) for v in home))
    assert at_home["H"] == explicit["H"] and at_home["G"] == explicit["G"]


def test_eom_refuses_to_flood_a_terminal_and_writes_a_file_instead(tmp_path, monkeypatch):
    """Equations longer than the limit are not printed to a terminal (one line saying how long and what to do);
    with --out they are written to the file, the same text a pipe would get."""
    from hapticdesign.interface.commands import dynamics

    piped = runner.invoke(app, ["eom", "--preset", "phantom-3dof", "--format", "latex"])
    assert piped.exit_code == 0
    text = piped.stdout
    monkeypatch.setattr(dynamics, "TERMINAL_LIMIT", len(text) // 2)
    monkeypatch.setattr(dynamics, "_terminal", lambda: True)
    refused = runner.invoke(app, ["eom", "--preset", "phantom-3dof", "--format", "latex"])
    assert refused.exit_code == 2 and refused.stdout == ""
    lines = refused.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: the equations are ") and "--out FILE" in lines[0]
    written = runner.invoke(app, ["eom", "--preset", "phantom-3dof", "--format", "latex", "--out", str(tmp_path / "e.tex")])
    assert written.exit_code == 0 and written.stdout == ""
    assert (tmp_path / "e.tex").read_text() == text
