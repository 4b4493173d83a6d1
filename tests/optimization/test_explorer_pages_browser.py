"""Every example study's report and ``rcube optimize``'s open in the design explorer in headless Chromium (Debian's,
through Selenium): no console message, and the hook answers ``design(1)`` with the first row of the front the run
wrote beside the page (front.csv, read here with the csv module; the R-CUBE's table_7_2_front.csv, in mm and degrees).
``study phantom``'s explorer is checked beside its report (tests/studies/test_study_report_browser.py).

Each example study runs on a small budget (population 6, 2 generations, no polishing, a 3-point grid, 2 starts of a
start search; a convex program as it is) so that the test checks the pages, not the optimizer; the Falcon redesign's
``rod`` and ``ratio`` ranges are narrowed to the light, geared corner of its box, where its constraints hold, so that
12 designs include a feasible one (a run without one writes the report of why, a page without the explorer).
"""

from __future__ import annotations

import csv
import math
import time
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from hapticdesign.interface.cli import app
from hapticdesign.optimization.study_outputs import without_unit

pytestmark = pytest.mark.slow  # end to end in a browser: deselect with -m "not slow"

ROOT = Path(__file__).resolve().parents[2]
STUDIES = sorted(p for p in (ROOT / "examples" / "studies").glob("*.yaml") if "objectives" in yaml.safe_load(p.read_text()))
NARROWED = {"falcon-redesign": {"rod": [0.4, 0.5], "ratio": [9.0, 12.0]}}
runner = CliRunner()


def small(path: Path, folder: Path) -> Path:
    """The study file ``path`` on the small budget of the module docstring, written into ``folder``."""
    data = yaml.safe_load(path.read_text())
    data["device"] = str((path.parent / data["device"]).resolve())
    data["variables"].update(NARROWED.get(path.stem, {}))
    if "grid" in data.get("workspace", {}):
        data["workspace"]["grid"] = 3
    algorithm = data["algorithm"]
    if algorithm.get("method", "nsga2") != "convex":
        algorithm.update(population=6, generations=2, polish="none")
        if algorithm.get("start"):
            algorithm["start"]["starts"] = 2
    small = folder / path.name
    small.write_text(yaml.safe_dump(data, sort_keys=False))
    return small


def opened(driver, page: Path) -> None:
    """``page`` loaded from disk and its explorer started."""
    driver.set_window_size(1300, 1000)
    driver.get("about:blank")
    driver.get(page.resolve().as_uri())
    for _ in range(100):
        if driver.execute_script("return !!window.hdExplorer"):
            return
        time.sleep(0.05)
    raise AssertionError(f"the explorer of {page} did not start")


def console(driver) -> list[dict]:
    return [e for e in driver.get_log("browser") if e["level"] in ("SEVERE", "WARNING")]


def read_rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def first_row(path: Path) -> dict[str, str]:
    with path.open(newline="") as f:
        return {without_unit(k): v for k, v in next(csv.DictReader(f)).items()}


@pytest.mark.parametrize("study", STUDIES, ids=[p.stem for p in STUDIES])
def test_every_example_studys_report_opens_in_the_explorer(browser, tmp_path, study):
    out = tmp_path / "out"
    done = runner.invoke(app, ["optimize", str(small(study, tmp_path)), "--seed", "1", "--out", str(out), "--quiet",
                               "--force"])
    assert done.exit_code == 0, done.output
    opened(browser, out / "report.html")
    design = browser.execute_script("return window.hdExplorer.design(1)")
    row = first_row(out / "front.csv")
    assert design["variables"] == {k: float(row[k]) for k in design["variables"]}
    assert design["objectives"] == {k: float(row[k]) for k in design["objectives"]}
    assert console(browser) == []


@pytest.fixture(scope="module")
def rcube_out(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("rcube") / "out"
    done = runner.invoke(app, ["rcube", "optimize", "--quick", "--seed", "1", "--out", str(out), "--quiet"])
    assert done.exit_code == 0, done.output
    return out


def test_rcube_optimize_opens_in_the_explorer(browser, rcube_out):
    opened(browser, rcube_out / "report.html")
    design = browser.execute_script("return window.hdExplorer.design(1)")
    row = first_row(rcube_out / "table_7_2_front.csv")  # written with 10 significant digits
    expected = {"q_max": math.radians(float(row["q_max_deg"])),
                **{k: float(row[f"{k}_mm"]) / 1e3 for k in ("l1", "l2", "l3")}}
    assert design["variables"] == pytest.approx(expected, rel=1e-9)
    assert design["objectives"] == pytest.approx({k: float(row[k]) for k in ("O1", "O2", "O3")}, rel=1e-9)
    assert design["constraints"]["l1 + l2 + l3"] == pytest.approx(float(row["total_mm"]) / 1e3, rel=1e-9)
    # the picture: three chains of links l1, l2, l3 from their bases to the platform at home (S, S, S), S = l1
    bars = design["picture"]["bars"]
    assert [math.dist(*b) for b in bars] == pytest.approx([expected[k] for k in ("l1", "l2", "l3")] * 3, rel=1e-9)
    assert design["picture"]["origins"]["platform"] == pytest.approx([expected["l1"]] * 3, rel=1e-9)
    assert browser.execute_script("return window.hdExplorer.state().selected") == \
        int(first_row(rcube_out / "table_7_5_weighted_rms.csv")["solution"])
    # every design it shows is embedded (no sample), numbered 1..count as the served page's data require
    shown = browser.find_element("id", "shown-count")
    count = int(shown.get_attribute("data-count"))
    assert int(shown.get_attribute("data-shown")) == count >= len(read_rows(rcube_out / "table_7_2_front.csv"))
    assert shown.text == f"This page holds all {count:,} evaluated designs."
    assert console(browser) == []


def test_explore_refuses_rcube_optimizes_folder_in_one_line(rcube_out):
    """``hapticdesign explore`` serves optimize's output folders; the R-CUBE chain's has no front.csv or
    evaluations.csv: one line, exit status 2, nothing written."""
    before = sorted(p.relative_to(rcube_out) for p in rcube_out.rglob("*"))
    done = runner.invoke(app, ["explore", str(rcube_out)])
    assert done.exit_code == 2 and done.stdout == "" and "Traceback" not in done.stderr
    assert done.stderr.startswith("error: ") and done.stderr.count("\n") == 1
    assert "is not a study's output folder" in done.stderr
    assert sorted(p.relative_to(rcube_out) for p in rcube_out.rglob("*")) == before
