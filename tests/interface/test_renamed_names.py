"""An old name taken for one release says so in one ``warning:`` line on stderr, once, and the work goes on under
the new name (as python-control deprecates a keyword): the ``kmax`` index's ``damping`` (now ``wall_damping``, the name
of the wall damper in the loop record, its option, the commands' ``--wall-damping`` and their outputs) and the hand
``grasp`` (now ``light``)."""

from __future__ import annotations

from dataclasses import fields

import pytest

from hapticdesign.analysis.metrics.indices import Request, requests_of
from hapticdesign.analysis.sampled_loop import Hand, SampledLoop
from hapticdesign.interface.common import user_errors


def test_an_old_name_is_one_warning_line_once(capsys):
    with user_errors():
        for _ in range(3):
            assert requests_of([Request("kmax", {"damping": 0.5})])[0].options == {"wall_damping": 0.5}
        Hand.named("grasp")
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines == ["warning: index kmax: the option 'damping' is now called 'wall_damping'; 'damping' will be removed",
                     "warning: the hand 'grasp' is now called 'light' (the same 0.1 kg, 2 N s/m, 200 N/m); 'grasp' "
                     "will be removed"]


def test_quiet_says_nothing(capsys):
    with user_errors(quiet=True):
        requests_of([Request("kmax", {"damping": 0.5})])
    assert capsys.readouterr().err == ""


def test_one_name_per_setting_in_the_record_and_its_output():
    """The loop record's fields and the keys of what every command states of it are the same names (and the flags'
    ``--delay``, ``--error-percent``, ``--wall-damping``)."""
    named = {f.name for f in fields(SampledLoop)} - {"held"}
    stated = set(SampledLoop().as_dict()) - {"rate", "held_joints"}
    assert named == stated == {"period", "delay", "velocity", "compensation", "error_percent", "wall_damping", "hand"}


@pytest.mark.parametrize("old", ["virtual_damping", "model_error"])
def test_the_records_former_field_names_are_gone(old):
    with pytest.raises(TypeError):
        SampledLoop(**{old: 1.0})


def _flags(name: str) -> set[str]:
    import typer.main

    from hapticdesign.interface.cli import app

    command = typer.main.get_command(app).commands[name]
    return {flag for param in command.params for flag in getattr(param, "opts", [])}


LOOP_COMMANDS = ["impedance-range", "transparency", "stability-boundary", "campaign", "zwidth", "spec"]


@pytest.mark.parametrize("command", LOOP_COMMANDS)
def test_every_command_names_the_loop_settings_as_the_record_does(command):
    """A flag of a loop setting is the record's field (``--period``, ``--delay``, ``--error-percent``,
    ``--wall-damping``): no command spells one of them otherwise (``spec --rate`` is its former name, one release)."""
    flags = _flags(command)
    assert "--delay" in flags and ("--period" in flags or command == "campaign")  # a campaign's period is the seed's
    others = {"--rate", "--delay-samples", "--model-error", "--model-error-percent", "--virtual-damping", "--damping"}
    allowed = {"spec": {"--rate"}, "stability-boundary": {"--damping"}, "zwidth": {"--damping"}}.get(command, set())
    assert flags & others <= allowed


def test_spec_rate_is_the_former_period_with_one_warning_line():
    from pathlib import Path

    from typer.testing import CliRunner

    from hapticdesign.interface.cli import app

    five_bar = str(Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml")
    base = ["spec", "--device", five_bar, "--no-simulate", "--no-workspace", "--json", "--delay", "2"]
    runner = CliRunner()
    new = runner.invoke(app, [*base, "--period", "0.002"])
    old = runner.invoke(app, [*base, "--rate", "500"])
    assert new.exit_code == old.exit_code == 0
    assert old.stdout == new.stdout and '"period": 0.002' in new.stdout
    assert old.stderr.strip() == ("warning: --rate is now --period (the sample period, 1 / rate, in s); --rate will "
                                  "be removed")
    both = runner.invoke(app, [*base, "--period", "0.002", "--rate", "500"])
    assert both.exit_code == 2 and both.stderr.strip().startswith("error: --rate is the former name")
