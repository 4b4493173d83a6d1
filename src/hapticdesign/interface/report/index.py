"""``index.html`` for a folder of loose results (PNG and SVG figures, CSV tables, Markdown and JSON files).

``campaign``, ``zwidth`` and ``rcube maps`` write their figures and tables as files; the index shows them on one
page: each PNG inline (with its SVG linked when there is one), each CSV as a table (its first rows) with a link,
other files as links. Paths are relative to the folder, in sorted order, and the page holds no date or absolute
path, so the same files give the same bytes. Every file name, title and cell is escaped (``html.escape``; links
percent-encoded); the page has no script and loads nothing from the network.
"""

from __future__ import annotations

import csv
import io
from html import escape
from pathlib import Path
from urllib.parse import quote

from hapticdesign.files import write_atomically

INDEX_NAME = "index.html"
STYLE = """
body { font-family: "DejaVu Sans", Arial, sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em; color: #222; }
table { border-collapse: collapse; font-size: .85em; }
th, td { border: 1px solid #bbc; padding: .2em .5em; text-align: right; }
th { background: #eef; }
.table-wrap { max-width: 100%; overflow-x: auto; }
figure img { max-width: 100%; border: 1px solid #dde; }
.note { font-size: .85em; color: #555; }
"""
CSV_ROWS = 30
"""Rows of a CSV file shown in the index (the link gives the whole file)."""


def _href(path: str) -> str:
    return escape(quote(path), quote=True)


def _csv_table(text: str) -> tuple[list[str], list[list[str]], int]:
    rows = list(csv.reader(io.StringIO(text)))
    if not rows:
        return [], [], 0
    return rows[0], rows[1:CSV_ROWS + 1], len(rows) - 1


def _table(name: str, text: str) -> str:
    head, rows, total = _csv_table(text)
    shown = f"all {total} rows" if total <= CSV_ROWS else f"the first {CSV_ROWS} of {total} rows"
    cells = "".join(f"<th>{escape(c)}</th>" for c in head)
    body = "".join("<tr>" + "".join(f"<td>{escape(c)}</td>" for c in row) + "</tr>" for row in rows)
    return (f'<h3><a href="{_href(name)}">{escape(name)}</a></h3>\n<div class="table-wrap"><table><thead><tr>{cells}'
            f'</tr></thead><tbody>{body}</tbody></table></div>\n<p class="note">{escape(shown)}</p>\n')


def folder_index(title: str, description: str, folder: Path, files) -> str:
    """The index page of ``files`` (paths inside ``folder``)."""
    folder = Path(folder)
    names = sorted({Path(f).resolve().relative_to(folder.resolve()).as_posix() for f in files})
    figures = [n for n in names if n.endswith(".png")]
    tables = [n for n in names if n.endswith(".csv")]
    svgs = {n for n in names if n.endswith(".svg")}
    beside_png = {n for n in svgs if n[:-4] + ".png" in figures}
    others = [n for n in names if n not in set(figures) | set(tables) | beside_png]
    parts = [f"<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{escape(title)}</title>\n"
             f"<style>{STYLE}</style>\n</head>\n<body>\n<h1>{escape(title)}</h1>\n<p>{escape(description)}</p>\n"]
    if figures:
        parts.append("<h2>Figures</h2>\n")
        for name in figures:
            svg = name[:-4] + ".svg"
            link = f' (<a href="{_href(svg)}">SVG</a>)' if svg in svgs else ""
            parts.append(f'<figure><img src="{_href(name)}" alt="{escape(name)}"><figcaption><a href="{_href(name)}">'
                         f"{escape(name)}</a>{link}</figcaption></figure>\n")
    if tables:
        parts.append("<h2>Tables</h2>\n")
        for name in tables:
            parts.append(_table(name, (folder / name).read_text(encoding="utf-8", errors="replace")))
    if others:
        parts.append("<h2>Other files</h2>\n<ul>\n")
        parts.extend(f'<li><a href="{_href(name)}">{escape(name)}</a></li>\n' for name in others)
        parts.append("</ul>\n")
    parts.append("</body>\n</html>\n")
    return "".join(parts)


def write_folder_index(folder: Path, title: str, description: str, files) -> Path:
    """Write ``folder/index.html`` for ``files`` (atomically) and return its path."""
    path = Path(folder) / INDEX_NAME
    write_atomically(path, folder_index(title, description, folder, files))
    return path
