"""The README's tour: each command that writes files writes them to a place of its own, so running the tour
in order loses nothing (two zwidth commands once shared zw/)."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def _tour() -> list[str]:
    text = README.read_text()
    block = text[text.index("```sh\nH=.venv/bin/hapticdesign"):]
    block = block[: block.index("\n```", 5)]
    return [line.split("#")[0].strip() for line in block.splitlines()[2:] if line.startswith("$H")]


def test_tour_commands_write_to_distinct_places():
    places = []
    for line in _tour():
        for command in line.split(";"):
            places += re.findall(r"--out\s+(\S+)", command) + re.findall(r">\s*(\S+)", command)
    assert places and len(places) == len(set(places)), sorted(p for p in places if places.count(p) > 1)
