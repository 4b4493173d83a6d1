"""Regenerates docs/optimization.md's "Redesigning the Phantom Premium": the study beside the published design.

Runs ``hapticdesign optimize examples/studies/phantom-premium-redesign.yaml --seed 1`` (one process), keeps its
pareto.png, front.csv and selected.yaml in docs/figures/optimization/phantom-premium-redesign/, and
evaluates the published Phantom Premium 1.5 (examples/devices/phantom-premium.yaml, unmodified) through the same
index registry at the study's workspace points. It prints the Markdown of the section: the run, a table of the
published design beside front designs (the felt mass at the median of the points, at the box's centre and at the
heaviest point; the weakest wall with the light hand and without a hand; the worst continuous and peak force; the
largest box of the study's proportions and centre each design reaches on the study's grid, as a fraction of the
data sheet's), what the selected design gained and lost, the wall the published design renders with compliant
capstans of a few stiffnesses (an illustration: no stiffness is published), and draws front_vs_published.png (the
front, every feasible design evaluated, the published design).

Run: ``PYTHONPATH=src .venv/bin/python docs/scripts/phantom_redesign.py`` (a few minutes on a shared 2-core
machine).
"""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402

from hapticdesign.analysis.metrics.indices import Request, reduce  # noqa: E402
from hapticdesign.analysis.workspace import Workspace, reach_workspace  # noqa: E402
from hapticdesign.devices.device_file import load_device_file  # noqa: E402
from hapticdesign.errors import UserError  # noqa: E402
from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study  # noqa: E402
from hapticdesign.optimization.study_file import load_study  # noqa: E402
from hapticdesign.optimization.study_outputs import without_unit  # noqa: E402
from hapticdesign.analysis.metrics.indices import evaluate  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "examples" / "studies" / "phantom-premium-redesign.yaml"
DEVICE = ROOT / "examples" / "devices" / "phantom-premium.yaml"
TARGET = ROOT / "docs" / "figures" / "optimization" / "phantom-premium-redesign"
KEPT = ("pareto.png", "front.csv", "selected.yaml")  # report.html needs its folder: the docs show screenshots
SEED = 1
DATA_SHEET_BOX = (0.191, 0.381, 0.267)
"""The Phantom Premium 1.5 data sheet's workspace, depth x width x height (m; SensAble Technologies), along the
device file's x, y, z."""
SHOWN = 8
"""Front designs in the table: both ends, the selected one and evenly spaced others."""

LOOP = {"period": 0.001, "delay": 1}
REQUESTS = [Request("apparent_mass", {}, "mass"), Request("kmax", {**LOOP, "hand": "light"}, "wall"),
            Request("kmax", LOOP, "bare"), Request("force", {"torque": "continuous"}, "force"),
            Request("force", {"torque": "peak"}, "peak")]
CABLES = (200.0, 1000.0, 5000.0, 20000.0)
"""Transmission stiffnesses (N m/rad at each joint) of the compliance illustration: no figure is published."""


def published_variables() -> dict[str, float]:
    """The study's variables at the published device file's values (lengths and capstan ratios)."""
    data = yaml.safe_load(DEVICE.read_text())
    ratios = {a["joint"]: float(a["gear_ratio"]) for a in data["actuators"]}
    return {"l1": float(data["parameters"]["l1"]), "l2": float(data["parameters"]["l2"]),
            "l3": float(data["parameters"]["l3"]), "ratio1": ratios["q1"], "ratio2": ratios["q2"],
            "ratio3": ratios["q3"]}


def run_study(scratch: Path) -> tuple[dict, float]:
    out = scratch / "run"
    begin = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", "from hapticdesign.interface.cli import main; main()", "optimize",
                           str(STUDY), "--seed", str(SEED), "--out", str(out), "--json", "--quiet"],
                          capture_output=True, text=True, check=True)
    elapsed = time.perf_counter() - begin
    TARGET.mkdir(parents=True, exist_ok=True)
    for name in KEPT:
        shutil.copyfile(out / name, TARGET / name)
    with open(out / "evaluations.csv", newline="") as handle:
        rows = [{without_unit(k): v for k, v in row.items()} for row in csv.DictReader(handle)]  # "mass [kg]": "mass"
        feasible = [row for row in rows if row["feasible"] == "yes"]
    summary = json.loads(done.stdout)
    summary["feasible"] = [(float(r["mass"]), float(r["force"])) for r in feasible]
    return summary, elapsed


