"""The seeds' own studies in the design explorer (:func:`~hapticdesign.interface.report.optimization_page.explorer_page`,
the page every study opens in): ``rcube optimize``'s synthesis (seed 001 §7.1-7.2, :func:`rcube_page`) and a study
step's designs (:func:`step_page`: ``study phantom``'s campaign over the design sets, seed 000 §3.2.2, §4.1.4), each
as ``report.html`` with ``plotly.min.js`` beside it (:func:`write_explorer`). The static
part under the explorer lists what the run found and the files beside the page; the numbers are the run's own."""

from __future__ import annotations

from html import escape
from pathlib import Path

from hapticdesign.files import write_atomically
from hapticdesign.interface.report.optimization_page import PLOTLY, _table, explorer_page, plotly_js

REPORT = "report.html"


def write_explorer(out: Path, page: str) -> list[Path]:
    """Write an explorer ``page`` as ``out/report.html`` with Plotly.js beside it (:data:`PLOTLY`)."""
    write_atomically(out / PLOTLY, plotly_js())
    write_atomically(out / REPORT, page)
    return [out / PLOTLY, out / REPORT]


def _front_rows(data: dict) -> tuple[list[str], list[list]]:
    """The front as a table of the explorer's own numbers (SI units), one row per front design."""
    E = data["evaluations"]
    columns = [*data["variables"], *data["objectives"], *data["constraints"]]
    values = [*E["variables"], *E["objectives"], *E["constraints"]]
    head = ["design", *(f"{c['name']} [{c['unit']}]" if c["unit"] else c["name"] for c in columns)]
    return head, [[n, *(column[k] for column in values)] for n, k in enumerate(data["front"], start=1)]


def rcube_page(data: dict, summary: dict, files: list[str]) -> str:
    """``rcube optimize``'s report: the explorer of the synthesis (:func:`~hapticdesign.optimization.rcube.explorer.
    chain_explorer`), then the chain's results (``summary``: :func:`~hapticdesign.optimization.rcube.chain.
    chain_summary`) and the front."""
    selected = summary["selected"]
    plies = summary["plies"]
    rows = [["designs on the front (Table 7.2)", summary["front_size"]],
            ["hypervolume of the front (objectives scaled to [0, 1])", summary["hypervolume"]],
            ["objective evaluations", summary["evaluations"]],
            ["selected solution (Table 7.5)", selected["solution"]],
            ["selected l1, l2, l3 [mm]", ", ".join(f"{selected[k] * 1e3:.1f}" for k in ("l1", "l2", "l3"))],
            ["selected q_max [deg]", selected["q_max_deg"]],
            ["cross-section ratio d/D (eq. 7.5)", summary["ratio"]],
            ["plies (0, 90, +-45 per link)", str(plies["counts"])],
            ["CF1 under 20 N [mm]", plies["CF1_mm"]],
            ["link mass [g] (Table 7.9)", summary["specifications"]["total_link_mass_g"]]]
    head, front = _front_rows(data)
    body = ["<h2>The chain (seed 001 ch. 7)</h2>",
            "<p>The explorer shows the synthesis: the bound sets' final populations (the designs NSGA-II kept; a run "
            "keeps no other), the merged front of Table 7.2 and the design the weighted RMS selects. Then the chain "
            "goes on from the selected design: the cross-section ratio, the plies and the final design.</p>",
            _table("What the chain found (summary.json)", ["quantity", "value"], rows),
            _table(f"The front: {len(front)} designs (table_7_2_front.csv in mm and degrees; click a row to pick it)",
                   head, front, data["selected"]["position"], ident="front-table")]
    return explorer_page(data["title"], data["title"], data, body, files)


def step_page(title: str, data: dict, paragraphs: list[str], files: list[str]) -> str:
    """A study step's designs in the explorer (:class:`~hapticdesign.studies.steps.Explorer`: ``study phantom``'s
    campaign, :func:`~hapticdesign.studies.phantom_explorer.campaign_explorer`), then ``paragraphs`` and the front."""
    head, front = _front_rows(data)
    body = ["<h2>The designs</h2>", *(f"<p>{escape(p, quote=False)}</p>" for p in paragraphs),
            _table(f"The front: {len(front)} designs (click a row to pick it)", head, front,
                   data["selected"]["position"], ident="front-table")]
    return explorer_page(title, title, data, body, files)
