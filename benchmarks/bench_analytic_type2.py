"""Analytic type 2 against the simulated type 2, per LN level (issue 25): the agreement table of docs/simulation.md.

A design set made by the Linearity Number engine (Table 3.3 levels, ``--count`` designs per level,
seed ``--seed``, rigid-body realizable, as the campaign's), each design's maximum stable impedance
in type 2 (joints 2 and 3 driven at 0.52 sin(3 pi t), Table 4.3) found by the campaign's own case
(:func:`~hapticdesign.simulation.campaign.run_case`) with ``method="analytic"`` (the linear
time-varying loop of :mod:`hapticdesign.simulation.analytic_driven`) and with the simulation.

    python benchmarks/bench_analytic_type2.py [--count 20] [--seed 1]            # print the table
    python benchmarks/bench_analytic_type2.py --write docs/simulation.md         # replace the table there
    python benchmarks/bench_analytic_type2.py --check docs/simulation.md         # exit 1 when it drifted
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

from hapticdesign.interface.commands.linearity_adapter import write_design_set
from hapticdesign.simulation.campaign import CampaignOptions, read_designs, run_case

LEVELS = "0,0.001,0.01,0.1,1,2"
START, END = "<!-- analytic-type2-agreement:start -->", "<!-- analytic-type2-agreement:end -->"


def agreement(count: int, seed: int) -> str:
    """The markdown table: per level, mean k_max of both methods, the share of designs with the same k_max
    and the largest difference of the peak excursion at the simulated k_max."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "designs.csv"
        write_design_set("phantom-3dof", None, None, False, LEVELS, count, seed, path, "fast", "rigid-body")
        designs = read_designs(path)
    rows = {}
    for d in designs:
        found = {m: run_case("phantom-3dof", d.params, "impedance", 2, CampaignOptions(method=m))
                 for m in ("analytic", "simulation")}
        rows.setdefault(d.level, []).append((found["analytic"]["value"], found["simulation"]["value"],
                                             found["analytic"]["limiting_criterion"],
                                             found["simulation"]["limiting_criterion"]))
    lines = [f"Type 2, {count} designs per level (seed {seed}; `python benchmarks/bench_analytic_type2.py --count "
             f"{count} --seed {seed}`):", "",
             "| LN | designs | K_max simulated (mean) | K_max analytic (mean) | same K_max | same limiting criterion |",
             "|---|---|---|---|---|---|"]
    for level in sorted(rows):
        a = np.array([r[0] for r in rows[level]])
        s = np.array([r[1] for r in rows[level]])
        same = int(np.sum(a == s))
        criterion = sum(r[2] == r[3] for r in rows[level])
        lines.append(f"| {level:g} | {len(a)} | {s.mean():.2f} | {a.mean():.2f} | {same} of {len(a)} "
                     f"({100 * same / len(a):.0f} %) | {criterion} of {len(a)} |")
    return "\n".join(lines)


def replace_block(text: str, block: str) -> str:
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{START}\n{block}\n{END}{tail}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=20, help="designs per LN level")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--write", type=Path, default=None, help="replace the table in this markdown file")
    parser.add_argument("--check", type=Path, default=None, help="exit 1 when the table in this file differs")
    args = parser.parse_args(argv)
    table = agreement(args.count, args.seed)
    print(table)
    if args.write is not None:
        args.write.write_text(replace_block(args.write.read_text(), table))
    if args.check is not None and replace_block(args.check.read_text(), table) != args.check.read_text():
        print(f"the agreement table in {args.check} drifted from the regenerated one", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
