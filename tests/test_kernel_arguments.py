"""Compiled kernels take typed records, not loose arrays: no numba function has more than 12 parameters.

Every function of the package decorated with ``njit`` (or ``nb.njit``) is read with :mod:`ast`; one with more
than :data:`MOST` parameters fails, naming the module and the function (issue 21: bundle its arrays into a
NamedTuple record as :mod:`hapticdesign.simulation.records` and :mod:`hapticdesign.analysis.loops.records` do).
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src" / "hapticdesign"
MOST = 12


def _compiled(tree: ast.Module):
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            decorators = [ast.unparse(d.func if isinstance(d, ast.Call) else d) for d in node.decorator_list]
            if any(d.split(".")[-1] == "njit" for d in decorators):
                yield node


def test_no_compiled_function_takes_more_than_twelve_parameters():
    wide = []
    for path in sorted(ROOT.rglob("*.py")):
        for node in _compiled(ast.parse(path.read_text(encoding="utf-8"))):
            count = len(node.args.posonlyargs) + len(node.args.args) + len(node.args.kwonlyargs)
            if count > MOST:
                wide.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name} takes {count}")
    assert not wide, "compiled functions with loose arguments: " + "; ".join(wide)


def test_the_check_sees_the_kernels():
    """The scan finds the closed-loop kernels (a renamed decorator would make the check vacuous)."""
    names = {node.name for path in ROOT.rglob("*.py") for node in _compiled(ast.parse(path.read_text(encoding="utf-8")))}
    assert {"newton_into", "solve_path", "motion_entries_into", "closed_loop_terms", "run_loop"} <= names
