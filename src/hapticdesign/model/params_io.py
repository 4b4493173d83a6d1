"""Parameter files: overrides by the seed's names from JSON, YAML or TOML.

A file is a flat mapping ``{name: number}`` (``m2: 0.156``, ``r2ax: 0.078``, ``l2: 0.215``,
``g: 9.81``); names not given keep the preset's value. A top-level ``params`` mapping is also
accepted so that a parameter file may carry other keys (e.g. a note).
"""

from __future__ import annotations

from pathlib import Path

from hapticdesign.errors import UserError
from hapticdesign.files import load_structured, quote


def read_mapping(path: Path, what: str = "file") -> dict:
    """Read a JSON, YAML or TOML file into a dictionary; malformed files raise :class:`UserError`."""
    data = load_structured(path, what)
    if not isinstance(data, dict):
        raise UserError(f"{path}: expected a mapping (name: value) at the top level")
    return data


def read_parameters(path: Path) -> dict[str, float]:
    """Parameter overrides ``{name: value}`` from a file (values checked by the device)."""
    data = read_mapping(path, "parameter file")
    if "params" in data and isinstance(data["params"], dict):
        data = data["params"]
    for key, value in data.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise UserError(f"{path}: parameter {quote(key)} must be a number, got {quote(value)}")
    return {str(k): float(v) for k, v in data.items()}
