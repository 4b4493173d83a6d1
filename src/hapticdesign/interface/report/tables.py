"""Table cells as text: numbers with a fixed number of significant digits, CSV with full precision."""

from __future__ import annotations

import math
from numbers import Integral, Real
from typing import Any

from hapticdesign.files import csv_rows
from hapticdesign.studies.steps import Table


def cell_text(value: Any, digits: int = 6) -> str:
    """A readable cell: ``None`` empty, floats to ``digits`` significant digits, booleans yes/no."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, Integral):
        return str(int(value))
    if isinstance(value, Real):
        v = float(value)
        if math.isnan(v):
            return "NaN"
        return f"{v:.{digits}g}"
    return str(value)


def csv_text(table: Table) -> str:
    """The table as CSV; floats keep full precision (``repr``)."""
    return csv_rows(list(table.columns), (["" if v is None else repr(float(v)) if isinstance(v, Real)
                                           and not isinstance(v, (bool, Integral)) else v for v in row]
                                          for row in table.rows))
