"""Library errors do not name command-line flags; the command line adds the flag.

Every module below ``interface/`` is read with :mod:`ast`; any string constant inside a ``raise``
statement (plain strings, the literal parts of f-strings, concatenated pieces) that names a flag
such as ``--count`` fails, naming the module and the line.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src" / "hapticdesign"
FLAG = re.compile(r"(?<![\w-])--[A-Za-z]")


def _flag_messages(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Raise) or node.exc is None:
            continue
        for part in ast.walk(node.exc):
            if isinstance(part, ast.Constant) and isinstance(part.value, str) and FLAG.search(part.value):
                found.append(f"{path.relative_to(ROOT.parent)}:{part.lineno}: {part.value!r}")
    return found


def test_no_library_error_names_a_flag():
    library = [p for p in sorted(ROOT.rglob("*.py")) if "interface" not in p.relative_to(ROOT).parts]
    assert len(library) > 50
    offenders = [line for path in library for line in _flag_messages(path)]
    assert not offenders, "library errors naming a command-line flag:\n" + "\n".join(offenders)


def test_the_check_finds_a_flag():
    source = 'def f(n):\n    raise ValueError(f"--count must be at least 1, got {n}")\n'
    tree = ast.parse(source)
    raised = next(node for node in ast.walk(tree) if isinstance(node, ast.Raise))
    strings = [p.value for p in ast.walk(raised.exc) if isinstance(p, ast.Constant) and isinstance(p.value, str)]
    assert any(FLAG.search(s) for s in strings)
