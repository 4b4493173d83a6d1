"""Command-line options shared by every command, so names and help read the same everywhere."""

from __future__ import annotations

import typer

PRESET = typer.Option(None, "--preset", help="Built-in device: phantom-3dof or phantom-6dof (default phantom-3dof).")
DEVICE = typer.Option(None, "--device", help="Device file (YAML, TOML, JSON or URDF) instead of a preset.")
PARAMS = typer.Option(None, "--params", help="Parameter overrides by the seed's names (JSON, YAML or TOML).")
STRICT = typer.Option(False, "--strict", help="Refuse inertias that break the triangle inequality (the seed's designs do).")
JSON_OUT = typer.Option(False, "--json", help="Print the result as one JSON object on stdout.")
QUIET = typer.Option(False, "--quiet", help="No warnings, notes or progress bars on stderr; errors still print.")
SEED = typer.Option(1, "--seed", min=0, help="Random seed (>= 0): the same seed gives the same numbers.")
FORCE = typer.Option(False, "--force", help="Run work estimated above the stated limits (docs/limits.md).")
FORCE_HINT = "add --force to run it anyway"
