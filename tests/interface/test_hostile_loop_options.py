"""Hostile values through every option of the sampled-loop commands (issue 46's sweep): NaN, inf, 1e308, 1e-300,
negative, 10^9, strings and unicode, each refused before any work with one ``error:`` line, exit status 2, no
traceback and nothing written. The values these options take as a valid run (a damper of 1e-300, a hand of 10^9
N/m ...) are not here: they run the loop."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app

from tests.helpers.sim_designs import write_designs

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
ALL = ("nan", "inf", "1e308", "1e-300", "-1", "1000000000", "abc", "é∞")
"""The hostile values of the sweep."""
TEXT = ("abc", "é∞")
"""A string and unicode where a number is asked."""
NOT_INT = ("nan", "inf", "1e308", "1e-300", "abc", "é∞")
"""Values that are no whole number."""
NAMES = ("1e308", "é∞")
"""A number and unicode where a name is asked (every other value takes the same way to the same refusal)."""
OUT = "<out>"
DESIGNS = "<designs>"

BASES = {
    "zwidth": ["zwidth", "--inertia", "0.039", "--damping", "0.5", "--json"],
    "zwidth-device": ["zwidth", "--preset", "phantom-3dof", "--q", "0,0,0", "--joint", "1", "--map-joints", "2,3",
                      "--map-points", "3", "--out", OUT, "--json"],
    "stability-boundary": ["stability-boundary", "--inertia", "0.01", "--damping", "0.1", "--samples", "400",
                           "--json"],
    "impedance-range": ["impedance-range", "--json"],
    "spec": ["spec", "--no-workspace", "--json"],
    "transparency": ["transparency", "--sweep", "1", "--f1", "2", "--json"],
    "campaign": ["campaign", "--designs", DESIGNS, "--out", OUT, "--workers", "1", "--k-limit", "4", "--duration",
                 "0.6", "--sweep", "1", "--f1", "2", "--method", "analytic", "--json"],
    "robustness": ["robustness", "--designs", DESIGNS, "--errors", "0,5", "--per-level", "1", "--out", OUT, "--json"],
}
"""A valid run of each command, to which one hostile option is added."""

REFUSED: dict[tuple[str, str], tuple[str, ...]] = {
    ('campaign', '--workers'): NOT_INT,
    ('impedance-range', '--compensation'): NAMES,
    ('impedance-range', '--counts'): ('nan', 'inf', '1e308', '1e-300', '-1', 'abc', 'é∞'),
    ('impedance-range', '--delay'): ALL,
    ('impedance-range', '--duration'): ALL,
    ('impedance-range', '--equilibrium'): NOT_INT,
    ('impedance-range', '--error-percent'): ('nan', 'inf', '1e308', '1000000000', 'abc', 'é∞'),
    ('impedance-range', '--hand-damping'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('impedance-range', '--hand-mass'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('impedance-range', '--hand-stiffness'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('impedance-range', '--hold'): ALL,
    ('impedance-range', '--joint'): ALL,
    ('impedance-range', '--k-limit'): ('nan', 'inf', '1e308', '1e-300', '-1', 'abc', 'é∞'),
    ('impedance-range', '--method'): NAMES,
    ('impedance-range', '--overshoot'): ('nan', 'inf', '-1', 'abc', 'é∞'),
    ('impedance-range', '--period'): ('nan', 'inf', '1e308', '1e-300', '-1', 'abc', 'é∞'),
    ('impedance-range', '--preset'): NAMES,
    ('impedance-range', '--resolution'): ('nan', 'inf', '1e308', '-1', '1000000000', 'abc', 'é∞'),
    ('impedance-range', '--safety'): ('nan', 'inf', '-1', 'abc', 'é∞'),
    ('impedance-range', '--settings'): NAMES,
    ('impedance-range', '--settle-tolerance'): ('nan', 'inf', '-1', 'abc', 'é∞'),
    ('impedance-range', '--settle-window'): ('nan', 'inf', '1e308', '-1', '1000000000', 'abc', 'é∞'),
    ('impedance-range', '--step'): ALL,
    ('impedance-range', '--step-control'): NAMES,
    ('impedance-range', '--type'): ALL,
    ('impedance-range', '--velocity'): NAMES,
    ('impedance-range', '--wall-damping'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('impedance-range', '--wall-direction'): ALL,
    ('robustness', '--draws'): ALL,
    ('robustness', '--errors'): ('nan', 'inf', '1e308', '-1', '1000000000', 'abc', 'é∞'),
    ('robustness', '--method'): NAMES,
    ('robustness', '--per-level'): ('nan', 'inf', '1e308', '1e-300', '-1', 'abc', 'é∞'),
    ('robustness', '--seed'): ('nan', 'inf', '1e308', '1e-300', '-1', 'abc', 'é∞'),
    ('robustness', '--type'): ALL,
    ('spec', '--compensation'): NAMES,
    ('spec', '--delay'): ALL,
    ('spec', '--hand'): NAMES,
    ('spec', '--hand-damping'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('spec', '--hand-mass'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('spec', '--hand-stiffness'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('spec', '--period'): ALL,
    ('spec', '--q'): ALL,
    ('spec', '--rate'): ALL,
    ('stability-boundary', '--compensation'): NAMES,
    ('stability-boundary', '--damping'): ALL,
    ('stability-boundary', '--delay'): ALL,
    ('stability-boundary', '--error-percent'): ALL,
    ('stability-boundary', '--inertia'): ALL,
    ('stability-boundary', '--period'): ALL,
    ('stability-boundary', '--samples'): ALL,
    ('stability-boundary', '--settings'): NAMES,
    ('stability-boundary', '--substeps'): ALL,
    ('stability-boundary', '--velocity'): NAMES,
    ('stability-boundary', '--wall-damping'): ALL,
    ('transparency', '--amplitude'): ('nan', 'inf', 'abc', 'é∞'),
    ('transparency', '--band'): ('nan', '-1', 'abc', 'é∞'),
    ('transparency', '--compensation'): NAMES,
    ('transparency', '--counts'): ('nan', 'inf', '1e308', '1e-300', '-1', 'abc', 'é∞'),
    ('transparency', '--delay'): ALL,
    ('transparency', '--error-percent'): ('nan', 'inf', '1e308', '1000000000', 'abc', 'é∞'),
    ('transparency', '--f0'): ('inf', '-1', 'abc', 'é∞'),
    ('transparency', '--f1'): ('nan', '1e-300', '1000000000', 'abc', 'é∞'),
    ('transparency', '--hand-damping'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('transparency', '--hand-mass'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('transparency', '--hand-stiffness'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('transparency', '--joint'): ('nan', 'inf', '1000000000', 'abc', 'é∞'),
    ('transparency', '--method'): TEXT,
    ('transparency', '--period'): ('nan', '1e308', '1e-300', '-1', '1000000000', 'abc', 'é∞'),
    ('transparency', '--step'): ('nan', 'inf', '1e308', 'abc', 'é∞'),
    ('transparency', '--stiffness'): TEXT,
    ('transparency', '--sweep'): ('nan', 'abc', 'é∞'),
    ('transparency', '--type'): ('nan', 'inf', '1e308', '1e-300', '-1', 'abc', 'é∞'),
    ('transparency', '--wall-damping'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('zwidth', '--b-values'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('zwidth', '--compensation'): NAMES,
    ('zwidth', '--damping'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('zwidth', '--delay'): ALL,
    ('zwidth', '--error-percent'): ALL,
    ('zwidth', '--inertia'): ('nan', 'inf', '1e308', '1e-300', '-1', 'abc', 'é∞'),
    ('zwidth', '--map-joints'): ALL,
    ('zwidth', '--map-points'): NOT_INT,
    ('zwidth', '--period'): ('nan', 'inf', '1e308', '1e-300', '-1', 'abc', 'é∞'),
    ('zwidth', '--points'): ALL,
    ('zwidth', '--preset'): NAMES,
    ('zwidth', '--settings'): NAMES,
    ('zwidth', '--velocity'): NAMES,
    ('zwidth', '--wall-direction'): ALL,
    ('zwidth-device', '--b-values'): ('nan', 'inf', '1e308', '-1', 'abc', 'é∞'),
    ('zwidth-device', '--joint'): ALL,
    ('zwidth-device', '--map-points'): NOT_INT,
    ('zwidth-device', '--points'): ALL,
    ('zwidth-device', '--q'): ALL,
    ('zwidth-device', '--wall-direction'): ALL,
}
"""Each command's option and the hostile values it refuses before any work."""


