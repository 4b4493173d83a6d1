"""Formulas of a study file: a device parameter computed from the study's variables (``0.06 / sin(q_max)``), a
quantity minimized before the search (``l1 + l2 + l3``) or a filter of the front (docs/optimization.md).

A formula is data, never code: it is read by Python's own parser (:func:`ast.parse`, which only reads) and
evaluated by walking the tree, which admits numbers, names, ``pi``, the operators ``+ - * / **`` and the functions
of :data:`FUNCTIONS` (NumPy's, so that a formula evaluates a whole batch of designs at once). Anything else (an
attribute, a subscript, a call of another name, a string) is refused with a one-line message.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from hapticdesign.errors import UserError

FUNCTIONS = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan,
             "sqrt": np.sqrt, "exp": np.exp, "log": np.log, "abs": np.abs}
"""The functions a formula may call."""

MAX_LENGTH = 1000
MAX_DEPTH = 50
"""Most nested operations in a formula (the evaluation recurses once per level)."""
_OPERATORS = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.divide, ast.Pow: np.power}


@dataclass(frozen=True)
class Formula:
    """A checked formula: its ``text`` and the ``names`` it reads (``pi`` excluded)."""

    text: str

    @cached_property
    def tree(self) -> ast.expr:
        if len(self.text) > MAX_LENGTH:
            raise UserError(f"a formula has at most {MAX_LENGTH} characters")
        try:
            tree = ast.parse(self.text.strip(), mode="eval").body
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            raise UserError(f"cannot read the formula {self.text[:60]!r}") from None
        levels = [(tree, 1)]
        while levels:
            node, depth = levels.pop()
            if depth > MAX_DEPTH:
                raise UserError(f"formula {self.text[:60]!r}: more than {MAX_DEPTH} nested operations")
            self._check(node)
            levels += [(child, depth + 1) for child in ast.iter_child_nodes(node)]
        return tree

    def _check(self, node: ast.AST) -> None:
        allowed = (ast.BinOp, ast.UnaryOp, ast.Name, ast.Load, ast.Call, ast.UAdd, ast.USub, *_OPERATORS)
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                raise UserError(f"formula {self.text[:60]!r}: {str(node.value)[:20]!r} is not a number")
            value = node.value
            if abs(value) >= 2 ** 1000 if isinstance(value, int) else not math.isfinite(value):
                raise UserError(f"formula {self.text[:60]!r}: a number is too large")
        elif isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS or node.keywords \
                    or len(node.args) != 1:
                raise UserError(f"formula {self.text[:60]!r}: a call is one of {', '.join(FUNCTIONS)} of one argument")
        elif not isinstance(node, allowed):
            raise UserError(f"formula {self.text[:60]!r}: only numbers, names, + - * / ** and "
                            f"{', '.join(FUNCTIONS)} are allowed")

    @property
    def names(self) -> tuple[str, ...]:
        called = {id(n.func) for n in ast.walk(self.tree) if isinstance(n, ast.Call)}
        found = [n.id for n in ast.walk(self.tree) if isinstance(n, ast.Name) and id(n) not in called and n.id != "pi"]
        return tuple(dict.fromkeys(found))

    def value(self, values: Mapping[str, float | np.ndarray]):
        """The formula at ``values`` (numbers or arrays of one design per entry)."""
        with np.errstate(all="ignore"):
            return self._eval(self.tree, values)

    def _eval(self, node: ast.expr, values):
        if isinstance(node, ast.Constant):
            return float(node.value)
        if isinstance(node, ast.Name):
            if node.id == "pi":
                return math.pi
            if node.id not in values:
                raise UserError(f"formula {self.text[:60]!r}: unknown name {node.id!r}")
            return values[node.id]
        if isinstance(node, ast.UnaryOp):
            operand = self._eval(node.operand, values)
            return -operand if isinstance(node.op, ast.USub) else operand
        if isinstance(node, ast.BinOp):
            return _OPERATORS[type(node.op)](self._eval(node.left, values), self._eval(node.right, values))
        return FUNCTIONS[node.func.id](self._eval(node.args[0], values))


def formula(text: object) -> Formula:
    """A :class:`Formula` of ``text``, checked (a one-line UserError otherwise)."""
    if not isinstance(text, str) or not text.strip():
        raise UserError(f"a formula is a text such as 0.06 / sin(q_max), got {text!r}")
    out = Formula(text)
    _ = out.tree
    return out