def indices(device, points: np.ndarray, center: int) -> dict[str, float]:
    """The table's reduced indices of ``device`` at the ``points``, the box's centre the ``center``-th."""
    result = evaluate(device, points, REQUESTS)
    if result.reason is not None:
        raise SystemExit(f"a design of the table does not reach the workspace: {result.reason}")
    v = result.values
    return {"mass": reduce(v["mass"], "median"), "centre": reduce(v["mass"], "center", center),
            "heaviest": reduce(v["mass"], "max"), "wall": reduce(v["wall"], "min"), "bare": reduce(v["bare"], "min"),
            "force": reduce(v["force"], "min"), "peak": reduce(v["peak"], "min")}


def largest_scale(device, box) -> float:
    """The largest box of the study's centre and proportions whose grid-3 points the device reaches, as a fraction
    of the data sheet's sizes (bisection to 0.05 % of the study's box)."""
    def reaches(scale: float) -> bool:
        points = Workspace(box.center, tuple(scale * s for s in box.size), 3).points()
        try:
            reach_workspace(device, points)
            return True
        except UserError:
            return False
    low, high = 0.5, 1.5
    if not reaches(low):
        return float("nan")
    while high - low > 5e-4:
        middle = (low + high) / 2
        low, high = (middle, high) if reaches(middle) else (low, middle)
    return low * box.size[1] / DATA_SHEET_BOX[1]


def data_sheet_box(device, box) -> str:
    """Whether the published design reaches the data sheet's whole box at the study's centre, and why not."""
    points = Workspace(box.center, DATA_SHEET_BOX, 3).points()
    farthest = max(float(np.linalg.norm(p)) for p in points)
    try:
        reach_workspace(device, points)
        missed = "reaches it"
    except UserError as exc:
        missed = f"does not: {exc}"
    return (f"The data sheet's whole box at the study's centre (its farthest corner {1000 * farthest:.1f} mm from the "
            f"shoulder, l1 + l2 = {1000 * (device.params['l1'] + device.params['l2']):.1f} mm): the published "
            f"design {missed}.")


def finer_grid(device, box) -> str:
    """The published design's reduced indices on grid 5 (125 points) of the study's box."""
    fine = Workspace(box.center, box.size, 5)
    got = indices(device, fine.points(), fine.center_index)
    return (f"On grid 5 (125 points) of the study's box the published design gives a median felt mass of "
            f"{1000 * got['mass']:.1f} g (heaviest {1000 * got['heaviest']:.1f} g), weakest wall with the light hand "
            f"{got['wall']:.1f} N/m, worst continuous force {got['force']:.3f} N.")


def cable_walls(points: np.ndarray) -> str:
    """The published design's weakest wall (light and firm hand) with every capstan given the same compliance."""
    data = yaml.safe_load(DEVICE.read_text())
    lines = ["| transmission stiffness at each joint (N m/rad) | weakest wall, light hand (N/m) | weakest wall, firm "
             "hand (N/m) | first resonance of q1's motor on its cable (Hz) |", "| --- | --- | --- | --- |"]
    rotor = 1.08e-6 * 13.3 ** 2
    hands = [Request("kmax", {**LOOP, "hand": name}, name) for name in ("light", "firm")]
    for cable in (None, *CABLES):
        data["actuators"] = [{k: v for k, v in a.items() if k != "transmission_stiffness"}
                             | ({} if cable is None else {"transmission_stiffness": cable}) for a in data["actuators"]]
        with tempfile.TemporaryDirectory() as scratch:
            path = Path(scratch) / "phantom-premium-cables.yaml"
            path.write_text(yaml.safe_dump(data))
            values = evaluate(load_device_file(path), points, hands).values
        resonance = "rigid" if cable is None else f"{np.sqrt(cable / rotor) / (2 * np.pi):.0f}"
        lines.append(f"| {'rigid (the device file)' if cable is None else f'{cable:g}'} "
                     f"| {reduce(values['light'], 'min'):.1f} | {reduce(values['firm'], 'min'):.1f} | {resonance} |")
    return "\n".join(lines)


