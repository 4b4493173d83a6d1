"""The affine value grammar of device files (hapticdesign.devices.schema.parse_expression)."""

from __future__ import annotations

import math

import pytest

from hapticdesign.devices.schema import parse_expression


@pytest.mark.parametrize(
    "text, constant, terms",
    [
        ("0.3", 0.3, {}),
        ("1e-3", 1e-3, {}),
        ("l2", 0.0, {"l2": 1.0}),
        ("-l2a", 0.0, {"l2a": -1.0}),
        ("-pi/2", -math.pi / 2, {}),
        ("2*pi/3", 2 * math.pi / 3, {}),
        ("-theta3", 0.0, {"theta3": -1.0}),
        ("theta5 - pi/2", -math.pi / 2, {"theta5": 1.0}),
        ("theta1 - theta2", 0.0, {"theta1": 1.0, "theta2": -1.0}),
        ("0.5*q1 + q1/2 + 1/4", 0.25, {"q1": 1.0}),
        ("q1 - q1 + la", 0.0, {"la": 1.0}),
    ],
)
def test_affine_expressions(text, constant, terms):
    expr = parse_expression(text)
    assert expr.constant == pytest.approx(constant, abs=1e-15)
    assert dict(expr.terms) == pytest.approx(terms)


@pytest.mark.parametrize("text", ["", "2*", "a*b", "--a", "a b", "l2**2", "x/0", "3*(a)", "cos(q1)", "q1 +", "1e400/0"])
def test_everything_else_is_refused(text):
    with pytest.raises(ValueError):
        parse_expression(text)
