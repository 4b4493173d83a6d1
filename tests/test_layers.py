"""Imports go only downward through the layers of docs/architecture.md, and no modules form a circle.

Every ``import`` and ``from ... import`` of every module is read with :mod:`ast`, at module level and
inside functions; an import of a higher layer fails, naming the module and the import. Module-level
imports between modules must not form a circle, and neither may any imports counting function-level
ones (issue 21: a lazy import that picks a method hides a circle; the shared types go below both).
"""

from __future__ import annotations

import ast
from functools import lru_cache
from pathlib import Path

PACKAGE = "hapticdesign"
ROOT = Path(__file__).resolve().parents[1] / "src" / PACKAGE

# Lowest first; a module may import its own layer or any lower one (docs/architecture.md).
LAYERS: dict[str, int] = {
    "errors": 0, "files": 0, "escape": 0, "workload": 0, "version": 0,
    "model": 1,
    "analysis": 2,
    "devices": 3,
    "simulation": 4,
    "optimization": 5,
    "studies": 6,
    "interface": 7,
}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@lru_cache(maxsize=1)
def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


def _imports(name: str, path: Path, source: str | None = None) -> list[tuple[str, int, bool]]:
    """``(imported module, line, at module level)`` for every import of ``hapticdesign`` in a module."""
    tree = ast.parse(path.read_text(encoding="utf-8") if source is None else source, filename=str(path))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    top_level = {id(node) for node in tree.body}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[: len(anchor) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            # ``from a import b`` imports the module a.b when b is one, else a name of a
            targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in _modules() else base for alias in node.names]
        else:
            continue
        at_top = id(node) in top_level or _inside_top_level_block(tree, node)
        found += [(t, node.lineno, at_top) for t in targets if t == PACKAGE or t.startswith(PACKAGE + ".")]
    return found


def _inside_top_level_block(tree: ast.Module, target: ast.AST) -> bool:
    """An import under a module-level ``try``/``if`` (not in a function or class body) runs at import time."""
    for node in tree.body:
        if isinstance(node, (ast.Try, ast.If)):
            if any(child is target for child in ast.walk(node)):
                return True
    return False


def _layer(module: str) -> int | None:
    """The layer of a module; ``None`` for the package root, which sits above everything."""
    parts = module.split(".")
    return None if len(parts) == 1 else LAYERS[parts[1]]


def test_every_module_has_a_layer():
    unknown = sorted({m.split(".")[1] for m in _modules() if "." in m and m.split(".")[1] not in LAYERS})
    assert not unknown, f"modules outside every layer (add them to docs/architecture.md and LAYERS): {unknown}"


def test_imports_go_only_downward():
    upward = []
    for name, path in _modules().items():
        mine = _layer(name)
        for target, line, _ in _imports(name, path):
            theirs = _layer(target)
            if theirs is None and mine is not None:
                upward.append(f"{name} (line {line}) imports the package root {target}")
            elif mine is not None and theirs > mine:
                upward.append(f"{name} (line {line}) imports {target}, a higher layer")
    assert not upward, "upward imports:\n" + "\n".join(upward)


def _circle(graph: dict[str, set[str]]) -> list[str] | None:
    """One circle of the directed graph, or ``None``."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return None


def _parents(module: str) -> list[str]:
    """Subpackages whose ``__init__`` runs before ``module`` (an import of a.b.c.d imports a.b and a.b.c)."""
    parts = module.split(".")
    return [".".join(parts[:i]) for i in range(2, len(parts))]


def _graph(lazy: bool) -> dict[str, set[str]]:
    """Import edges between modules: module-level imports, and with ``lazy`` function-level ones too."""
    modules = _modules()
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        for target, _, at_top in _imports(name, path):
            if (at_top or lazy) and target != name:
                # a module's own packages are already importing when it runs: no edge to them
                mine = {name, *_parents(name + ".x")}
                graph.setdefault(name, set()).update(t for t in [*_parents(target), target] if t in modules and t not in mine)
    return graph


def test_no_circle_at_module_level():
    circle = _circle(_graph(lazy=False))
    assert circle is None, "module-level import circle: " + " -> ".join(circle)


def test_no_circle_even_through_function_level_imports():
    """Issue 21: a lazy import that picks a method may not close a circle either; shared types go below both."""
    circle = _circle(_graph(lazy=True))
    assert circle is None, "import circle (through a function-level import): " + " -> ".join(circle)


def test_the_circle_check_counts_lazy_imports():
    assert _circle({"a": {"b"}, "b": {"a"}}) == ["a", "b", "a"]
    assert _circle({"a": {"b"}, "b": set()}) is None


def test_the_checker_sees_function_level_and_relative_imports():
    path = ROOT / "model" / "device.py"
    source = "def f():\n    from hapticdesign.interface.cli import main\n    from ..devices import loading\n"
    found = {(target, top) for target, _, top in _imports("hapticdesign.model.device", path, source)}
    assert found == {("hapticdesign.interface.cli", False), ("hapticdesign.devices.loading", False)}


def test_device_readers_share_the_builder_and_do_not_import_each_other():
    """Issue 12: the device-file reader (device_file, schema) and the URDF reader (urdf) both build through
    devices.builder and never import each other."""
    sides = {"hapticdesign.devices.device_file": "file", "hapticdesign.devices.schema": "file",
             "hapticdesign.devices.urdf": "urdf"}
    modules = _modules()
    crossing, users = [], set()
    for name, side in sides.items():
        targets = {target for target, _, _ in _imports(name, modules[name])}
        crossing += [f"{name} imports {t}" for t in targets if sides.get(t, side) != side]
        if "hapticdesign.devices.builder" in targets:
            users.add(name)
    assert not crossing, "device readers import each other:\n" + "\n".join(crossing)
    assert users == set(sides)


def test_nothing_generic_imports_the_r_cube_chain():
    """Issue 36: the registry of design indices and every generic optimization module (the study file, its
    evaluation, methods, run, polishing and outputs, pymoo's runner, the local search) import no R-CUBE code; the
    R-CUBE's indices register from the R-CUBE's own module (the ``hapticdesign.indices`` entry point)."""
    generic = [name for name in _modules() if name.startswith("hapticdesign.analysis.metrics.indices")
               or (name.startswith("hapticdesign.optimization.")
                   and not name.startswith("hapticdesign.optimization.rcube"))]
    assert {"hapticdesign.optimization.study_run", "hapticdesign.optimization.pymoo_run",
            "hapticdesign.optimization.local_search", "hapticdesign.optimization.study_methods"} <= set(generic)
    found = [f"{name} (line {line}) imports {target}" for name in generic
             for target, line, _ in _imports(name, _modules()[name])
             if target.startswith(("hapticdesign.optimization.rcube", "hapticdesign.analysis.rcube",
                                   "hapticdesign.model.rcube"))]
    assert not found, "generic modules import R-CUBE code:\n" + "\n".join(found)
