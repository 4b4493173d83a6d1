"""The reports in headless Chromium: they render, every image loads, the console stays clean."""

from __future__ import annotations

from pathlib import Path

import pytest

# end to end: deselect with -m "not slow"; one xdist worker takes every test of the shared smoke studies
# (`make test` runs --dist loadgroup), so that the other worker is not left waiting on their lock
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("smoke-studies")]


def _check(driver, report: Path, summary: dict) -> None:
    driver.get(report.resolve().as_uri())
    assert driver.execute_script("return document.readyState") == "complete"
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
    assert browser.execute_script("return document.readyState") == "complete"
    assert browser.find_element("tag name", "h1").text == "phantom-3dof"
    sliders = browser.execute_script("return document.querySelectorAll('input[type=range]').length")
    assert sliders == 3  # the 3-DOF Phantom's joints
    assert len(browser.execute_script("return window.deviceView.pose()")) == 3
    problems = [e for e in browser.get_log("browser") if e["level"] in ("SEVERE", "WARNING")]
    assert problems == []


def test_rcube_report_renders(browser, rcube_study):
    out, summary = rcube_study
    _check(browser, out / "report.html", summary)
