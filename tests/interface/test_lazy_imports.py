"""``hapticdesign --help`` and ``--version`` load no engine: the command table imports only typer, numpy and the
interface (the engines load when a command runs), so both answer without seconds of imports."""

from __future__ import annotations

import subprocess
import sys

HEAVY = ("numba", "scipy", "sympy", "cvxpy", "control", "matplotlib", "hapticdesign.analysis", "hapticdesign.simulation")


def _modules_after(code: str) -> set[str]:
    done = subprocess.run([sys.executable, "-c", code + "\nimport sys\nprint('\\n'.join(sys.modules))"],
                          capture_output=True, text=True, check=True)
    return set(done.stdout.split())


def test_the_command_table_imports_no_engine():
    loaded = _modules_after("import hapticdesign.interface.cli")
    assert not [m for m in loaded if m.split(".")[0] in HEAVY or m.startswith(HEAVY)]


def test_version_and_help_run_without_engines():
    code = ("import sys\nfrom hapticdesign.interface.cli import app\nfrom typer.testing import CliRunner\n"
            "for args in (['--version'], ['--help']):\n    assert CliRunner().invoke(app, args).exit_code == 0")
    loaded = _modules_after(code)
    assert not [m for m in loaded if m.split(".")[0] in HEAVY or m.startswith(HEAVY)]


def test_the_package_names_load_on_first_use():
    loaded = _modules_after("import hapticdesign as hd\nassert callable(hd.mass_matrix) and hd.__version__")
    assert "hapticdesign.analysis.dynamics.device" in loaded
