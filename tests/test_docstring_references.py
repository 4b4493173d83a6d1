"""Every module, class, function, method, attribute or datum a docstring names by a role resolves.

Docstrings (every string standing alone as a statement: a module's, a class's, a function's, an attribute's) name
code as ``:mod:`...```, ``:func:`...```, ``:class:`...```, ``:meth:`...```, ``:data:`...``` and ``:attr:`...```
(the API reference renders them as links). Each target is resolved the way the reference reads it: a fully dotted
name by importing its longest module prefix and walking the attributes; ``.name`` from the module's own package
(``.config`` beside ``simulation/zwidth.py``) or the module itself; a bare name among the enclosing classes'
members, in the module's namespace (its own definitions and what it imports), or as a module. A dataclass field, an
annotated name and what a class's methods assign to ``self`` count as the class's attributes.
"""

from __future__ import annotations

import ast
import builtins
import importlib
import inspect
import re
import textwrap
from functools import lru_cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "src" / "hapticdesign"
ROLE = re.compile(r":(mod|func|class|meth|data|attr):`([^`]+)`")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _docstrings(path: Path):
    """``(line, enclosing classes, text)`` of every string statement of a module."""

    def visit(node, classes):
        for child in ast.iter_child_nodes(node):
            if (isinstance(child, ast.Expr) and isinstance(child.value, ast.Constant)
                    and isinstance(child.value.value, str)):
                yield child.lineno, classes, child.value.value
            yield from visit(child, (*classes, child.name) if isinstance(child, ast.ClassDef) else classes)

    yield from visit(ast.parse(path.read_text(encoding="utf-8")), ())


def _references() -> list[tuple[str, tuple[str, ...], int, str, str]]:
    found = []
    for path in sorted(ROOT.rglob("*.py")):
        for line, classes, text in _docstrings(path):
            for role, target in ROLE.findall(text):
                found.append((_module_name(path), classes, line, role, re.sub(r"\s+", "", target)))
    return found


@lru_cache(maxsize=None)
def _module(name: str):
    try:
        return importlib.import_module(name)
    except ImportError:
        return None


_MISSING = object()


@lru_cache(maxsize=None)
def _instance_attributes(klass: type) -> frozenset[str]:
    """The names a class's methods assign to ``self`` (``self.names = ...`` in ``__init__``)."""
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(klass)))
    except (OSError, TypeError):
        return frozenset()
    return frozenset(node.attr for node in ast.walk(tree)
                     if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store)
                     and isinstance(node.value, ast.Name) and node.value.id == "self")


def _attribute(owner, name: str):
    value = getattr(owner, name, _MISSING)
    if value is _MISSING and isinstance(owner, type):
        for klass in owner.__mro__:  # a dataclass field without a default, or an annotated attribute
            if (name in getattr(klass, "__dataclass_fields__", {}) or name in getattr(klass, "__annotations__", {})
                    or name in _instance_attributes(klass)):
                return name
    if value is _MISSING:
        module = getattr(owner, "__name__", None)
        if isinstance(module, str) and _module(f"{module}.{name}") is not None:  # a submodule not yet imported
            return _module(f"{module}.{name}")
    return value


def _walk(owner, names: list[str]) -> bool:
    for name in names:
        owner = _attribute(owner, name)
        if owner is _MISSING:
            return False
    return True


def _dotted(name: str) -> bool:
    """A fully dotted name: its longest importable module prefix, then attributes."""
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        module = _module(".".join(parts[:cut]))
        if module is not None:
            return _walk(module, parts[cut:])
    return False


def resolves(module_name: str, role: str, target: str, classes: tuple[str, ...] = ()) -> bool:
    """Whether ``target`` of ``role`` in a docstring of ``module_name`` (inside the nested ``classes``) names
    something that exists."""
    name = target.lstrip("~!").strip()
    if "<" in name:  # "text <target>"
        name = name[name.index("<") + 1:name.rindex(">")]
    name = name.removesuffix("()")
    here = _module(module_name)
    package = module_name if Path(here.__file__).name == "__init__.py" else module_name.rpartition(".")[0]
    if name.startswith("."):
        rest = name.lstrip(".")
        up = len(name) - len(rest) - 1
        base = package.rsplit(".", up)[0] if up else package
        return _dotted(f"{base}.{rest}") or _walk(here, rest.split("."))
    for depth in range(len(classes), 0, -1):  # the enclosing classes' own members first
        if _walk(here, [*classes[:depth], *name.split(".")]):
            return True
    if _walk(here, name.split(".")) or _dotted(name):
        return True
    return role != "mod" and "." not in name and hasattr(builtins, name)


REFERENCES = _references()


def test_docstrings_name_code_by_role():
    assert len(REFERENCES) > 300  # the scan finds them


def test_every_named_target_resolves():
    broken = [f"{module}:{line}: :{role}:`{target}`" for module, classes, line, role, target in REFERENCES
              if not resolves(module, role, target, classes)]
    assert not broken, "docstrings name what does not exist:\n" + "\n".join(broken)


@pytest.mark.parametrize("module, role, target, expected", [
    ("hapticdesign.simulation.zwidth", "mod", ".kernel", True),
    ("hapticdesign.simulation.zwidth", "func", "~.impedance.wall_interval", True),
    ("hapticdesign.simulation.zwidth", "func", "along_wall", True),
    ("hapticdesign.analysis.sampled_loop", "attr", "SampledLoop.held", True),
    ("hapticdesign.analysis.sampled_loop", "meth", "hapticdesign.analysis.sampled_loop.SampledLoop.seed", True),
    ("hapticdesign.optimization.study_run", "mod", ".study_dask", False),
    ("hapticdesign.simulation.zwidth", "func", "hapticdesign.simulation.zwidth.no_such", False),
    ("hapticdesign.simulation.zwidth", "mod", "hapticdesign.simulation.reference", False),
    ("hapticdesign.simulation.zwidth", "attr", "SampledLoop.no_such", False),
])
def test_the_resolver_tells_found_from_missing(module, role, target, expected):
    assert resolves(module, role, target) is expected
