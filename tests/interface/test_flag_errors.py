"""The command line names the flag of a bad input; the library's message names the quantity only."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.linearity.region import parse_region
from hapticdesign.analysis.rcube.tolerance import check_budget, draw_errors
from hapticdesign.errors import InputError
from hapticdesign.interface.cli import app

runner = CliRunner()


@pytest.mark.parametrize("args, line", [
    (["ln", "--region", "q2=a:b"], "error: --region: bounds of 'q2=a:b' are not numbers"),
    (["ln", "--region", "q9=0:1"], "error: --region: coordinate 9 does not exist (the device has 3)"),
    (["ln", "--symbolic", "--part", "X"], "error: --part: choose all, H, C or G, got 'X'"),
    (["eom", "--symbolic", "nonsense"], "error: --symbolic: unknown parameter name 'nonsense' for device phantom-3dof"),
    (["eom", "--format", "rtf"], "error: --format: expected latex, python or text, got 'rtf'"),
    (["rcube", "tolerance", "--samples", "0"], "error: --samples must be at least 1, got 0"),
    (["rcube", "tolerance", "--samples", "1", "--grid", "1"], "error: --grid must be at least 2, got 1"),
    (["impedance-range", "--step-control", "rk45"],
     "error: unknown step control 'rk45'; choose one of auto, fixed, adaptive (--step-control)"),
    (["eom", "--preset", "phantom-3dof", "--device", "x.yaml"],
     "error: give either a preset or a device file, not both (--preset, --device)"),
])
def test_cli_names_the_flag(args, line):
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert result.stderr.splitlines() == [line]


def test_cli_appends_the_flags_of_a_remedy():
    result = runner.invoke(app, ["rcube", "tolerance", "--samples", "100000", "--grid", "9"])
    assert result.exit_code == 2, result.output
    assert result.stderr.rstrip().endswith("or allow the long run (--samples, --grid, --allow-long)")


@pytest.mark.parametrize("call, message", [
    (lambda: parse_region("q2=a:b", 3), "region: bounds of 'q2=a:b' are not numbers"),
    (lambda: draw_errors(None, 0, 1), "samples must be at least 1, got 0"),
    (lambda: check_budget(100_000, 9), "lower the samples or the grid, or allow the long run"),
])
def test_library_message_names_the_quantity(call, message):
    with pytest.raises(InputError) as caught:
        call()
    assert message in str(caught.value) and "--" not in str(caught.value)
