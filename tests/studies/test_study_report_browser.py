"""The reports in headless Chromium: they render, every image loads, the console stays clean; the phantom study's
campaign opens in the design explorer."""

from __future__ import annotations

import csv
import json
import time
from pathlib import Path

import pytest
from selenium.webdriver.support.ui import WebDriverWait
from typer.testing import CliRunner

from hapticdesign.interface.cli import app

# end to end: deselect with -m "not slow"; one xdist worker takes every test of the shared smoke studies
# (`make test` runs --dist loadgroup), so that the other worker is not left waiting on their lock
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("smoke-studies")]


def _loaded(driver) -> None:
    """Wait until the page and its images have loaded (Chromium may hand the page back while a large image of a busy
    machine is still decoding: readyState "interactive")."""
    WebDriverWait(driver, 120).until(lambda d: d.execute_script("return document.readyState") == "complete")


def _check(driver, report: Path, summary: dict) -> None:
    driver.get(report.resolve().as_uri())
    _loaded(driver)
    assert driver.title.startswith(("Phantom", "Modified R-CUBE"))
    sections = driver.execute_script("return Array.from(document.querySelectorAll('h2')).map(h => h.id)")
    assert set(summary["steps"]) <= set(sections)
    images = driver.execute_script(
        "return Array.from(document.images).map(i => [i.complete, i.naturalWidth, i.naturalHeight])")
    assert len(images) == len(list((report.parent / "figures").glob("*.png"))) > 0
    assert all(done and w > 0 and h > 0 for done, w, h in images)
    # wide tables scroll inside their box instead of widening the page
    assert driver.execute_script(
        "return document.documentElement.scrollWidth <= document.documentElement.clientWidth")
    problems = [e for e in driver.get_log("browser") if e["level"] in ("SEVERE", "WARNING")]
    assert problems == []


def test_phantom_report_renders(browser, phantom_study):
    out, summary = phantom_study
    _check(browser, out / "report.html", summary)


def test_report_opens_the_interactive_device_view(browser, phantom_study):
    """The report links the device page; following the link shows the device with a slider per joint."""
    out, _ = phantom_study
    browser.get((out / "report.html").resolve().as_uri())
    links = browser.execute_script(
        "return Array.from(document.querySelectorAll('a')).map(a => a.href).filter(h => h.includes('/pages/'))")
    assert len(links) == 1
    browser.get(links[0])
    _loaded(browser)
    assert browser.find_element("tag name", "h1").text == "phantom-3dof"
    sliders = browser.execute_script("return document.querySelectorAll('input[type=range]').length")
    assert sliders == 3  # the 3-DOF Phantom's joints
    assert len(browser.execute_script("return window.deviceView.pose()")) == 3
    problems = [e for e in browser.get_log("browser") if e["level"] in ("SEVERE", "WARNING")]
    assert problems == []


def test_rcube_report_renders(browser, rcube_study):
    out, summary = rcube_study
    _check(browser, out / "report.html", summary)


def test_the_phantom_campaign_opens_in_the_design_explorer(browser, phantom_study):
    """Linked from the report; no console message; the hook's designs are the design set's rows (the design-set step's
    CSV, read with the csv module) with the campaign's own results (its case files), and no evaluated design beats a
    front design in both objectives (the least LN, the largest K_max)."""
    out, _ = phantom_study
    browser.get((out / "report.html").resolve().as_uri())
    links = browser.execute_script(
        "return Array.from(document.querySelectorAll('a')).map(a => a.href).filter(h => h.includes('/explorer/'))")
    assert links == [(out / "explorer" / "campaign" / "report.html").resolve().as_uri()]
    browser.get(links[0])
    for _ in range(100):
        if browser.execute_script("return !!window.hdExplorer"):
            break
        time.sleep(0.05)
    [designs_csv] = (out / "work").glob("designs_smoke_*.csv")
    with designs_csv.open(newline="") as f:
        rows = [{"design": f"d{i:04d}", **row} for i, row in enumerate(csv.DictReader(f), start=1)]  # campaign's names
    [cases] = [p for p in (out / "work").glob("campaign_*/cases") if any(p.glob(f"{rows[0]['design']}__*"))]

    def k_max(row: dict) -> float:
        return json.loads((cases / f"{row['design']}__impedance__type1.json").read_text())["value"]

    front = browser.execute_script("return document.querySelectorAll('#front-table tbody tr').length")
    assert front >= 1 and browser.execute_script("return window.hdExplorer.state().selected") is not None
    points = []
    for n in range(1, front + 1):
        design = browser.execute_script("return window.hdExplorer.design(arguments[0])", n)
        [row] = [r for r in rows if all(float(r[k]) == v for k, v in design["variables"].items() if k != "level")]
        assert design["objectives"]["LN"] == float(row["ln"]) and design["variables"]["level"] == float(row["level"])
        assert design["objectives"]["K_max type 1"] == k_max(row)
        assert (out / "explorer" / "campaign" / design["file"]).is_file()
        points.append((design["objectives"]["LN"], design["objectives"]["K_max type 1"]))
    for row in rows:
        ln, k = float(row["ln"]), k_max(row)
        assert not any(ln <= a and k >= b and (ln, k) != (a, b) for a, b in points)
    shown = browser.find_element("id", "shown-count")  # every design of the design set, none sampled out
    assert (int(shown.get_attribute("data-shown")), int(shown.get_attribute("data-count"))) == (len(rows), len(rows))
    problems = [e for e in browser.get_log("browser") if e["level"] in ("SEVERE", "WARNING")]
    assert problems == []
    # hapticdesign explore serves optimize's folders: on the campaign's, one line and exit status 2
    done = CliRunner().invoke(app, ["explore", str(out / "explorer" / "campaign")])
    assert done.exit_code == 2 and done.stdout == "" and done.stderr.count("\n") == 1
    assert done.stderr.startswith("error: ") and "is not a study's output folder" in done.stderr
