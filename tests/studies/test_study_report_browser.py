"""The reports in headless Chromium: they render, every image loads, the console stays clean."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # end to end: deselect with -m "not slow"

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
DRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"
OPTIONS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
           "--disable-background-networking", "--disable-component-update", "--disable-sync")


@pytest.fixture(scope="module")
def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    if not (Path(CHROMIUM).exists() and Path(DRIVER).exists()):
        pytest.fail("chromium and chromedriver are needed (make browser installs them)")
    profile = tempfile.mkdtemp(prefix="hd-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in OPTIONS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


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


def test_rcube_report_renders(browser, rcube_study):
    out, summary = rcube_study
    _check(browser, out / "report.html", summary)
