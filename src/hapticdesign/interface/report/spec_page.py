"""The spec sheet's HTML page, in the reports' style (:data:`hapticdesign.interface.report.html.STYLE`): the sheet's
rows (:mod:`hapticdesign.studies.spec_page`), the vendor's numbers and the reasons for the differences where they
are known (the columns are left out for a device without vendor data), and the figures. One self-contained file,
every user string escaped."""

from __future__ import annotations

import base64
from html import escape

from hapticdesign.interface.report.html import STYLE
from hapticdesign.studies.spec_page import ROWS, value_text, vendor_numbers


def _figure(title: str, caption: str, png: bytes) -> str:
    data = base64.b64encode(png).decode("ascii")
    return (f"<h2>{escape(title)}</h2><figure><img alt=\"{escape(title)}\" src=\"data:image/png;base64,{data}\">"
            f"<figcaption>{escape(caption)}</figcaption></figure>")


def spec_page(sheet: dict, figures=()) -> str:
    """A self-contained HTML page of ``sheet`` (:func:`hapticdesign.studies.spec.spec_sheet`) and ``figures``
    (``(title, caption, png bytes)``, e.g. :func:`hapticdesign.studies.spec_maps.workspace_png`)."""
    reference = sheet.get("reference")
    vendor = vendor_numbers(reference or sheet["device"])
    published = f"vendor ({reference}, the published device)" if reference else "vendor"
    columns = ["quantity", "hapticdesign", "unit", *((published, "why they differ") if vendor else ())]
    rows = []
    for key, label, unit in ROWS:
        cells = [label, value_text(sheet, key), unit]
        if vendor:
            number, vendor_unit, why = vendor.get(key, (None, "", ""))
            cells += ["" if number is None else f"{number:g} {vendor_unit}", why]
        rows.append("<tr>" + "".join(f'<td class="text">{escape(c)}</td>' for c in cells) + "</tr>")
    for name, number in sheet.get("indices", {}).items():
        cells = [f"index {name}", f"{number:.4g}", sheet["units"]["indices"][name], *(("", "") if vendor else ())]
        rows.append("<tr>" + "".join(f'<td class="text">{escape(c)}</td>' for c in cells) + "</tr>")
    head = "".join(f"<th>{escape(c)}</th>" for c in columns)
    pose = ", ".join(f"{v:.4g}" for v in sheet["q"])
    handle = ", ".join(f"{1000 * v:.4g}" for v in sheet["handle"])
    title = f"{sheet['device']}: spec sheet"
    return (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>{escape(title)}</title>'
            f"<style>{STYLE}</style></head><body><h1>{escape(title)}</h1>"
            f"<p>At q = ({escape(pose)}), handle at ({escape(handle)}) mm. Forces exclude gravity; definitions in "
            "hapticdesign.studies.spec.</p>"
            f'<div class="table-wrap"><table><caption>The sheet at this pose</caption><thead><tr>{head}</tr></thead>'
            f"<tbody>{''.join(rows)}</tbody></table></div>"
            + "".join(_figure(*f) for f in figures) + "</body></html>\n")
