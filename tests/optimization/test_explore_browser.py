"""The explorer served by ``hapticdesign explore`` and the explorer of a 1e5-evaluation study, in headless Chromium
(Debian's, through Selenium; WebGL by SwiftShader, as the large scatter traces need it).

Served, a design off the front picked on the page gets its card computed by the server: maps, a picture, the numbers
of its row of evaluations.csv; from ``file://`` the same page says where such a card comes from and requests nothing.
A study of 100,000 evaluations (seed 001's R-CUBE synthesis, population 1000, 100 generations) opens with no console
error and states how many designs it holds of how many: the front's and a sample of
:data:`~hapticdesign.optimization.study_explorer.EMBEDDED_LIMIT`, the total being evaluations.csv's rows.

Oracles: the files the runs wrote (evaluations.csv, front.csv), read with the csv module.
"""

from __future__ import annotations

import csv
import json
import math
import shutil
import tempfile
import threading
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app
from hapticdesign.interface.commands.explore_adapter import StudyFolder, server
from hapticdesign.optimization.study_explorer import EMBEDDED_LIMIT
from hapticdesign.optimization.study_outputs import without_unit
from tests.conftest import CHROMIUM, CHROMIUM_FLAGS, DRIVER
from tests.optimization.test_explore import VARIABLES, study  # noqa: F401 - the module's study fixture

pytestmark = pytest.mark.slow  # end to end in a browser: deselect with -m "not slow"

runner = CliRunner()
RCUBE = Path(__file__).resolve().parents[2] / "examples" / "devices" / "rcube.yaml"


@pytest.fixture(scope="module")
def gl_browser():
    """Debian's Chromium through Selenium, headless, with software WebGL (``--enable-unsafe-swiftshader``)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    if not (Path(CHROMIUM).exists() and Path(DRIVER).exists()):
        pytest.fail("chromium and chromedriver are needed (make browser installs them)")
    profile = tempfile.mkdtemp(prefix="hd-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in (*(f for f in CHROMIUM_FLAGS if f != "--disable-gpu"), "--enable-unsafe-swiftshader"):
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    driver.set_window_size(1300, 1000)
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return [{without_unit(k): v for k, v in row.items()} for row in csv.DictReader(f)]


def _open(driver, url: str) -> None:
    driver.get("about:blank")
    driver.get_log("browser")
    driver.get_log("performance")
    driver.get(url)
    for _ in range(200):
        if driver.execute_script("return !!window.hdExplorer"):
            return
        time.sleep(0.05)
    raise AssertionError("the explorer did not start")


def _errors(driver) -> list[dict]:
    """The console's errors and warnings, but the software GL driver's notes on its own speed (``GL Driver Message
    (OpenGL, Performance, ...): GPU stall due to ReadPixels``, of source ``rendering``: WebGL read back by Plotly's
    point picking), which are not the page's."""
    return [e for e in driver.get_log("browser") if e["level"] in ("SEVERE", "WARNING")
            and not (e["source"] == "rendering" and "GL Driver Message (OpenGL, Performance" in e["message"])]


def _card(driver) -> dict[str, float]:
    """The card's variables, objectives and constrained values by name (not its spec summary, data-kind spec)."""
    cells = driver.execute_script(
        "return Array.from(document.querySelectorAll('#design-card [data-name]:not([data-kind=spec])'))"
        ".map(function (e) { return [e.getAttribute('data-name'), e.getAttribute('data-value')]; })")
    return {name: float(value) if value else math.nan for name, value in cells}


def _requested(driver) -> set[str]:
    out = set()
    for entry in driver.get_log("performance"):
        message = json.loads(entry["message"])["message"]
        if message["method"] == "Network.requestWillBeSent":
            out.add(message["params"]["request"]["url"])
    return out


