"""The design explorer of a 1e5-evaluation study in headless Chromium (issue 42, item 8): how long report.html takes to
load from disk, to apply a filter (a range on one axis, as a brush on the parallel coordinates sets it) and to pick a
design, and how large it is.

The study is real: seed 001's R-CUBE synthesis (examples/devices/rcube.yaml; variables q_max, l2, l3; objectives O1 and
O2 of eq. 6.82-6.83; two of its elbow constraints), NSGA-II, population 1000, 100 generations: 100,000 evaluations,
run by ``optimize`` into a temporary folder (or into ``--out FOLDER``, where a rerun continues from the checkpoint).
The page embeds the front and a sample of the other evaluations
(:data:`~hapticdesign.optimization.study_explorer.EMBEDDED_LIMIT`). Times are the page's own
(``performance.now()``): load is the navigation's ``loadEventEnd`` (every script run and the plots, the parallel
coordinates and the card drawn); a filter or a pick is one call of ``window.hdExplorer`` (the plots, the parallel
coordinates, the card and the counts redrawn); each the median of ``REPEATS``. Chromium runs with
``--enable-unsafe-swiftshader``: the large scatter traces are WebGL (software-rendered here). The machine's load
average is printed with the figures.

Run: ``.venv/bin/python benchmarks/bench_explorer.py [--out FOLDER] [--limit N] [--write]`` (``--limit N``: the page
written again with N in place of the limit, e.g. 100000 to embed every evaluation, the measurement behind the limit;
``--write``: the figures into docs/optimization.md, between its ``explorer-benchmark`` markers).
"""

from __future__ import annotations

import json
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEVICE = ROOT / "examples" / "devices" / "rcube.yaml"
REPEATS = 5
STUDY = """# 1e5 evaluations of seed 001's R-CUBE synthesis (benchmarks/bench_explorer.py)
device: {device}
variables: {{q_max: [0.07, 1.5], l2: [0.001, 0.500], l3: [0.001, 0.500]}}
parameters: {{l1: "0.06 / sin(q_max)", S: "l1"}}
objectives:
  - {{name: O1, index: rcube_o1, reduce: max, sense: min}}
  - {{name: O2, index: rcube_o2, reduce: max, sense: min}}
constraints:
  - {{index: rcube_constraint, options: {{point: C2}}, reduce: max, "<=": 0}}
  - {{index: rcube_constraint, options: {{point: B1}}, reduce: max, "<=": 0}}
algorithm: {{method: nsga2, population: 1000, generations: 100, polish: none}}
"""
CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-quic", "--no-first-run", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--enable-unsafe-swiftshader")


def study_folder(out: Path, limit: int | None = None) -> Path:
    """The 1e5-evaluation study's output folder ``out`` (run by ``optimize``, seed 1; a folder holding the run
    already is written again from its checkpoint), its page embedding at most ``limit`` designs off the front
    (None: :data:`~hapticdesign.optimization.study_explorer.EMBEDDED_LIMIT`)."""
    from hapticdesign.interface.commands.optimize_adapter import optimize
    from hapticdesign.optimization import study_explorer

    if limit is not None:
        study_explorer.EMBEDDED_LIMIT = limit

    out.mkdir(parents=True, exist_ok=True)
    study = out.parent / f"{out.name}-study.yaml"
    study.write_text(STUDY.format(device=json.dumps(str(DEVICE))))
    start = time.perf_counter()
    optimize(study, seed=1, out=out, quiet=True)
    print(f"study run and written in {time.perf_counter() - start:.0f} s")
    return out


def chromium(profile: str):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(shutil.which("chromedriver") or "/usr/bin/chromedriver"), options=options)