def _args(base: str, option: str, value: str, tmp_path: Path) -> list[str]:
    fill = {OUT: str(tmp_path / "out"), DESIGNS: str(tmp_path / "designs.csv")}
    if base in ("campaign", "robustness"):
        write_designs(tmp_path / "designs.csv")
    return [fill.get(a, a) for a in BASES[base]] + [option, value]


def refused(args: list[str], out: Path | None = None) -> str:
    """Run the CLI: exit 2, one ``error:`` line on stderr, no traceback, nothing on stdout, ``out`` not made."""
    result = runner.invoke(app, args)
    assert result.exit_code == 2, (args, result.output, result.exception)
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), (args, result.stderr)
    assert "Traceback" not in result.output and result.stdout == ""
    assert out is None or not out.exists(), args
    return lines[0]


@pytest.mark.parametrize("base, option, value",
                         [(b, o, v) for (b, o), values in REFUSED.items() for v in values])
def test_every_hostile_value_is_one_line_before_any_work(tmp_path, base, option, value):
    refused(_args(base, option, value, tmp_path), tmp_path / "out")


# -- the failures the sweep found, each at its root ----------------------------------------------------------------
@pytest.mark.parametrize("args, fragment", [
    (["--stiffness", "inf"], "the wall stiffness must be positive, got inf (--stiffness)"),
    (["--stiffness", "1e308"], "the wall stiffness must be at most 1e+12 (SI units), got 1e+308 (--stiffness)"),
    (["--sweep", "1e308"], "is not a finite amount of work"),
    (["--step", "1e-300"], "above the limit of 5e+08 plant steps"),
])
def test_transparency_checks_its_request_before_searching_the_stable_limit(args, fragment):
    """Before: a warning line about the stable limit, then the error (inf, 1e308), a traceback (sweep 1e308) or a
    search that did not end in 60 s (step 1e-300)."""
    assert fragment in refused([*BASES["transparency"], *args])


