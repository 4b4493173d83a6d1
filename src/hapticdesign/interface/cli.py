"""The ``hapticdesign`` command: a table of contents of the toolkit.

Each module of :mod:`hapticdesign.interface.commands` contributes its commands through a
``register(app)`` function, so every area (dynamics, Linearity Number, simulation, R-CUBE,
studies) keeps its command-line code next to its own name.
"""

from __future__ import annotations

import importlib
import pkgutil

import typer

from hapticdesign.interface import commands

app = typer.Typer(
    name="hapticdesign",
    help="Design kinesthetic haptic devices for high impedance performance.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _register_all() -> None:
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{commands.__name__}.{info.name}")
        register = getattr(module, "register", None)
        if register is not None:
            register(app)


_register_all()


def main() -> None:
    app()