def measure(out: Path) -> dict:
    """Load, filter and pick times [ms] of ``out``'s report.html, the counts it states and its console's errors."""
    profile = tempfile.mkdtemp(prefix="hd-bench-")
    driver = chromium(profile)
    try:
        driver.set_window_size(1300, 1000)
        url = (out / "report.html").resolve().as_uri()
        loads = []
        for _ in range(REPEATS):
            driver.get("about:blank")
            driver.get(url)
            loads.append(driver.execute_script("return performance.getEntriesByType('navigation')[0].loadEventEnd"))
        O1 = driver.execute_script("return window.hdExplorer.design(1).objectives.O1")
        filters, picks = [], []
        for k in range(REPEATS):
            filters.append(driver.execute_script(
                "var t = performance.now(); window.hdExplorer.filter('obj:O1', arguments[0], arguments[1]);"
                " return performance.now() - t", O1 * (1 + 0.1 * k), O1 * (3 + k)))
            picks.append(driver.execute_script("var t = performance.now(); window.hdExplorer.select(arguments[0]);"
                                               " return performance.now() - t", k + 2))
        state = driver.execute_script("return window.hdExplorer.state()")
        shown = driver.find_element("id", "shown-count")
        errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        return {"load": statistics.median(loads), "filter": statistics.median(filters),
                "pick": statistics.median(picks), "passing": len(state["passing"]),
                "shown": int(shown.get_attribute("data-shown")), "count": int(shown.get_attribute("data-count")),
                "errors": errors}
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


START, END = "<!-- explorer-benchmark:start -->", "<!-- explorer-benchmark:end -->"
DOC = ROOT / "docs" / "optimization.md"


def paragraph(figures: dict, front: int, size: int) -> str:
    """The figures as docs/optimization.md states them (between :data:`START` and :data:`END`)."""
    lines = (f"*How fast, at {figures['count']:,} evaluations* (`benchmarks/bench_explorer.py`: seed 001's R-CUBE "
             f"synthesis with two objectives and two constraints, NSGA-II, population 1000, 100 generations, its "
             f"{front:,}-design front; headless Chromium with software WebGL on this 2-core machine shared with other "
             f"jobs, load average {figures['load_average']:.1f}): the page holds {figures['shown']:,} of the "
             f"{figures['count']:,} designs ({size / 2**20:.1f} MB); it loads in {figures['load'] / 1000:.1f} s (the "
             "navigation's `loadEventEnd`, plots and parallel coordinates drawn), a filter (a range on one axis, as a "
             f"brush sets it) redraws everything in {figures['filter'] / 1000:.2f} s and a pick in "
             f"{figures['pick'] / 1000:.2f} s (medians of {REPEATS}).")
    words, out, line = lines.split(" "), [], ""
    for word in words:  # wrapped at 118 characters, as the page's other paragraphs
        if line and len(line) + 1 + len(word) > 118:
            out.append(line)
            line = word
        else:
            line = f"{line} {word}" if line else word
    return "\n".join([*out, line])


def main() -> None:
    args = sys.argv[1:]
    with tempfile.TemporaryDirectory(prefix="hd-explorer-") as folder:
        out = Path(args[args.index("--out") + 1]) if "--out" in args else Path(folder) / "out"
        limit = int(args[args.index("--limit") + 1]) if "--limit" in args else None
        if limit is not None or not (out / "report.html").is_file():
            study_folder(out, limit)
        figures = measure(out)
        figures["load_average"] = os.getloadavg()[0]
        size = (out / "report.html").stat().st_size
        front = sum(1 for _ in (out / "front.csv").open()) - 1
    print(f"load average {figures['load_average']:.1f} (2 cores); headless Chromium, software WebGL")
    print(f"report.html: {figures['shown']:,} of {figures['count']:,} evaluations embedded, {size / 2**20:.1f} MB")
    print(f"load {figures['load'] / 1000:.2f} s; filter {figures['filter']:.0f} ms ({figures['passing']:,} designs "
          f"pass); pick {figures['pick']:.0f} ms (medians of {REPEATS})")
    if figures["errors"]:
        print(f"console errors: {figures['errors']}")
    if "--write" in args:
        text = DOC.read_text()
        head, rest = text.split(START, 1)
        DOC.write_text(f"{head}{START}\n{paragraph(figures, front, size)}\n{END}{rest.split(END, 1)[1]}")
        print(f"wrote the figures into {DOC}")


if __name__ == "__main__":
    main()
