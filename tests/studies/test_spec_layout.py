"""The spec sheet in the reports' style, fitted to planar devices: axes in the base's order, titles inside the
figure, no empty vendor columns, "not stated" where the file states nothing."""

import re

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402

from hapticdesign.interface.report.html import STYLE  # noqa: E402
from hapticdesign.interface.report.spec_page import spec_page  # noqa: E402
from hapticdesign.studies.spec_maps import Section, planes, section_figure  # noqa: E402

SHEET = {"device": "five-bar", "q": [0.1, 0.2], "handle": [0.01, 0.0, 0.12], "resolution": 2e-5,
         "force_continuous": None, "force_peak": None, "apparent_mass": {"min": 0.05, "max": 0.2},
         "backdrive_friction": None, "stiffness": None, "workspace": {"cube": 60.0},
         "renderable_stiffness": {"exact": 0.0, "rate": 1000.0, "delay": 1, "passivity_viscous": 0.0,
                                  "passivity_coulomb": None, "exact_with_hand": 1345.0, "simulated": None,
                                  "hand": {"mass": 0.1, "damping": 2.0, "stiffness": 200.0}}}


def test_a_planar_device_moving_in_z_then_x_draws_an_x_z_plane():
    """The handle's directions at home in the order (-z, x): the section is the x-z plane, axes +x and +z."""
    (names, axes), = planes(np.array([[0.0, 1.0], [0.0, 0.0], [-1.0, 0.0]]))
    assert names == ("x", "z")
    np.testing.assert_array_equal(axes, [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def test_a_single_section_keeps_its_long_title_inside_the_figure():
    offsets = np.linspace(-0.09, 0.09, 5)
    section = Section(("x", "z"), np.eye(3)[[0, 2]], offsets, offsets, np.ones((5, 5), bool), np.zeros((5, 5, 2)))
    title = "a five-bar with a long descriptive name from its device file: the sheet's quantities over the workspace"
    fig = section_figure([section], 0.06, title)
    fig.canvas.draw()
    box, page = fig._suptitle.get_window_extent(), fig.bbox
    assert box.x0 >= page.x0 and box.x1 <= page.x1
    assert fig.axes[0].get_title() == "x-z plane through home"


def test_the_page_uses_the_reports_style_and_states_what_the_file_does_not():
    page = spec_page(SHEET)
    assert STYLE in page and 'class="table-wrap"' in page
    heads = re.findall(r"<th>(.*?)</th>", page)
    assert heads == ["quantity", "hapticdesign", "unit"]  # no vendor data for this device: no empty columns
    row = re.search(r"<td class=\"text\">renderable stiffness</td><td class=\"text\">(.*?)</td>", page)
    assert row.group(1).startswith("exact not stated") and not re.search(r"(?<![\d.])0 N/m", page)
    assert "0.02</td>" in page  # resolution in mm
    falcon = spec_page({**SHEET, "device": "falcon"})
    assert re.findall(r"<th>(.*?)</th>", falcon)[-2:] == ["vendor", "why they differ"] and "3000 N/m" in falcon
