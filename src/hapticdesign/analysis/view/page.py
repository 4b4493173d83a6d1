"""The device as one self-contained, interactive HTML page: a canvas, a slider per joint, no network.

The page embeds the skeleton of :mod:`.skeleton` as JSON (``<``, ``>`` and ``&`` written as
``\\u003c``, ``\\u003e``, ``\\u0026`` so no user string can close the data block) and a small
hand-written script that redoes the forward kinematics from the node table (seed 000 §2.1: each
node an elementary rotation or translation of value ``offset + coef . q``) and projects the frames
orthographically on a 2D canvas. User strings reach the page only as escaped text (``html.escape``)
or through ``textContent`` and canvas ``fillText``; a Content-Security-Policy allows no network
access and only the page's own script (by its SHA-256 hash).
"""

from __future__ import annotations

import base64
import hashlib
from html import escape
from importlib.resources import files

from hapticdesign.escape import script_json

STYLE = """
body { font-family: "DejaVu Sans", Arial, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; margin: 0 0 .3em; }
.note { font-size: .85em; color: #555; margin: .2em 0 .8em; }
#view { display: flex; flex-wrap: wrap; gap: 1.2em; align-items: flex-start; }
canvas { border: 1px solid #ccd; background: #fbfbfd; cursor: grab; max-width: 100%; }
#controls { min-width: 260px; }
#controls label { display: block; font-size: .9em; margin-top: .6em; }
#controls input[type=range] { width: 240px; }
#controls output { font-family: monospace; margin-left: .4em; }
"""


def script() -> str:
    """The page's JavaScript (``device_view.js`` next to this module)."""
    return files("hapticdesign.analysis.view").joinpath("device_view.js").read_text(encoding="utf-8")


def embedded_json(data: dict) -> str:
    """JSON safe inside ``<script type="application/json">``: no ``<``, ``>`` or ``&`` left to close it
    (:func:`hapticdesign.escape.script_json`)."""
    return script_json(data)


def render_page(data: dict) -> str:
    """The whole page for skeleton data (:func:`hapticdesign.analysis.view.skeleton.export`)."""
    code = script()
    digest = base64.b64encode(hashlib.sha256(code.encode("utf-8")).digest()).decode("ascii")
    policy = f"default-src 'none'; script-src 'sha256-{digest}'; style-src 'unsafe-inline'"
    name = escape(str(data["name"]))
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        f"<meta http-equiv=\"Content-Security-Policy\" content=\"{policy}\">\n"
        f"<title>{name}: device view</title>\n<style>{STYLE}</style>\n</head>\n<body>\n"
        f"<h1>{name}</h1>\n"
        "<p class=\"note\">Drag to turn the view, use the wheel to zoom. Thin lines join each frame's origin to "
        "its parent's (links); thick bars are bodies (from their frame's origin to twice their mass centre, as a "
        "uniform bar); grey plates are rigid bodies through three or more frame origins; the bar at the bottom "
        "left is the scale; grey dots are frame origins, the orange dot is the end effector, red discs are mass "
        "centres (area proportional to mass), purple rings mark loop closures; axes x, y, z of the base in red, "
        "green, blue.</p>\n"
        "<div id=\"view\"><canvas id=\"canvas\" width=\"720\" height=\"540\"></canvas>"
        "<div id=\"controls\"><label><input type=\"checkbox\" id=\"labels\"> frame names</label></div></div>\n"
        f"<script type=\"application/json\" id=\"device-data\">{embedded_json(data)}</script>\n"
        f"<script>{code}</script>\n</body>\n</html>\n"
    )
