"""The modelling-error study of docs/simulation.md (issue 25): type 2, several seeded draws per design.

Designs by the Linearity Number engine (Table 3.3 levels, ``--count`` per level, seed 1, rigid-body
realizable, as the campaign's); masses and inertias of the compensator's model wrong by E percent with
random signs, ``--draws`` draws per design (:func:`hapticdesign.simulation.robustness.error_cases`,
analytic type 2), summarized per LN level with 95 % confidence intervals.

    python benchmarks/bench_robustness.py [--count 10] [--draws 5]
    python benchmarks/bench_robustness.py --write docs/simulation.md --figure docs/figures/simulation/robustness
    python benchmarks/bench_robustness.py --check docs/simulation.md     # exit 1 when it drifted
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy import stats

from hapticdesign.devices.registry import preset
from hapticdesign.interface.commands.linearity_adapter import write_design_set
from hapticdesign.simulation.campaign import read_designs
from hapticdesign.simulation.figures import robustness_chart
from hapticdesign.simulation.robustness import ErrorCase, error_cases, summarize_errors

LEVELS = "0,0.001,0.01,0.1,1,2"
ERRORS = [0.0, 1.0, 5.0]
NAMES = ("robustness-study", "robustness-answer")


def _ci(row: dict, key: str, low: str, high: str, sign: str = "+") -> str:
    if row[key] is None:
        return "-"
    if row[low] is None:
        return f"{row[key]:{sign}.2f}"
    return f"{row[key]:{sign}.2f} ({row[low]:{sign}.2f} to {row[high]:{sign}.2f})"


def _pooled(values: list[float]) -> str:
    v = np.array(values)
    half = stats.t.ppf(0.975, v.size - 1) * v.std(ddof=1) / np.sqrt(v.size)
    return f"{v.mean():+.2f} N m/rad (95 % CI {v.mean() - half:+.2f} to {v.mean() + half:+.2f}, {v.size} cases)"


def answer(cases: list[ErrorCase], rows: list[dict]) -> str:
    """The answer, its numbers taken from the cases and the summary."""
    base = {c.design: c.k_max for c in cases if c.error_percent == 0}
    parts = []
    for error in sorted({c.error_percent for c in cases} - {0.0}):
        chosen = [r for r in rows if r["error_percent"] == error]
        lows, highs = [r["absolute_change_ci_low"] for r in chosen], [r["absolute_change_ci_high"] for r in chosen]
        overlap = max(lows) <= min(highs)
        rhos = [r["spearman_abs_change_vs_abs_1_minus_c"] for r in chosen
                if r["spearman_abs_change_vs_abs_1_minus_c"] is not None]
        under = [c.k_max - base[c.design] for c in cases if c.error_percent == error and c.fraction < 1]
        over = [c.k_max - base[c.design] for c in cases if c.error_percent == error and c.fraction > 1]
        zero = np.mean([c.k_max == 0 for c in cases if c.error_percent == error and c.fraction > 1])
        means = [r["mean_absolute_change"] for r in chosen]
        intervals = ", ".join(f"[{r['absolute_change_ci_low']:.2f}, {r['absolute_change_ci_high']:.2f}] (LN {r['level']:g})"
                              for r in chosen)
        parts.append(
            f"- At E = {error:g} % the mean absolute change of K_max is {min(means):.2f}-{max(means):.2f} N m/rad "
            f"across the LN levels, 95 % intervals {intervals}: they "
            f"{'share a common range' if overlap else 'do not all overlap'}. Within a level the change's rank "
            f"correlation with |1 - c| is {min(rhos):.2f} to {max(rhos):.2f}. Under-estimated "
            f"inertia (c < 1) changes K_max by {_pooled(under)}, over-estimated (c > 1) by {_pooled(over)}, and "
            f"{100 * zero:.0f} % of the over-estimated cases have no stable spring at all (K_max = 0).")
    return "\n".join(parts)


def readme_phrase(rows: list[dict]) -> str:
    """The figures README.md states (its modelling-error row)."""
    at = {(r["level"], r["error_percent"]): r for r in rows}
    one = [r for r in rows if r["error_percent"] == 1.0]
    five = [r for r in rows if r["error_percent"] == 5.0]
    low = [r["spearman_abs_change_vs_abs_1_minus_c"] for r in one if r["level"] <= 1.0]
    over = [r["over_change"] for r in one]
    zero = [r["over_to_zero_share"] for r in five]
    levels = sorted({r["level"] for r in rows})
    first, high, top = levels[0], levels[-2], levels[-1]
    return (f"1 % error on masses and inertias moves K_max by {min(r['mean_absolute_change'] for r in one):.2f}-"
            f"{max(r['mean_absolute_change'] for r in one):.2f} N m/rad on average per LN level, set by the draw through "
            f"1 - c (c = model H11 / true H11; rank correlation {min(low):.2f}-{max(low):.2f} at LN <= 1), one-sided: "
            f"an over-estimated inertia lowers it ({max(over):.2f} to {min(over):.2f} N m/rad) and at 5 % leaves no "
            f"stable spring in {100 * min(zero):.0f}-{100 * max(zero):.0f} % of those draws; at 5 % the low-LN designs "
            f"keep their mean range (LN = {first:g}: {at[first, 0.0]['mean']:.2f} -> {at[first, 5.0]['mean']:.2f}, CI "
            f"{at[first, 5.0]['mean_ci_low']:.2f}-{at[first, 5.0]['mean_ci_high']:.2f}) while LN = {high:g} and {top:g} "
            f"lose most of theirs ({at[high, 0.0]['mean']:.2f} -> {at[high, 5.0]['mean']:.2f}, CI "
            f"{at[high, 5.0]['mean_ci_low']:.2f}-{at[high, 5.0]['mean_ci_high']:.2f}; {at[top, 0.0]['mean']:.2f} -> "
            f"{at[top, 5.0]['mean']:.2f})")


def study(count: int, draws: int, seed: int, figure: Path | None = None) -> tuple[str, str, str]:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "designs.csv"
        write_design_set("phantom-3dof", None, None, False, LEVELS, count, 1, path, "fast", "rigid-body")
        designs = read_designs(path)
    base = preset("phantom-3dof")
    devices = [(d.name, d.level, base.with_params(d.params)) for d in designs]
    cases = error_cases(devices, ERRORS, seed, sim_type=2, draws=draws)
    rows = summarize_errors(cases)
    if figure is not None:
        robustness_chart(rows, figure, 2)
    lines = [f"Type 2, analytic, {count} designs per level, {draws} sign draws per design and error (seed {seed}; "
             f"`python benchmarks/bench_robustness.py --count {count} --draws {draws} --seed {seed}`); changes of "
             "K_max from the same design without error in N m/rad, means with their 95 % confidence intervals; "
             "c = H_model,11 / H_11 at the start:", "",
             "| LN | E [%] | cases | K_max | abs. change | c < 1: cases, change | c > 1: cases, change | c > 1: K_max = 0 "
             "| rank corr. of abs. change with abs(1 - c) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["error_percent"] == 0:
            lines.append(f"| {r['level']:g} | 0 | {r['n']} | {_ci(r, 'mean', 'mean_ci_low', 'mean_ci_high', '')} "
                         "| - | - | - | - | - |")
            continue
        zero = "-" if r["over_to_zero_share"] is None else f"{100 * r['over_to_zero_share']:.0f} %"
        rho = "-" if r["spearman_abs_change_vs_abs_1_minus_c"] is None else \
            f"{r['spearman_abs_change_vs_abs_1_minus_c']:.2f}"
        lines.append(f"| {r['level']:g} | {r['error_percent']:g} | {r['n']} "
                     f"| {_ci(r, 'mean', 'mean_ci_low', 'mean_ci_high', '')} "
                     f"| {_ci(r, 'mean_absolute_change', 'absolute_change_ci_low', 'absolute_change_ci_high', '')} "
                     f"| {r['under_n']}: {_ci(r, 'under_change', 'under_ci_low', 'under_ci_high')} "
                     f"| {r['over_n']}: {_ci(r, 'over_change', 'over_ci_low', 'over_ci_high')} | {zero} | {rho} |")
    return "\n".join(lines), answer(cases, rows), readme_phrase(rows)


def replace_block(text: str, name: str, block: str) -> str:
    start, end = f"<!-- {name}:start -->", f"<!-- {name}:end -->"
    head, rest = text.split(start, 1)
    _, tail = rest.split(end, 1)
    return f"{head}{start}\n{block}\n{end}{tail}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=10, help="designs per LN level")
    parser.add_argument("--draws", type=int, default=5, help="error-sign draws per design and error level")
    parser.add_argument("--seed", type=int, default=1, help="seed of the error signs")
    parser.add_argument("--figure", type=Path, default=None, help="also draw the chart (path without suffix)")
    parser.add_argument("--write", type=Path, default=None)
    parser.add_argument("--check", type=Path, default=None)
    args = parser.parse_args(argv)
    *blocks, phrase = study(args.count, args.draws, args.seed, args.figure)
    print("\n\n".join(blocks))
    print(f"\nREADME: {phrase}")
    if args.write is not None:
        text = args.write.read_text()
        for name, block in zip(NAMES, blocks):
            text = replace_block(text, name, block)
        args.write.write_text(text)
    if args.check is not None:
        text = args.check.read_text()
        readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
        if phrase not in readme or any(replace_block(text, name, block) != text for name, block in zip(NAMES, blocks)):
            print(f"the modelling-error study in {args.check} drifted", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