@pytest.mark.parametrize("args, fragment", [
    (["--map-points", "-1"], "the map needs 2 to 101 points per axis, got -1"),
    (["--map-points", "1000000000"], "the map needs 2 to 101 points per axis"),
    (["--map-joints", "abc"], "--map-joints: give two joints"),
    (["--map-joints", "1,2"], "two joints other than the wall joint"),
])
def test_zwidth_checks_its_map_before_writing_the_chart(tmp_path, args, fragment):
    """Before: zwidth.png and zwidth.svg were written into --out, then the map's options refused."""
    out = tmp_path / "out"
    assert fragment in refused([*_args("zwidth-device", *args, tmp_path)], out)



@pytest.mark.parametrize("args, fragment", [
    (["--stiffness", "1e308"], "the wall stiffness must be at most 1e+12 (SI units), got 1e+308 (--stiffness)"),
    (["--sweep", "1e-300"], "the chirp's sweep time 1e-300 s is shorter than one sample period (0.001 s) (--sweep)"),
])
def test_campaign_checks_its_transparency_request_before_making_its_folder(tmp_path, args, fragment):
    """Before: the folder made and the error from the first transparency case (1e308), or a traceback from the
    spectra of a chirp shorter than a sample (1e-300)."""
    assert fragment in refused(_args("campaign", *args, tmp_path), tmp_path / "out")


def test_campaign_estimates_the_analytic_loop_of_a_billion_samples_before_making_its_folder(tmp_path):
    """Before: the folder made, then the first analytic case refused the loop's order."""
    assert "above the limit of 600 rows" in refused(_args("campaign", "--delay", "1000000000", tmp_path),
                                                    tmp_path / "out")
