"""Where each seed equation lives: an index built from the docstrings (``make docs``).

Every docstring that cites a seed equation, table, figure or section (``eq. 2.50``,
``eq. 5.84-5.97``, ``Table 7.3``, ``§4.1.2``) becomes a row of ``docs/equations.md``. The seed
is the one the docstring names (``seed 000`` / ``seed 001``); otherwise it follows from the
package (R-CUBE, stiffness, metrics and optimization code belongs to seed 001).
"""

from __future__ import annotations

import ast
import re
import sys
from collections import defaultdict
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]
REFERENCE = re.compile(r"(?:eq\.|eqs\.|Table|Tables|Figure|Figures|§)\s*\(?(\d+\.\d+(?:\s*[-–]\s*\d+\.\d+)?)")
SEED = re.compile(r"seed\s*(000|001)")
SEED_001_PARTS = ("rcube", "stiffness", "metrics", "optimization")


def _kind(match_text: str) -> str:
    for word, kind in (("eq", "eq."), ("Table", "Table"), ("Figure", "Figure"), ("§", "§")):
        if match_text.startswith(word):
            return kind
    return "eq."


def _sort_key(ref: str) -> tuple:
    major, minor = ref.split("-")[0].split("–")[0].strip().split(".")
    return int(major), int(minor)


def collect(package: Path = PACKAGE) -> dict[str, dict[tuple[str, str], set[str]]]:
    """``{seed: {(kind, reference): {"module:object", ...}}}`` for every cited reference."""
    found: dict[str, dict[tuple[str, str], set[str]]] = defaultdict(lambda: defaultdict(set))
    for path in sorted(package.rglob("*.py")):
        if path.resolve() == Path(__file__).resolve():
            continue
        module = ".".join(path.relative_to(package.parent).with_suffix("").parts)
        default_seed = "001" if any(p in module for p in SEED_001_PARTS) else "000"
        tree = ast.parse(path.read_text())
        nodes = [tree] + [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef))]
        for node in nodes:
            doc = ast.get_docstring(node)
            if not doc:
                continue
            where = module if node is tree else f"{module}:{node.name}"
            seeds = SEED.findall(doc)
            seed = seeds[0] if len(set(seeds)) == 1 else default_seed
            for m in REFERENCE.finditer(doc):
                ref = re.sub(r"\s+", "", m.group(1)).replace("–", "-")
                found[seed][(_kind(m.group(0)), ref)].add(where)
    return found


def render(found: dict[str, dict[tuple[str, str], set[str]]]) -> str:
    titles = {
        "000": "Seed 000 — Kızılbey (2019), Phantom, Linearity Number, rendering simulation",
        "001": "Seed 001 — Görgülü (2018), R-CUBE analysis and optimization",
    }
    lines = [
        "# Where each seed equation lives",
        "",
        "Generated from the docstrings by `python -m hapticdesign.interface.equation_index` (`make docs`);",
        "do not edit by hand.",
    ]
    for seed in sorted(found):
        lines += ["", f"## {titles[seed]}", "", "| reference | where |", "|---|---|"]
        for (kind, ref) in sorted(found[seed], key=lambda kr: (kr[0] != "eq.", kr[0], _sort_key(kr[1]))):
            places = ", ".join(f"`{w}`" for w in sorted(found[seed][(kind, ref)]))
            lines.append(f"| {kind} {ref} | {places} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str]) -> None:
    out = Path(argv[0]) if argv else None
    text = render(collect())
    if out is None:
        sys.stdout.write(text)
    else:
        out.write_text(text)


if __name__ == "__main__":
    main(sys.argv[1:])
