"""The ``hapticdesign`` command: a table of contents of the toolkit.

Each module of :mod:`hapticdesign.interface.commands` contributes its commands through a
``register(app)`` function, so every area (dynamics, Linearity Number, simulation, R-CUBE,
studies) keeps its command-line code next to its own name. Here they are ordered and grouped
into the sections of ``hapticdesign --help``, following the seeds' chapters.
"""

from __future__ import annotations

import importlib
import math
import os
import pkgutil
import sys
from contextlib import nullcontext

import typer
from typer.core import TyperGroup

from hapticdesign.interface import commands

CONTENTS = {
    "dynamics": "Equations of motion (seed 000 ch. 2)",
    "linearity": "Linearity Number and linear designs (seed 000 ch. 3)",
    "simulation": "Haptic rendering simulation (seed 000 ch. 4)",
    "stability": "Haptic rendering simulation (seed 000 ch. 4)",
    "metrics": "Performance metrics of any device (seed 001 ch. 4)",
    "stiffness": "Performance metrics of any device (seed 001 ch. 4)",
    "maps": "Performance metrics of any device (seed 001 ch. 4)",
    "show": "Pictures of any device",
    "rcube": "R-CUBE mechanism and its optimization (seed 001)",
    "rcube_optimize": "R-CUBE mechanism and its optimization (seed 001)",
    "optimize": "Design optimization of any device",
    "explore": "Design optimization of any device",
    "study": "Studies and reports (both seeds end to end)",
}
OTHER = "More commands"


class OneLineErrors(TyperGroup):
    """A usage mistake (unknown option, missing or malformed value) as one ``error:`` line and exit status 2."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        from typer._click.exceptions import ClickException, NoArgsIsHelpError

        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        try:
            code = super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        except NoArgsIsHelpError as exc:  # the help is already printed
            sys.exit(exc.exit_code)
        except ClickException as exc:
            command = exc.ctx.command_path if getattr(exc, "ctx", None) is not None else "hapticdesign"
            message = _not_a_number(exc, sys.argv[1:] if args is None else list(args)) or exc.format_message()
            typer.echo(f"error: {message} (see {command} --help)", err=True)
            sys.exit(exc.exit_code)
        sys.exit(code if isinstance(code, int) else 0)

    def invoke(self, ctx):
        """Ctrl-C: one line (typer then exits with status 130); every file is written atomically, so
        none is left half-written, and an interrupted campaign resumes from the cases it wrote."""
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            typer.echo("error: interrupted", err=True)
            raise

    def list_commands(self, ctx) -> list[str]:
        """Commands section by section, in the order of :data:`CONTENTS`."""
        sections = [*dict.fromkeys(CONTENTS.values()), OTHER]
        names = super().list_commands(ctx)
        return sorted(names, key=lambda n: sections.index(getattr(self.commands[n], "rich_help_panel", None) or OTHER))


def _not_a_number(exc, args: list[str]) -> str | None:
    """The message for an option given NaN, whose range check would otherwise say a bound it does not break
    (``--rate nan`` "should be <= 1000000"); None when the option's value is not NaN."""
    param = getattr(exc, "param", None)
    for k, arg in enumerate(args):
        for opt in getattr(param, "opts", ()):
            value = args[k + 1] if arg == opt and k + 1 < len(args) else arg[len(opt) + 1:] if (
                arg.startswith(opt + "=")) else None
            try:
                if value is not None and math.isnan(float(value)):
                    return f"Invalid value for '{opt}': {value[:20]!r} is not a number"
            except ValueError:
                pass
    return None


app = typer.Typer(
    name="hapticdesign",
    cls=OneLineErrors,
    help="Design kinesthetic haptic devices for high impedance performance: equations of motion and the "
    "Linearity Number of the Phantom (seed 000), rendering simulations, and the R-CUBE mechanism's analysis and "
    "optimization (seed 001). Every command takes --json (one JSON object on stdout) and --quiet (nothing on "
    "stderr but errors); mistakes print one 'error:' line and exit with status 2.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode="markdown",  # units such as [rad] or [kg] stay text (rich markup would eat them)
)


def _version(value: bool) -> None:
    if value:
        from hapticdesign.version import __version__

        typer.echo(f"hapticdesign {__version__}")
        raise typer.Exit()


@app.callback()
def _root(version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                       help="Print the version and exit.")) -> None:
    """Design kinesthetic haptic devices for high impedance performance."""


def _contents_order(name: str) -> tuple[int, str]:
    order = list(CONTENTS)
    return (order.index(name) if name in CONTENTS else len(order), name)


def _register_all() -> None:
    """Register every command module's commands; ``*_adapter`` modules hold a command's work, imported when it
    runs (so ``--help`` loads no engine)."""
    found = (m.name for m in pkgutil.iter_modules(commands.__path__) if not m.name.endswith("_adapter"))
    modules = sorted(found, key=_contents_order)
    for name in modules:
        module = importlib.import_module(f"{commands.__name__}.{name}")
        register = getattr(module, "register", None)
        if register is None:
            continue
        known = len(app.registered_commands), len(app.registered_groups)
        register(app)
        for info in app.registered_commands[known[0]:] + app.registered_groups[known[1]:]:
            info.rich_help_panel = info.rich_help_panel or CONTENTS.get(name, OTHER)


_register_all()


def _notice(line: str) -> None:
    sys.stderr.write(f"{line}\n")
    sys.stderr.flush()


def _compile_notice(args: list[str]):
    """The compile notice of :func:`main` (numba's event listener), or nothing where no kernel can compile:
    ``--quiet``, ``--help``, ``--version`` or no command, which then import no engine."""
    if not args or "--quiet" in args or any(a in ("--help", "-h", "--version") for a in args):
        return nullcontext()
    from hapticdesign.simulation.warmup import compile_notice

    return compile_notice(_notice)


def main() -> None:
    """Run the command; an output stream that cannot be written (``> /dev/full``) is one line, exit 2.

    A run that compiles a numba kernel (the first on a machine: later runs load it from numba's cache)
    says so in one line on stderr first, unless ``--quiet``."""
    try:
        with _compile_notice(sys.argv[1:]):
            app()
        sys.stdout.flush()
    except OSError as exc:
        if isinstance(exc, BrokenPipeError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            sys.exit(1)
        try:
            sys.stdout = open(os.devnull, "w")
        finally:
            sys.stderr.write(f"error: cannot write the output: {exc.strerror or exc}\n")
        sys.exit(2)
