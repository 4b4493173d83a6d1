"""The study report groups infeasible designs by the kind of reason, numbers aside, and puts objectives first."""

import re
from html import unescape
from types import SimpleNamespace

from hapticdesign.interface.report.optimization_page import _reasons, reason_kind
from hapticdesign.optimization.study_run import Record, StudyRun


def _record(violated: str = "", invalid: str = "") -> Record:
    return Record(1, (0.0,), {"l1": 0.1}, (0.5,), (), invalid, violated, 1.0 if violated else 0.0)


def _rows(html: str) -> list[list[str]]:
    body = html.split("<tbody>")[1]
    return [[unescape(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row)] for row in body.split("</tr>") if "<td" in row]


def test_many_wall_failures_count_as_one_reason_ahead_of_a_few_loop_failures():
    """The issue's study: 643 wall-limit failures, each with its own numbers, were 643 one-count rows, so 13
    'loops cannot close' looked like the top reason. Grouped by kind: 643 first, then 13, the numbers' ranges aside."""
    walls = [_record(violated=f"min_kmax = {100 + k * 0.5:g} N/m, not >= 500") for k in range(643)]
    loops = [_record(invalid="the loops cannot close at workspace point 3") for _ in range(13)]
    run = StudyRun(SimpleNamespace(), 1, [*walls, *loops, _record()], [])
    rows = _rows(_reasons(run))
    assert rows[0] == ["min_kmax = # N/m, not >= #", "643", "100 to 421; 500"]
    assert rows[1] == ["the loops cannot close at workspace point #", "13", "3"]
    assert len(rows) == 2


def test_names_keep_their_digits():
    assert reason_kind("l1 + l2 = 0.300198, not <= 0.3") == ("l1 + l2 = #, not <= #", [0.300198, 0.3])
    assert reason_kind("the handle cannot reach (-0.03, 0, 1e-05) m") == ("the handle cannot reach (#, #, #) m",
                                                                           [-0.03, 0.0, 1e-05])


def test_the_front_table_shows_the_objectives_first(tmp_path):
    """A front is its objectives: the report's front table has them right after the design number, before the
    variables (which used to push them off the page)."""
    from typer.testing import CliRunner

    from hapticdesign.interface.cli import app
    from tests.optimization.test_study_run import small_study

    done = CliRunner().invoke(app, ["optimize", str(small_study(tmp_path)), "--seed", "7", "--out",
                                    str(tmp_path / "out"), "--quiet"])
    assert done.exit_code == 0, done.output
    page = (tmp_path / "out" / "report.html").read_text()
    table = page[page.index("<caption>The front:"):]
    heads = [unescape(h) for h in re.findall(r"<th>(.*?)</th>", table[:table.index("</thead>")])]
    assert heads[:5] == ["design", "iso [1]", "mass [kg]", "l2 [m]", "actuators.q2.gear_ratio [1]"]