def shown_designs(front: list[dict], selected: int) -> list[int]:
    """Front numbers (from 1) of the table: evenly spaced over the front, its ends and the selected design."""
    picks = {int(round(k)) for k in np.linspace(1, len(front), min(SHOWN, len(front)))} | {selected}
    return sorted(picks)


def front_ranges(front: list[dict]) -> str:
    mass = [1000 * d["objectives"]["mass"] for d in front]
    force = [d["objectives"]["force"] for d in front]
    return f"median felt mass {min(mass):.1f} to {max(mass):.1f} g, weakest continuous force {min(force):.3f} to " \
           f"{max(force):.3f} N"


def at_bounds(study, front: list[dict]) -> str:
    """How many front designs hold each variable within 1 % of its range from a bound."""
    said = []
    for name, (low, high) in study.spec.variables.items():
        values = np.array([d["variables"][name] for d in front])
        near = [(np.sum(values <= low + 0.01 * (high - low)), "lower", low),
                (np.sum(values >= high - 0.01 * (high - low)), "upper", high)]
        said += [f"`{name}` at its {side} bound {bound:g} in {count}" for count, side, bound in near if count]
    return ("variables within 1 % of a bound: " + ", ".join(said)) if said else "no variable at a bound"


def figure(rows: dict, feasible: list[tuple[float, float]], front: list[dict]) -> Path:
    """Every feasible design, the front and the published design: the median felt mass against the weakest continuous
    force."""
    fig, whole = plt.subplots(1, 1, figsize=(7, 4.6), dpi=110)
    mass = [1000 * d["objectives"]["mass"] for d in front]
    force = [d["objectives"]["force"] for d in front]
    published = rows["published"]
    whole.scatter([1000 * m for m, _ in feasible], [f for _, f in feasible], s=8, color="0.75",
                  label="feasible designs evaluated")
    whole.plot(mass, force, "o-", color="tab:blue", markersize=4, label=f"front ({len(front)} designs)")
    whole.scatter([1000 * published["mass"]], [published["force"]], marker="*", s=220, color="tab:red",
                  label=f"published Phantom Premium 1.5\n(worst continuous force {published['force']:.2f} N < 1.4 N)")
    whole.set_xlabel("median apparent mass over the box's 27 points (g)")
    whole.set_ylabel("weakest continuous force over the box (N)")
    whole.axhline(1.4, color="0.4", linestyle=":", linewidth=1)  # the data sheet's 1.4 N, the constraint
    whole.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    whole.grid(True, alpha=0.3)
    fig.tight_layout()
    path = TARGET / "front_vs_published.png"
    fig.savefig(path, metadata={"Software": None}, bbox_inches="tight")
    plt.close(fig)
    return path


def change(before: float, after: float, unit: str, scale: float = 1.0, digits: int = 1, lower_is_better=True) -> str:
    """``74.1 -> 70.2 g (-5.3 %, better)``."""
    percent = 100.0 * (after / before - 1.0)
    better = (after < before) == lower_is_better
    word = "same" if abs(percent) < 0.05 else ("better" if better else "worse")
    return f"{scale * before:.{digits}f} -> {scale * after:.{digits}f} {unit} ({percent:+.1f} %, {word})"


