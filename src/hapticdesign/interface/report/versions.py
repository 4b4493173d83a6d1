"""Versions of the interpreter, the platform and the libraries a study ran with."""

from __future__ import annotations

import platform
from importlib import metadata

PACKAGES = ("hapticdesign", "numpy", "scipy", "sympy", "numba", "matplotlib", "pymoo", "cvxpy", "dask", "typer", "rich")


def versions() -> dict[str, str]:
    out = {"python": platform.python_version(), "platform": platform.platform()}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out
