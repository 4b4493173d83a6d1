"""The spec sheet as an HTML page: our numbers beside the vendor's, with the reason for each difference.

Vendor numbers (stated where they are known): the Phantom Premium 1.5's data sheet (nominal position
resolution 0.03 mm, continuous force 1.4 N, peak force 8.5 N, apparent mass at the tip under 75 g) and the
stiffness CHAI3D recommends for rendering on it (800 N/m) and on the Novint Falcon (3000 N/m).
"""

from __future__ import annotations

import base64
import html

VENDOR = {
    "phantom-premium": {
        "resolution": (0.03, "mm", "our largest step of one count of any joint at home: 0.029 mm; the data "
                       "sheet's nominal figure rounds it (1024-line encoders, x4, capstans 11.2 and 13.3)."),
        "force_continuous": (1.4, "N", "ours is the force in the weakest direction at home (motor 2's 11.2 x "
                             "28.6 mN m over the 0.215 m upper arm, vertical); the data sheet's is lower, "
                             "presumably over its whole workspace or with a thermal margin."),
        "force_peak": (8.5, "N", "ours uses the 129 mN m stall torque in the weakest direction at home; the vendor's "
                       "peak is higher, presumably in a favourable direction or pose and with a higher peak "
                       "current than the stall data of the model."),
        "apparent_mass": (0.075, "kg", "ours at home with the rotors: 37 g along the forearm's swing, 81 g along "
                          "the base rotation (H11, the moments about the vertical and motor 1's reflected inertia, "
                          "over 0.215 m); the vendor's under 75 g is presumably at its nominal position and along its "
                          "main directions."),
        "renderable_stiffness": (800.0, "N/m", "CHAI3D's recommended stiffness is far above the exact limit of "
                                 "the model alone (its only damping is 0.0005 N m s/rad per joint, which bounds "
                                 "2b/T) but below the Coulomb passivity bound 2 f_c / Delta: the devices' dry "
                                 "friction and the user's hand dissipate the energy the sampled spring creates "
                                 "(Abbott & Okamura 2005; Diolaiti et al. 2006), as the limits with the hand and "
                                 "with friction and quantization show; a firmer grasp than the default raises the "
                                 "former."),
    },
    "falcon": {
        "renderable_stiffness": (3000.0, "N/m", "the file has no damping or friction data (libnifalcon gives "
                                 "none), so the model's exact limit and passivity bounds are zero; the Falcon "
                                 "renders walls thanks to its drives' friction and the hand, which the file "
                                 "does not hold."),
    },
}

ROWS = [("resolution", "resolution", "m"), ("force_continuous", "continuous force", "N"),
        ("force_peak", "peak force", "N"), ("apparent_mass", "apparent mass (min - max)", "kg"),
        ("backdrive_friction", "backdrive friction (min - max)", "N"), ("stiffness", "stiffness (VJM)", "N/m"),
        ("workspace", "workspace cube edge", "mm"), ("renderable_stiffness", "renderable stiffness", "N/m")]


def _value(sheet: dict, key: str) -> str:
    value = sheet.get(key)
    if value is None:
        return "not stated in the file"
    if key in ("apparent_mass", "backdrive_friction"):
        return f"{value['min']:.4g} - {value['max']:.4g}"
    if key == "workspace":
        return f"{value['cube']:.4g}"
    if key == "renderable_stiffness":
        hand = value["hand"]
        simulated = "not run" if value["simulated"] is None else f"{value['simulated']:.4g}"
        return (f"exact {value['exact']:.4g}; with the hand ({hand['mass']:g} kg, {hand['damping']:g} N s/m, "
                f"{hand['stiffness']:g} N/m) {value['exact_with_hand']:.4g}; simulated with dry friction and "
                f"quantization {simulated}; passivity: 2b/T = {value['passivity_viscous']:.4g}, 2 f_c / Delta = "
                + ("n/a" if value["passivity_coulomb"] is None else f"{value['passivity_coulomb']:.4g}")
                + f" (at {value['rate']:g} Hz, delay {value['delay_samples']}, every joint free)")
    return f"{value:.4g}"


def _figures(figures) -> str:
    """``(title, caption, png bytes)`` as embedded images (the page stays one self-contained file)."""
    out = []
    for title, caption, png in figures:
        data = base64.b64encode(png).decode("ascii")
        out.append(f"<h2>{html.escape(title)}</h2>\n<figure><img src=\"data:image/png;base64,{data}\" "
                   f"alt=\"{html.escape(title)}\" style=\"max-width: 100%\"><figcaption>{html.escape(caption)}"
                   "</figcaption></figure>\n")
    return "".join(out)


def spec_page(sheet: dict, figures=()) -> str:
    """A self-contained HTML page of ``sheet`` (:func:`hapticdesign.studies.spec.spec_sheet`) and ``figures``
    (``(title, caption, png bytes)``, e.g. :func:`hapticdesign.studies.spec_maps.workspace_png`); text escaped."""
    vendor = VENDOR.get(sheet["device"], {})
    rows = []
    for key, label, unit in ROWS:
        ours = _value(sheet, key)
        if key == "resolution" and sheet.get(key) is not None:
            ours = f"{1000 * sheet[key]:.4g}"
            unit = "mm"
        theirs, note = ("", "")
        if key in vendor:
            number, vendor_unit, note = vendor[key]
            theirs = f"{number:g} {vendor_unit}"
        rows.append("<tr>" + "".join(f"<td>{html.escape(str(cell))}</td>" for cell in (label, ours, unit, theirs, note))
                    + "</tr>")
    pose = ", ".join(f"{v:.4g}" for v in sheet["q"])
    handle = ", ".join(f"{1000 * v:.4g}" for v in sheet["handle"])
    return (
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>"
        f"{html.escape(sheet['device'])} spec sheet</title></head><body>\n"
        f"<h1>{html.escape(sheet['device'])}: spec sheet</h1>\n"
        f"<p>At q = ({html.escape(pose)}), handle at ({html.escape(handle)}) mm. Forces exclude gravity; "
        "definitions in hapticdesign.studies.spec.</p>\n"
        "<table border=\"1\"><tr><th>quantity</th><th>ours</th><th>unit</th><th>vendor</th><th>why they differ</th>"
        "</tr>\n" + "\n".join(rows) + "\n</table>\n" + _figures(figures) + "</body></html>\n"
    )
