"""A tree is a device whose loops are empty (issue 44, Pinocchio's view: a tree is the empty list of constraints).

Above the compiled kernels no code asks "tree or loop?" on its own: every module of ``src/`` is read with
:mod:`ast`, and a comparison of a ``loops`` value with ``None`` (``loops is None``, ``mech.loops is not None``; a
:class:`~hapticdesign.model.loops.ClosedLoops` is never ``None``) or a name ``is_tree`` fails, naming the module
and the line. The kernels (``*_kernel.py``), which take the closures as flat arrays, may guard on their sizes; they
are not read.
"""

from __future__ import annotations

import ast
import warnings
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1] / "src" / "hapticdesign"


def _is_loops(node: ast.AST) -> bool:
    return (isinstance(node, ast.Name) and node.id == "loops") or (isinstance(node, ast.Attribute)
                                                                   and node.attr == "loops")


def tree_questions(source: str) -> list[int]:
    """Lines of ``source`` that ask whether a device is a tree instead of asking its loops for a capability."""
    tree = ast.parse(source)
    lines = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare) and any(isinstance(op, (ast.Is, ast.IsNot)) for op in node.ops):
            operands = [node.left, *node.comparators]
            if any(_is_loops(o) for o in operands) and any(isinstance(o, ast.Constant) and o.value is None
                                                           for o in operands):
                lines.add(node.lineno)
        if (isinstance(node, ast.Name) and node.id == "is_tree") or (isinstance(node, ast.Attribute)
                                                                      and node.attr == "is_tree"):
            lines.add(node.lineno)
    return sorted(lines)


def test_the_reader_finds_each_kind_of_question():
    """The reader is not blind: each form it refuses is found in a sample, and the capability questions pass."""
    source = ("a = mech.loops is None\nb = loops is not None\nc = None is device.mechanism.loops\n"
              "d = space.is_tree\ne = 1 if space.is_tree else 0\nf = mech.loops.empty\n"
              "g = not loops.closures\nh = loops.passive is None\ni = solver is None\n")
    assert tree_questions(source) == [1, 2, 3, 4, 5]


def test_no_module_above_the_kernels_asks_whether_a_device_is_a_tree():
    found = []
    for path in sorted(ROOT.rglob("*.py")):
        if path.name.endswith("_kernel.py"):
            continue
        lines = tree_questions(path.read_text(encoding="utf-8"))
        found += [f"{path.relative_to(ROOT.parent)}:{line}" for line in lines]
    assert found == [], "ask the loops for a capability (loops.empty, loops.closures), not None: " + ", ".join(found)


def test_a_tree_takes_the_same_calls_with_nothing_to_close():
    """A tree built without loops has the empty ones, and its configuration closes nothing: no constraints, no
    passive coordinates, full coordinates its actuated ones, ``T`` the identity (properties that must hold)."""
    from hapticdesign.analysis.configuration import configuration_of
    from hapticdesign.devices.registry import preset
    from hapticdesign.model.loops import ClosedLoops

    device = preset("phantom-3dof")
    assert device.mechanism.loops == ClosedLoops() and device.mechanism.loops.empty
    space = configuration_of(device)
    q = np.array([0.3, -0.2, 0.5])
    np.testing.assert_array_equal(space.full(q), q)
    np.testing.assert_array_equal(space.home, np.zeros(3))
    np.testing.assert_array_equal(space.velocity_transform(q), np.eye(3))
    assert space.passive(q).shape == (0,)
    assert space.solver.constraint_jacobian(q).shape == (0, 3)


def test_the_former_loop_configuration_is_the_configuration_with_a_deprecation_line():
    import hapticdesign.analysis.configuration as configuration

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert configuration.LoopConfiguration is configuration.Configuration
    assert [issubclass(w.category, FutureWarning) for w in caught] == [True]
    with pytest.raises(AttributeError):
        configuration.NoSuchName  # noqa: B018