def test_served_the_page_gets_the_card_of_a_design_off_the_front(gl_browser, study):  # noqa: F811 - the fixture
    httpd = server(StudyFolder(study))
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    try:
        front = {tuple(r[v] for v in VARIABLES) for r in _rows(study / "front.csv")}
        row = next(r for r in _rows(study / "evaluations.csv")
                   if r["feasible"] == "yes" and tuple(r[v] for v in VARIABLES) not in front)
        origin = f"http://127.0.0.1:{httpd.server_address[1]}"
        _open(gl_browser, f"{origin}/report.html#pick={row['evaluation']}")
        for _ in range(600):
            if gl_browser.find_elements("css selector", "#design-card [data-map]"):
                break
            time.sleep(0.05)
        maps = gl_browser.execute_script("return Array.from(document.querySelectorAll('#design-card [data-map]'))"
                                         ".map(function (e) { return e.getAttribute('data-map'); })")
        assert sorted(maps) == ["apparent_mass", "isotropy"]
        assert gl_browser.find_elements("id", "card-picture")
        assert gl_browser.find_element("id", "design-card").get_attribute("data-evaluation") == row["evaluation"]
        expected = {k: float(v) if v else math.nan for k, v in row.items()
                    if k not in ("evaluation", "generation", "feasible", "reason")}
        assert _card(gl_browser) == expected
        assert gl_browser.find_elements("id", "card-spec")  # its spec summary too (tests/optimization/test_explore.py)
        requested = _requested(gl_browser)
        assert f"{origin}/api/card?evaluation={row['evaluation']}" in requested
        assert all(url.startswith((origin, "data:", "blob:")) for url in requested), requested
        assert _errors(gl_browser) == []
        # from disk the page does not ask: it says that the server computes such a card
        _open(gl_browser, (study / "report.html").resolve().as_uri() + f"#pick={row['evaluation']}")
        assert not gl_browser.find_elements("css selector", "#design-card [data-map]")
        assert "hapticdesign explore" in gl_browser.find_element("id", "design-card").text
        assert all(url.split(":", 1)[0] in ("file", "data", "blob") for url in _requested(gl_browser))
        assert _errors(gl_browser) == []
    finally:
        httpd.shutdown()
        httpd.server_close()


STUDY = """device: {device}
variables: {{q_max: [0.07, 1.5], l2: [0.001, 0.500], l3: [0.001, 0.500]}}
parameters: {{l1: "0.06 / sin(q_max)", S: "l1"}}
objectives:
  - {{name: O1, index: rcube_o1, reduce: max, sense: min}}
constraints:
  - {{index: rcube_constraint, options: {{point: C2}}, reduce: max, "<=": 0}}
algorithm: {{method: nsga2, population: 1000, generations: 100, polish: none}}
"""


def test_a_page_of_100000_evaluations_opens_and_says_how_many_it_shows(gl_browser, tmp_path):
    path = tmp_path / "study.yaml"
    path.write_text(STUDY.format(device=json.dumps(str(RCUBE))))
    result = runner.invoke(app, ["optimize", str(path), "--seed", "1", "--out", str(tmp_path / "out"), "--quiet"])
    assert result.exit_code == 0, result.output
    out = tmp_path / "out"
    count, front = len(_rows(out / "evaluations.csv")), len(_rows(out / "front.csv"))
    assert count == 100_000 and front < 100
    _open(gl_browser, (out / "report.html").resolve().as_uri())
    shown = gl_browser.find_element("id", "shown-count")
    assert (int(shown.get_attribute("data-shown")), int(shown.get_attribute("data-count"))) == \
        (front + EMBEDDED_LIMIT, count)
    assert f"{front + EMBEDDED_LIMIT:,} of the {count:,} evaluated designs" in shown.text
    assert f"{count} evaluated" in gl_browser.find_element("id", "filter-status").text
    state = gl_browser.execute_script("return window.hdExplorer.state()")
    passing = state["passing"]  # the embedded designs, by their evaluation numbers: rows of evaluations.csv
    assert len(passing) == front + EMBEDDED_LIMIT and passing == sorted(set(passing)) and passing[-1] <= count
    assert gl_browser.execute_script("return document.querySelectorAll('#objective-space .gl-container').length") > 0
    # Plotly drew them (its WebGL traces compile functions: the page's policy allows it, else it shows this note)
    assert "WebGL is not supported" not in gl_browser.find_element("id", "objective-space").text
    # a brush on the first parallel axis filters the 20,000 and more designs
    from selenium.webdriver.common.action_chains import ActionChains

    canvas = gl_browser.find_element("id", "parallel")
    gl_browser.execute_script("arguments[0].scrollIntoView({block: 'center'})", canvas)
    first_axis = gl_browser.execute_script("return window.hdExplorer.parallelLine(1)[0][0]")
    ActionChains(gl_browser).move_to_element_with_offset(canvas, int(first_axis - canvas.size["width"] / 2), -80) \
        .click_and_hold().move_by_offset(0, 60).move_by_offset(0, 60).release().perform()
    time.sleep(0.5)
    state = gl_browser.execute_script("return window.hdExplorer.state()")
    low, high = state["ranges"]["var:q_max"]
    rows = {int(r["evaluation"]): float(r["q_max"]) for r in _rows(out / "evaluations.csv")}
    assert state["passing"] == [n for n in passing if low <= rows[n] <= high]
    assert 0 < len(state["passing"]) < len(passing)
    assert _errors(gl_browser) == []
