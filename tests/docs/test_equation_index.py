"""docs/equations.md (seed equation -> code) is the index the docstrings give today."""

from __future__ import annotations

from pathlib import Path

from hapticdesign.interface.equation_index import collect, render

DOCS = Path(__file__).resolve().parents[2] / "docs"


def test_equation_index_is_current():
    assert (DOCS / "equations.md").read_text() == render(collect()), "run `make docs` to regenerate docs/equations.md"


def test_index_covers_the_seed_chapters():
    found = collect()
    refs = {ref for (_, ref) in found["000"]} | {ref.split("-")[0] for (_, ref) in found["000"]}
    assert {"2.50", "2.52", "3.28"} <= refs
    chapters_001 = {ref.split(".")[0] for (_, ref) in found["001"]}
    assert {"4", "5", "6", "7"} <= chapters_001
