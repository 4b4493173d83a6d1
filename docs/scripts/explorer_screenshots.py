"""Regenerates the design explorer's screenshots of docs/optimization.md ("Exploring a study") and the cost of the
cards' spec summary on the showcase study.

Runs ``hapticdesign optimize`` with seed 1 on examples/studies/five-bar-geometry.yaml (two objectives) and
five-bar.yaml (three objectives), opens each report.html from disk in headless Chromium (Debian's ``chromium`` and
``chromedriver``, through Selenium, as the browser tests do) and saves into docs/figures/optimization/:
explorer-two-objectives.png (how many designs the page holds, the objective space and the parallel coordinates),
explorer-three-objectives.png (the pair plot of the three objectives) and explorer-card.png (the selected design's
card: numbers, picture, spec summary, maps, commands). Then it times :func:`hapticdesign.studies.spec.spec_summary` on each front design of
docs/figures/optimization/phantom-premium-redesign/front.csv (what the report adds to a run of
examples/studies/phantom-premium-redesign.yaml) and prints the Markdown lines.

Run: ``.venv/bin/python docs/scripts/explorer_screenshots.py`` (about a minute on a shared 2-core machine).
"""

from __future__ import annotations

import base64
import csv
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TARGET = ROOT / "docs" / "figures" / "optimization"
SHOWCASE = "phantom-premium-redesign"
FLAGS = ("--headless", "--no-sandbox", "--enable-unsafe-swiftshader", "--hide-scrollbars",  # WebGL: the large traces
         "--disable-background-networking", "--disable-component-update", "--no-first-run")


def run(study: str, out: Path) -> Path:
    subprocess.run([sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "optimize",
                    str(ROOT / "examples" / "studies" / f"{study}.yaml"), "--seed", "1", "--out", str(out), "--quiet"],
                   check=True, stdout=subprocess.DEVNULL)
    return out / "report.html"


def browser(profile: Path):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    for flag in FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver") or "/usr/bin/chromedriver"), options=options)
    driver.set_window_size(1280, 1000)
    return driver


def opened(driver, page: Path) -> None:
    driver.get(page.resolve().as_uri())
    for _ in range(200):
        if driver.execute_script("return !!window.hdExplorer"):
            time.sleep(1.0)  # Plotly's drawing
            return
        time.sleep(0.05)
    raise SystemExit(f"the explorer of {page} did not start")


def shot(driver, first: str, last: str, path: Path) -> None:
    """The page from the top of element ``first`` to the bottom of element ``last`` (CSS selectors) as a PNG."""
    top, bottom, left, right = driver.execute_script(
        "var a = document.querySelector(arguments[0]).getBoundingClientRect(),"
        " b = document.querySelector(arguments[1]).getBoundingClientRect(), y = window.scrollY;"
        " return [a.top + y, b.bottom + y, Math.min(a.left, b.left), Math.max(a.right, b.right)];", first, last)
    clip = {"x": left - 8, "y": top - 8, "width": right - left + 16, "height": bottom - top + 16, "scale": 1}
    png = driver.execute_cdp_cmd("Page.captureScreenshot", {"format": "png", "captureBeyondViewport": True, "clip": clip})
    path.write_bytes(base64.b64decode(png["data"]))


def spec_cost() -> tuple[int, float]:
    """The front designs of the showcase study's kept front.csv and the seconds spec_summary takes on all of them
    (after one call that loads the compiled kernels)."""
    from hapticdesign.optimization.study_evaluation import bind_study
    from hapticdesign.optimization.study_file import load_study
    from hapticdesign.optimization.study_outputs import without_unit
    from hapticdesign.studies.spec import spec_summary

    bound = bind_study(load_study(ROOT / "examples" / "studies" / f"{SHOWCASE}.yaml"))
    with (TARGET / SHOWCASE / "front.csv").open(newline="") as f:
        rows = [{without_unit(k): v for k, v in row.items()} for row in csv.DictReader(f)]
    devices = [bound.space.device(bound.device_values({k: float(r[k]) for k in bound.study.spec.variables}))
               for r in rows]
    spec_summary(devices[0])
    begin = time.perf_counter()
    for device in devices:
        spec_summary(device)
    return len(devices), time.perf_counter() - begin


def main() -> None:
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        two, three = run("five-bar-geometry", scratch / "two"), run("five-bar", scratch / "three")
        driver = browser(scratch / "profile")
        try:
            opened(driver, two)
            shot(driver, "#shown-count", "#parallel", TARGET / "explorer-two-objectives.png")
            opened(driver, three)
            shot(driver, "#explorer .toolbar", "#pairs", TARGET / "explorer-three-objectives.png")
            shot(driver, "#design-card", "#design-card", TARGET / "explorer-card.png")
        finally:
            driver.quit()
    count, seconds = spec_cost()
    print(f"![The explorer of five-bar-geometry](figures/optimization/explorer-two-objectives.png)\n"
          f"![The explorer of five-bar](figures/optimization/explorer-three-objectives.png)\n"
          f"![A design card](figures/optimization/explorer-card.png)\n"
          f"spec summary: {count} front designs of {SHOWCASE} in {seconds:.2f} s ({seconds / count * 1000:.0f} ms "
          "each)")


if __name__ == "__main__":
    main()
