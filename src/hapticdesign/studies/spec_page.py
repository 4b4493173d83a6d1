"""What the spec sheet's page shows (the page itself: :mod:`hapticdesign.interface.report.spec_page`): its rows,
each value in words, and the vendor's numbers beside ours with the reason for each difference.

Vendor numbers (stated where they are known): the Phantom Premium 1.5's data sheet (nominal position
resolution 0.03 mm, continuous force 1.4 N, peak force 8.5 N, apparent mass at the tip under 75 g), Novint's published
figures of the Novint Falcon (4 x 4 x 4 in touch space, force over 2 lb, resolution over 400 dpi), and the stiffness
CHAI3D recommends for rendering on each (800 N/m, 3000 N/m). They are keyed by the published device's name: a device
file named so, or one deriving from it (``reference: falcon``), shows them.
"""

from __future__ import annotations

from hapticdesign.errors import UserError

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
        "resolution": (0.0635, "mm", "Novint publishes \"> 400 dpi\", a step under 25.4 / 400 = 0.0635 mm; ours is the "
                       "largest handle step of one count of any motor at the pose (320-slot wheels read in quadrature, "
                       "through the 0.110 / 0.01425 capstans): 0.038 mm at home, within Novint's figure."),
        "force_peak": (8.9, "N", "Novint publishes \"> 2 lb\" (8.9 N); libnifalcon states no motor torques, so "
                       "falcon.yaml has no force; falcon-assumed-motors.yaml assumes a peak torque that gives 9.0 N at "
                       "home in the weakest direction (an assumption fitted to this number, not a check of it)."),
        "workspace": (101.6, "mm", "Novint publishes a 4 x 4 x 4 in touch space (101.6 mm), presumably the extent of "
                      "the handle's travel; ours is the largest cube centred on home that a study reaches as its box on "
                      "grids 3 and 5 (90.0 mm with libnifalcon's geometry)."),
        "renderable_stiffness": (3000.0, "N/m", "CHAI3D's stiffness for the Falcon. falcon.yaml has no damping or "
                                 "friction data (libnifalcon gives none), so the model's exact limit and passivity "
                                 "bounds are zero; the Falcon renders walls thanks to its drives' friction and the hand: "
                                 "falcon-assumed-motors.yaml's assumed motor friction gives the simulated row."),
    },
}


def vendor_numbers(name: str) -> dict:
    """The published numbers of :data:`VENDOR` for the device ``name`` (a device file's own name, or the
    ``reference:`` a derived file names): none for a device without published numbers."""
    return VENDOR.get(name, {})


def check_reference(name: str) -> None:
    """A device file's ``reference:`` must name a device whose published numbers are known (:data:`VENDOR`); a
    one-line :class:`~hapticdesign.errors.UserError` otherwise."""
    if name not in VENDOR:
        raise UserError(f"reference: no published numbers of a device named {name!r} are known (known: "
                        f"{', '.join(VENDOR)})")


ROWS = [("resolution", "resolution", "mm"), ("force_continuous", "continuous force", "N"),
        ("force_peak", "peak force", "N"), ("apparent_mass", "apparent mass (min - max)", "kg"),
        ("backdrive_friction", "backdrive friction (min - max)", "N"), ("stiffness", "stiffness (VJM)", "N/m"),
        ("workspace", "workspace cube edge", "mm"), ("renderable_stiffness", "renderable stiffness", "N/m")]


def value_text(sheet: dict, key: str) -> str:
    """The sheet's ``key`` in words (resolution in mm): "not stated in the file" where the file lacks what it needs,
    the renderable stiffness too when the file states no damping and no friction (its exact limit and passivity
    bounds would print as 0 N/m, which would read as a measured zero)."""
    value = sheet.get(key)
    if value is None:
        return "not stated in the file"
    if key == "resolution":
        return f"{1000 * value:.4g}"
    if key in ("apparent_mass", "backdrive_friction"):
        return f"{value['min']:.4g} - {value['max']:.4g}"
    if key == "workspace":
        return f"{value['cube']:.4g}"
    if key == "renderable_stiffness":
        hand = value["hand"]
        simulated = "not run" if value["simulated"] is None else f"{value['simulated']:.4g}"
        exact = ("not stated (the file has no damping or friction, which bound it)"
                 if value["passivity_viscous"] == 0.0 and not value["passivity_coulomb"] else
                 f"stable from {value['exact_lower']:.4g} to {value['exact']:.4g}" if value.get("exact_lower")
                 else f"{value['exact']:.4g}")
        return (f"exact {exact}; with the {hand.get('name', 'given')} hand ({hand['mass']:g} kg, {hand['damping']:g} "
                f"N s/m, {hand['stiffness']:g} N/m) {value['exact_with_hand']:.4g}; simulated with dry friction and "
                f"quantization {simulated}; passivity: 2b/T = {value['passivity_viscous']:.4g}, 2 f_c / Delta = "
                + ("n/a" if value["passivity_coulomb"] is None else f"{value['passivity_coulomb']:.4g}")
                + f" (at {value['rate']:g} Hz, delay {value['delay']}, every joint free, drive "
                + ("rigid" if value.get("compliance", "rigid") == "rigid" else
                   f"compliance of the {value['compliance']}") + ")")
    return f"{value:.4g}"