def main() -> None:
    study = load_study(STUDY)
    bound = bind_study(study)
    box = study.spec.workspace.box
    points = bound.points
    center = Workspace(box.center, box.size, study.spec.workspace.grid).center_index
    published = published_variables()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the published be and df bodies' triangle-inequality note (device file)
        unmodified = load_device_file(DEVICE)
        as_study = StudyEvaluator(bound)([published])[0]
        with tempfile.TemporaryDirectory() as scratch:
            summary, elapsed = run_study(Path(scratch))
        front, selected = summary["front"], summary["selected"]["design"]
        rows = {"published": {**published, **indices(unmodified, points, center),
                              "scale": largest_scale(unmodified, box)}}
        for k in shown_designs(front, selected):
            values = front[k - 1]["variables"]
            device = bound.space.device(bound.device_values(values))
            rows[k] = {**values, **indices(device, points, center), "scale": largest_scale(device, box)}
        cables = cable_walls(points)
    read = [o.name for o in study.spec.objectives]  # the study's objectives, in its order
    same = {name: (as_study.reduced[i], rows["published"][name]) for i, name in enumerate(read)}
    path = figure(rows, summary["feasible"], front)
    print(f"`hapticdesign optimize examples/studies/phantom-premium-redesign.yaml --seed {SEED}`: "
          f"{summary['evaluations']} designs evaluated, {len(summary['feasible'])} feasible, {len(front)} on the "
          f"front, whole run {elapsed:.0f} s wall (one process, shared 2-core machine). The published design "
          f"evaluated as a design of the study (its variables at the device file's values, through the study's "
          f"formulas) {'reaches every workspace point' if not as_study.reason else 'fails: ' + as_study.reason} and "
          f"gives "
          + ", ".join(f"{n} = {a:.6g} (the unmodified device file: {b:.6g})" for n, (a, b) in same.items())
          + ".\n")
    print(data_sheet_box(unmodified, box), finer_grid(unmodified, box), "\n")
    print("| design | l1, l2, l3 (mm) | ratios q1, q2, q3 | median felt mass (g) | at the centre (g) | heaviest (g) "
          "| weakest wall, light hand (N/m) | weakest wall, no hand (N/m) | worst continuous force (N) "
          "| worst peak force (N) | largest box reached (of 381 x 267 x 191 mm) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, r in rows.items():
        label = "published" if name == "published" else f"front {name}" + (" (selected)" if name == selected else "")
        print(f"| {label} | {1000 * r['l1']:.1f}, {1000 * r['l2']:.1f}, {1000 * r['l3']:.1f} "
              f"| {r['ratio1']:.2f}, {r['ratio2']:.2f}, {r['ratio3']:.2f} | {1000 * r['mass']:.1f} "
              f"| {1000 * r['centre']:.1f} | {1000 * r['heaviest']:.1f} | {r['wall']:.1f} | {r['bare']:.3f} "
              f"| {r['force']:.3f} | {r['peak']:.2f} | {100 * r['scale']:.1f} % |")
    print(f"\nThe whole front ({len(front)} designs): {front_ranges(front)}; {at_bounds(study, front)}.")
    base, best = rows["published"], rows[selected]
    print(f"\nSelected design {selected} against the published one: median felt mass "
          f"{change(base['mass'], best['mass'], 'g', 1000)}; at the box's centre "
          f"{change(base['centre'], best['centre'], 'g', 1000)}; heaviest point "
          f"{change(base['heaviest'], best['heaviest'], 'g', 1000)}; weakest wall with the light hand "
          f"{change(base['wall'], best['wall'], 'N/m', lower_is_better=False)} (without a hand "
          f"{change(base['bare'], best['bare'], 'N/m', digits=3, lower_is_better=False)}); worst continuous force "
          f"{change(base['force'], best['force'], 'N', digits=3, lower_is_better=False)}; worst peak force "
          f"{change(base['peak'], best['peak'], 'N', digits=2, lower_is_better=False)}; lengths l1 + l2 "
          f"{1000 * (base['l1'] + base['l2']):.1f} -> {1000 * (best['l1'] + best['l2']):.1f} mm.")
    print(f"\n![The front beside the published design]({path.relative_to(ROOT / 'docs').as_posix()})")
    print("\nThe published design with compliant capstans (every motor's `transmission_stiffness` the same; an "
          "illustration, no stiffness is published), at the study's points:\n")
    print(cables)


if __name__ == "__main__":
    main()
