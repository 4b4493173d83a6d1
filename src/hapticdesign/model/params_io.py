"""Parameter files: overrides by the seed's names from JSON, YAML or TOML.

A file is a flat mapping ``{name: number}`` (``m2: 0.156``, ``r2ax: 0.078``, ``l2: 0.215``,
``g: 9.81``); names not given keep the preset's value. A top-level ``params`` mapping is also
accepted so that a parameter file may carry other keys (e.g. a note).
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import yaml

from hapticdesign.errors import UserError


def read_mapping(path: Path) -> dict:
    """Read a JSON, YAML or TOML file into a dictionary; malformed files raise :class:`UserError`."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise UserError(f"cannot read {path}: {exc.strerror or exc}") from None
    suffix = path.suffix.lower()
    try:
        if suffix == ".json":
            data = json.loads(text)
        elif suffix in (".yaml", ".yml"):
            data = yaml.safe_load(text)
        elif suffix == ".toml":
            data = tomllib.loads(text)
        else:
            raise UserError(f"{path}: unknown file type {suffix!r} (use .json, .yaml, .yml or .toml)")
    except (json.JSONDecodeError, yaml.YAMLError, tomllib.TOMLDecodeError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise UserError(f"{path}: malformed {suffix[1:].upper()} ({first})") from None
    if not isinstance(data, dict):
        raise UserError(f"{path}: expected a mapping (name: value) at the top level")
    return data


def read_parameters(path: Path) -> dict[str, float]:
    """Parameter overrides ``{name: value}`` from a file (values checked by the device)."""
    data = read_mapping(path)
    if "params" in data and isinstance(data["params"], dict):
        data = data["params"]
    for key, value in data.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise UserError(f"{path}: parameter {key!r} must be a number, got {value!r}")
    return {str(k): float(v) for k, v in data.items()}
