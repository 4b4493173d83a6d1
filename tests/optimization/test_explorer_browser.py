"""The report of ``optimize`` is a design explorer: in headless Chromium (Debian's, through Selenium) it loads from
``file://`` with no request but ``file:``, ``data:`` and ``blob:`` and no console message; a real click on a front point
or on a line of the parallel coordinates fills the design card with that design's row of front.csv; a map's least
value is the objective that reduces it; pins fill the comparison; the address restores the view; a hostile objective
name stays text; two, three and one objectives each get their plots.

Oracles are the files the run wrote beside the page (front.csv, evaluations.csv), read here with the csv module, and
the CLI's ``--json`` answer (which design was selected); where a pixel is needed it comes from Plotly's own axis
mapping of front.csv's numbers (``l2p``), or the drawing of the canvas component, never from the click handler.
"""

from __future__ import annotations

import csv
import json
import math
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app
from hapticdesign.optimization.study_outputs import without_unit
from tests.optimization.test_study_run import ISOTROPY, MASS, point, write_study

pytestmark = pytest.mark.slow  # end to end in a browser: deselect with -m "not slow"

runner = CliRunner()
HOSTILE = "<img src=x onerror=document.title='X'>"
STIFFNESS = {"name": "stiffness", "index": "stiffness", "reduce": "min", "sense": "max"}
VARIABLES = {"l1": [0.15, 0.25], "l2": [0.1, 0.2]}


def _run(folder: Path, objectives: list[dict]) -> tuple[Path, dict]:
    """A small study (population 8, 2 generations, a 3 x 3 grid) run into ``folder / "out"``: the output folder and
    the ``--json`` answer."""
    folder.mkdir(parents=True, exist_ok=True)
    path = write_study(folder, VARIABLES, objectives, population=8, generations=2, center=point(0.2),
                       size=(0.03, 0.0, 0.03), grid=3)
    result = runner.invoke(app, ["optimize", str(path), "--seed", "1", "--out", str(folder / "out"), "--json", "--quiet"])
    assert result.exit_code == 0, result.output
    return folder / "out", json.loads(result.stdout)


def _rows(path: Path) -> list[dict[str, str]]:
    """The CSV's rows keyed by the study's names (the headers carry units: ``l1 [m]`` -> ``l1``)."""
    with path.open(newline="") as f:
        return [{without_unit(k): v for k, v in row.items()} for row in csv.DictReader(f)]


@pytest.fixture(scope="module")
def two(tmp_path_factory) -> tuple[Path, dict]:
    return _run(tmp_path_factory.mktemp("two"), [ISOTROPY, MASS])


def _open(driver, url: str) -> None:
    driver.set_window_size(1300, 1000)
    if driver.current_url != "about:blank":
        driver.get("about:blank")
    driver.get(url)
    for _ in range(100):
        if driver.execute_script("return !!window.hdExplorer"):
            return
        time.sleep(0.05)
    raise AssertionError("the explorer did not start")


def _console(driver) -> list[dict]:
    return [e for e in driver.get_log("browser") if e["level"] in ("SEVERE", "WARNING")]


def _card(driver, kind: str = ":not([data-kind=spec])") -> dict[str, float]:
    """The card's numbers by name: its variables, objectives and constrained values (``kind="[data-kind=spec]"``: its
    spec summary)."""
    cells = driver.execute_script(
        "return Array.from(document.querySelectorAll('#design-card [data-name]' + arguments[0])).map(function (e) {"
        " return [e.getAttribute('data-name'), e.getAttribute('data-value')]; })", kind)
    return {name: float(value) if value else math.nan for name, value in cells}


def _expected(row: dict[str, str]) -> dict[str, float]:
    return {name: float(value) for name, value in row.items() if name not in ("design", "polished")}


