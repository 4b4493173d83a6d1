"""User strings inside generated code and markup: escaped, never pasted.

Device names are free text (a file's ``name``, a URDF ``<robot name>``); they reach the
docstrings of generated Python (``eom --format python``, ``ln --symbolic --format python``), LaTeX
and HTML. Names that become code (coordinates, parameters, bodies) are validated as identifiers
where they enter (``devices/schema.py``, ``devices/urdf.py``); :func:`python_identifier` checks
them again at the point of export.
"""

from __future__ import annotations

import json
import keyword

from hapticdesign.errors import UserError


def docstring_text(text: str) -> str:
    """``text`` safe inside a triple-quoted Python string: every character outside printable ASCII,
    backslashes and quotes are escaped, so the string can neither end nor run anything."""
    out = []
    for ch in str(text):
        if ch in "\\\"'":
            out.append("\\" + ch)
        elif " " <= ch <= "~":
            out.append(ch)
        else:
            out.append(ch.encode("unicode_escape").decode("ascii"))
    return "".join(out)


def script_json(data) -> str:
    """``data`` as JSON safe inside an HTML ``<script type="application/json">`` element: ``<``, ``>`` and ``&``
    written as ``\\u003c``, ``\\u003e``, ``\\u0026`` (and every character outside ASCII escaped), so no string in
    it can close the element (``</script>``) or open a comment; ``JSON.parse`` of the element's text gives the data
    back. NaN and infinities are refused (write them as ``None``)."""
    text = json.dumps(data, allow_nan=False, separators=(",", ":"))
    return text.replace("&", "\\u0026").replace("<", "\\u003c").replace(">", "\\u003e")


def python_identifier(name: str) -> str:
    """``name`` if it is a Python identifier (not a keyword), else a one-line :class:`UserError`."""
    if not (name.isidentifier() and name.isascii() and not keyword.iskeyword(name)):
        raise UserError(f"{name[:40]!r} cannot be a name in generated code (use letters, digits and '_')")
    return name
