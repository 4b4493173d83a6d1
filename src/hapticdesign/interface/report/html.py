"""The report as one HTML document: inline styles, base64 PNG figures, no scripts, no network."""

from __future__ import annotations

import base64
from html import escape

from hapticdesign.interface.report.tables import cell_text
from hapticdesign.studies.steps import STATUS_DONE, STATUS_MISSING, STATUS_SKIPPED, Figure, Page, StepResult, Table
from hapticdesign.studies.study import StudyResult

STYLE = """
body { font-family: "DejaVu Sans", Arial, sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em;
       color: #222; line-height: 1.45; }
h1 { border-bottom: 2px solid #446; padding-bottom: .3em; }
h2 { margin-top: 2em; border-bottom: 1px solid #ccd; }
table { border-collapse: collapse; margin: .6em 0 1.2em; font-size: .9em; }
th, td { border: 1px solid #bbc; padding: .25em .6em; text-align: right; }
th { background: #eef; }
td:first-child, th:first-child, td.text { text-align: left; }
.table-wrap { max-width: 100%; overflow-x: auto; }
table.wide { font-size: .75em; }
table.wide th { white-space: normal; }
caption { caption-side: top; text-align: left; font-weight: bold; padding: .3em 0; }
pre { background: #f6f6f8; border: 1px solid #dde; padding: .6em; overflow-x: auto; font-size: .85em;
      white-space: pre-wrap; overflow-wrap: anywhere; }
figure { margin: 1em 0; }
figure img { max-width: 100%; border: 1px solid #dde; }
figcaption { font-size: .9em; color: #444; }
.status-done { color: #1a6b1a; font-weight: bold; }
.status-not-available { color: #8a6d00; font-weight: bold; }
.status-failed { color: #a01818; font-weight: bold; }
.status-skipped { color: #555555; font-weight: bold; }
.note { font-size: .85em; color: #555; }
.files { font-size: .8em; }
"""


def _status(status: str) -> str:
    return f'<span class="status-{status.replace(" ", "-")}">{escape(status)}</span>'


def _cell(value) -> str:
    """Numbers right-aligned (the default), text left-aligned."""
    css = ' class="text"' if isinstance(value, str) else ""
    return f"<td{css}>{escape(cell_text(value))}</td>"


WIDE_TABLE = 8
"""Tables with more columns than this get a smaller font."""


def _table(table: Table, csv_href: str) -> str:
    """A table in a horizontally scrolling box, so that a wide table never overflows the page."""
    head = "".join(f"<th>{escape(c)}</th>" for c in table.columns)
    body = "".join("<tr>" + "".join(_cell(v) for v in row) + "</tr>" for row in table.rows)
    note = f'<p class="note">{escape(table.note)}</p>' if table.note else ""
    css = ' class="wide"' if len(table.columns) > WIDE_TABLE else ""
    return (f'<div class="table-wrap"><table{css}><caption>{escape(table.title)}</caption><thead><tr>{head}</tr></thead>'
            f'<tbody>{body}</tbody></table></div>{note}<p class="files"><a href="{escape(csv_href)}">{escape(csv_href)}</a></p>')


def _figure(figure: Figure, stem: str) -> str:
    data = base64.b64encode(figure.png).decode("ascii")
    caption = escape(figure.title + (": " + figure.caption if figure.caption else ""))
    return (f'<figure><img alt="{escape(figure.title)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{caption} <span class=\"files\">(<a href=\"{escape(stem)}.png\">PNG</a>, "
            f"<a href=\"{escape(stem)}.svg\">SVG</a>)</span></figcaption></figure>")


def _page(page: Page, href: str) -> str:
    """A link to a page beside the report: the report itself runs no scripts, the page carries its own."""
    return f'<p class="files">{escape(page.title)}: <a href="{escape(href)}">{escape(href)}</a></p>'


def _key_value_table(title: str, mapping: dict) -> str:
    rows = "".join(f"<tr><td>{escape(str(k))}</td><td>{escape(cell_text(v))}</td></tr>" for k, v in mapping.items())
    return f'<div class="table-wrap"><table><caption>{escape(title)}</caption><tbody>{rows}</tbody></table></div>'


def _explorer(step: StepResult, href: str) -> str:
    """A link to the step's designs in the design explorer (a page with scripts beside the report)."""
    return (f'<p class="files">{escape(step.outcome.explorer.title)}, in the design explorer: '
            f'<a href="{escape(href)}">{escape(href)}</a></p>')


def _step(step: StepResult, table_href, figure_stem, page_href, explorer_href) -> str:
    parts = [f'<h2 id="{escape(step.key)}">{escape(step.title)}</h2>',
             f"<p>{_status(step.status)} &middot; {step.seconds:.2f} s</p>"]
    if step.status != STATUS_DONE:
        why = {STATUS_MISSING: "This step builds on one that did not finish, so no numbers are shown.",
               STATUS_SKIPPED: "This step does not apply to this device:"}.get(
            step.status, "The engine raised an error; no numbers are shown.")
        parts.append(f"<p>{escape(why)}</p><pre>{escape(step.reason)}</pre>")
        return "\n".join(parts)
    out = step.outcome
    if out.summary:
        parts.append(f"<p><strong>{escape(out.summary)}</strong></p>")
    parts += [f"<p>{escape(p)}</p>" for p in out.paragraphs]
    for title, text in out.listings:
        parts.append(f"<p>{escape(title)}</p><pre>{escape(text)}</pre>")
    parts += [_table(t, table_href(step, t)) for t in out.tables]
    parts += [_figure(f, figure_stem(step, f)) for f in out.figures]
    parts += [_page(p, page_href(step, p)) for p in out.pages]
    if out.explorer is not None:
        parts.append(_explorer(step, explorer_href(step)))
    return "\n".join(parts)


def render(study: StudyResult, versions: dict[str, str], table_href, figure_stem, page_href, explorer_href) -> str:
    """The whole report. ``table_href(step, table)``, ``figure_stem(step, figure)``, ``page_href(step, page)`` and
    ``explorer_href(step)`` (a step's design explorer) name the files."""
    toc = "".join(
        f'<tr><td><a href="#{escape(s.key)}">{escape(s.title)}</a></td><td>{_status(s.status)}</td>'
        f"<td>{s.seconds:.2f}</td></tr>" for s in study.steps)
    overview = (f"<table><caption>Steps and timings (total {study.seconds:.1f} s)</caption><thead><tr><th>step</th>"
                f"<th>status</th><th>time [s]</th></tr></thead><tbody>{toc}</tbody></table>")
    body = "\n".join(_step(s, table_href, figure_stem, page_href, explorer_href) for s in study.steps)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{escape(study.title)}</title>
<link rel="icon" href="data:,">
<style>{STYLE}</style></head>
<body>
<h1>{escape(study.title)}</h1>
<p>{escape(study.intro)}</p>
<p class="note">Run started {escape(study.started)} (UTC); hapticdesign study <code>{escape(study.name)}</code>.</p>
{overview}
{body}
<h2 id="settings">Settings and versions</h2>
{_key_value_table("Settings", study.settings)}
{_key_value_table("Versions", versions)}
</body></html>
"""