def _click_at(driver, x: float, y: float) -> None:
    """A real click at the viewport point (x, y) (the mouse moved there first, as a hand would)."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.actions.action_builder import ActionBuilder

    actions = ActionBuilder(driver)
    actions.pointer_action.move_to_location(int(round(x)), int(round(y)))
    actions.perform()
    time.sleep(0.2)  # Plotly finds the point under the mouse on its hover
    ActionChains(driver).click().perform()
    time.sleep(0.3)


def test_the_page_loads_from_disk_with_no_request_and_no_console_message(network_browser, two):
    out, _ = two
    from plotly.offline import get_plotlyjs

    assert (out / "plotly.min.js").read_text(encoding="utf-8") == get_plotlyjs()  # the installed package's, no CDN
    network_browser.get("about:blank")
    network_browser.get_log("performance")  # the browser's own start (its new-tab page) is not the report's
    _open(network_browser, (out / "report.html").resolve().as_uri())
    time.sleep(0.5)
    requested = set()
    for entry in network_browser.get_log("performance"):
        message = json.loads(entry["message"])["message"]
        if message["method"] == "Network.requestWillBeSent":
            requested.add(message["params"]["request"]["url"])
    assert requested and all(url.split(":", 1)[0] in ("file", "data", "blob") for url in requested), requested
    assert any(url.endswith("/plotly.min.js") for url in requested)
    assert network_browser.execute_script("return typeof Plotly") == "object"
    assert _console(network_browser) == []
    # each front design's device file was written where its card says
    front = _rows(out / "front.csv")
    for n in range(1, len(front) + 1):
        design = network_browser.execute_script("return window.hdExplorer.design(arguments[0])", n)
        assert (out / design["file"]).is_file()
        assert {k: design["variables"][k] for k in VARIABLES} == {k: float(front[n - 1][k]) for k in VARIABLES}


def test_a_click_on_a_front_point_fills_the_card_with_its_front_csv_row(browser, two):
    out, answer = two
    front = _rows(out / "front.csv")
    assert len(front) >= 2
    _open(browser, (out / "report.html").resolve().as_uri())
    selected = answer["selected"]["design"]
    assert _card(browser) == _expected(front[selected - 1])  # the card opens on the selected design
    browser.execute_script("document.getElementById('objective-space').scrollIntoView({block: 'center'})")
    to_pixel = ("var gd = document.getElementById('objective-space'), L = gd._fullLayout,"
                " box = gd.querySelector('.nsewdrag').getBoundingClientRect();"
                " return [box.left + L.xaxis.l2p(arguments[0]), box.top + L.yaxis.l2p(arguments[1])];")
    pixels = [browser.execute_script(to_pixel, float(r["iso"]), float(r["mass"])) for r in front]
    others = [browser.execute_script(to_pixel, float(r["iso"]), float(r["mass"]))
              for r in _rows(out / "evaluations.csv") if r["iso"] and r["mass"]]

    def room(n: int) -> float:  # how far front design n's point lies from every other evaluated design's
        x, y = pixels[n - 1]
        return min((math.hypot(x - a, y - b) for a, b in others if math.hypot(x - a, y - b) > 0.5), default=math.inf)

    n = max((k for k in range(1, len(front) + 1) if k != selected), key=room)
    assert room(n) > 3.0
    _click_at(browser, *pixels[n - 1])
    assert _card(browser) == _expected(front[n - 1])
    assert browser.execute_script("return window.hdExplorer.state().selected") == n
    assert _console(browser) == []


def test_a_click_on_a_line_of_the_parallel_coordinates_picks_that_design(browser, two):
    out, _ = two
    front = _rows(out / "front.csv")
    _open(browser, (out / "report.html").resolve().as_uri())
    browser.execute_script("window.hdExplorer.select(1); document.getElementById('parallel').scrollIntoView({block: 'center'})")
    lines = {n: browser.execute_script("return window.hdExplorer.parallelLine(arguments[0])", n)
             for n in range(1, len(front) + 1)}

    def best_spot(n: int) -> tuple[float, float, float]:  # the middle of a segment of n's line farthest from the others
        spots = []
        for i in range(len(lines[n]) - 1):
            x, y = (lines[n][i][0] + lines[n][i + 1][0]) / 2, (lines[n][i][1] + lines[n][i + 1][1]) / 2
            gap = min((abs(y - (line[i][1] + line[i + 1][1]) / 2) for m, line in lines.items() if m != n), default=99)
            spots.append((gap, x, y))
        return max(spots)

    n = max(range(2, len(front) + 1), key=lambda k: best_spot(k)[0])
    gap, x, y = best_spot(n)
    assert gap > 3.0
    box = browser.execute_script("var r = document.getElementById('parallel').getBoundingClientRect(),"
                                 " c = document.getElementById('parallel'); return [r.left, r.top, r.width / c.width];")
    _click_at(browser, box[0] + x * box[2], box[1] + y * box[2])
    assert _card(browser) == _expected(front[n - 1])


def _sheet_value(sheet: dict, path: str) -> float:
    for key in path.split("."):
        sheet = sheet[key]
    return math.nan if sheet is None else float(sheet)


def test_the_cards_spec_summary_is_what_spec_says_of_its_device_file(browser, two, monkeypatch):
    """Oracle: ``hapticdesign spec --json`` on the device file the card names, run in the output folder (the card's
    own command, without the workspace cube and the simulation the summary leaves out)."""
    out, _ = two
    front = _rows(out / "front.csv")
    _open(browser, (out / "report.html").resolve().as_uri())
    monkeypatch.chdir(out)
    for n in (1, len(front)):
        browser.execute_script("window.hdExplorer.select(arguments[0])", n)
        card = _card(browser, "[data-kind=spec]")
        design = browser.execute_script("return window.hdExplorer.design(arguments[0])", n)
        assert design["commands"][0]["command"] == f"hapticdesign spec --device {design['file']}"
        done = runner.invoke(app, ["spec", "--device", design["file"], "--json", "--no-workspace", "--no-simulate"])
        assert done.exit_code == 0, done.output
        sheet = json.loads(done.stdout)
        assert set(card) == {"force_continuous", "force_peak", "resolution", "apparent_mass.min", "apparent_mass.max",
                             "renderable_stiffness.exact", "renderable_stiffness.exact_with_hand"}
        for name, value in card.items():
            expected = _sheet_value(sheet, name)
            assert (math.isnan(value) and math.isnan(expected)) or value == expected, name
        units = browser.execute_script("return Array.from(document.querySelectorAll('#card-spec tr')).slice(1)"
                                       ".map(function (tr) { return tr.lastChild.textContent; })")
        assert units == ["N", "N", "m", "kg", "kg", "N/m", "N/m"] == [sheet["units"][k.split(".")[0]] for k in card]
    assert _console(browser) == []


def test_each_map_reduces_to_its_objective(browser, two):
    out, _ = two
    front = _rows(out / "front.csv")
    _open(browser, (out / "report.html").resolve().as_uri())
    for n, row in enumerate(front, start=1):
        maps = browser.execute_script("return window.hdExplorer.design(arguments[0]).maps", n)
        assert len(maps["isotropy"]["points"]) == 9 == len(maps["isotropy"]["values"])
        assert min(maps["isotropy"]["values"]) == float(row["iso"])  # ISOTROPY: the min of isotropy
        mean = math.fsum(maps["apparent_mass"]["values"]) / 9  # MASS: the mean of apparent_mass
        assert mean == pytest.approx(float(row["mass"]), rel=1e-13)


def test_pins_fill_the_comparison_and_the_address_restores_the_view(browser, two):
    out, _ = two
    front = _rows(out / "front.csv")
    _open(browser, (out / "report.html").resolve().as_uri())
    pinned = [1, len(front)]
    for n in pinned:
        browser.execute_script("window.hdExplorer.select(arguments[0])", n)
        browser.find_element("id", "pin-button").click()
    compare = browser.find_element("id", "compare")
    assert [e.get_attribute("data-design") for e in compare.find_elements("css selector", "[data-design]")] == \
        [str(n) for n in pinned]
    cells = browser.execute_script(
        "return Array.from(document.querySelectorAll('#compare tr')).slice(1).map(function (tr) {"
        " return Array.from(tr.querySelectorAll('[data-name]')).map(function (e) { return [e.getAttribute('data-name'),"
        " e.getAttribute('data-value')]; }); })")
    for k, n in enumerate(pinned):
        assert {row[k][0]: float(row[k][1]) for row in cells} == _expected(front[n - 1])
    low, high = sorted(float(r["l2"]) for r in front)[:2]
    browser.execute_script("window.hdExplorer.filter('var:l2', arguments[0], arguments[1]);"
                           " window.hdExplorer.select(arguments[2])", low, high, 2)
    before = browser.execute_script("return window.hdExplorer.state()")
    passing = [int(r["evaluation"]) for r in _rows(out / "evaluations.csv") if low <= float(r["l2"]) <= high]
    assert before["passing"] == passing
    url = browser.current_url
    assert "#" in url
    _open(browser, url)
    assert browser.execute_script("return window.hdExplorer.state()") == before
    assert _card(browser) == _expected(front[1])
    assert len(browser.find_elements("css selector", "#compare [data-design]")) == 2
    assert _console(browser) == []


def test_three_objectives_one_of_them_hostile_get_a_pair_plot_and_run_nothing(browser, tmp_path):
    out, _ = _run(tmp_path, [ISOTROPY, dict(MASS, name=HOSTILE), STIFFNESS])
    page = (out / "report.html").read_text(encoding="utf-8")
    assert HOSTILE not in page
    _open(browser, (out / "report.html").resolve().as_uri())
    title = browser.title
    assert browser.execute_script("return Object.keys(document.getElementById('pairs')._fullLayout)"
                                  ".filter(function (k) { return /^xaxis\\d*$/.test(k); }).length") == 3
    # the name shows as text in the card, the plots' axes and the comparison, and runs nothing
    browser.execute_script("window.hdExplorer.pin(1); window.hdExplorer.select(1)")
    names = browser.execute_script("return Array.from(document.querySelectorAll('#design-card [data-name]'))"
                                   ".map(function (e) { return e.getAttribute('data-name'); })")
    assert HOSTILE in names
    assert HOSTILE in browser.execute_script("return document.getElementById('pairs').textContent")
    browser.execute_script("document.getElementById('y-axis').value = arguments[0];"
                           " document.getElementById('y-axis').dispatchEvent(new Event('change'))", "obj:" + HOSTILE)
    assert HOSTILE in browser.execute_script("return document.getElementById('objective-space').textContent")
    time.sleep(0.3)
    assert browser.title == title != "X"
    assert browser.execute_script("return Array.from(document.images).filter(function (i) {"
                                  " return i.getAttribute('src') === 'x'; }).length") == 0
    assert _console(browser) == []


def test_one_objective_is_plotted_against_each_variable(browser, tmp_path):
    out, _ = _run(tmp_path, [ISOTROPY])
    _open(browser, (out / "report.html").resolve().as_uri())
    state = browser.execute_script("return window.hdExplorer.state()")
    assert (state["x"], state["y"]) == ("var:l1", "obj:iso")
    titles = browser.execute_script("var L = document.getElementById('pairs')._fullLayout; return Object.keys(L)"
                                    ".filter(function (k) { return /^xaxis\\d*$/.test(k); }).map(function (k) {"
                                    " return L[k].title.text; })")
    assert sorted(t.split(" ")[0] for t in titles) == sorted(VARIABLES)
    assert _console(browser) == []


def test_a_box_dragged_on_the_plot_and_a_range_brushed_on_an_axis_filter(browser, two):
    from selenium.webdriver.common.action_chains import ActionChains

    out, _ = two
    rows = _rows(out / "evaluations.csv")
    _open(browser, (out / "report.html").resolve().as_uri())
    drag = browser.find_element("css selector", "#objective-space .nsewdrag")
    browser.execute_script("arguments[0].scrollIntoView({block: 'center'})", drag)
    ActionChains(browser).move_to_element_with_offset(drag, -250, -150).click_and_hold().move_by_offset(200, 120) \
        .move_by_offset(200, 120).release().perform()
    time.sleep(0.5)
    state = browser.execute_script("return window.hdExplorer.state()")
    x0, x1, y0, y1 = state["selection"]["box"]
    inside = [int(r["evaluation"]) for r in rows if r["iso"] and r["mass"]
              and min(x0, x1) <= float(r["iso"]) <= max(x0, x1) and min(y0, y1) <= float(r["mass"]) <= max(y0, y1)]
    assert state["selection"]["x"] == "obj:iso" and state["passing"] == inside
    browser.find_element("id", "clear-filters").click()
    canvas = browser.find_element("id", "parallel")
    browser.execute_script("arguments[0].scrollIntoView({block: 'center'})", canvas)
    first_axis = browser.execute_script("return window.hdExplorer.parallelLine(1)[0][0]")  # the l1 axis, in pixels
    width = canvas.size["width"]
    ActionChains(browser).move_to_element_with_offset(canvas, int(first_axis - width / 2), -80).click_and_hold() \
        .move_by_offset(0, 60).move_by_offset(0, 60).release().perform()
    time.sleep(0.3)
    state = browser.execute_script("return window.hdExplorer.state()")
    assert state["selection"] is None and list(state["ranges"]) == ["var:l1"]
    low, high = state["ranges"]["var:l1"]
    assert low < high and state["passing"] == [int(r["evaluation"]) for r in rows if low <= float(r["l1"]) <= high]
    assert _console(browser) == []
