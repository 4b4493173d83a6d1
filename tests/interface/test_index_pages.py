"""index.html beside loose results (campaign, zwidth, rcube maps): every file listed, names and cells escaped,
the same files giving the same bytes wherever the folder is."""

from __future__ import annotations

import json
from html.parser import HTMLParser
from pathlib import Path

from typer.testing import CliRunner

from hapticdesign.interface.cli import app
from hapticdesign.interface.report.index import CSV_ROWS, folder_index

runner = CliRunner()


class _Page(HTMLParser):
    """Links, images and the text of table cells of a page."""

    def __init__(self):
        super().__init__()
        self.hrefs, self.images, self.cells, self.scripts = [], [], [], 0
        self._cell = False

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.hrefs += [attrs["href"]] if tag == "a" else []
        self.images += [attrs["src"]] if tag == "img" else []
        self.scripts += tag == "script"
        self._cell = tag in ("td", "th")

    def handle_endtag(self, tag):
        self._cell = False

    def handle_data(self, data):
        if self._cell:
            self.cells.append(data)


def _parse(text: str) -> _Page:
    page = _Page()
    page.feed(text)
    return page


def _folder(root: Path) -> list[Path]:
    root.mkdir()
    hostile = root / "<img src=x onerror=alert(1)>.png"
    hostile.write_bytes(b"\x89PNG\r\n\x1a\n")
    (root / "plain.svg").write_text("<svg/>")
    table = root / "t.csv"
    table.write_text("name,value\n" + "".join(f"<b>{i}</b>,{i}\n" for i in range(CSV_ROWS + 5)))
    return [hostile, root / "plain.svg", table]


def test_index_escapes_names_and_cells_and_lists_every_file(tmp_path):
    files = _folder(tmp_path / "a")
    text = folder_index("<title>", "a & b", tmp_path / "a", files)
    page = _parse(text)
    assert page.scripts == 0 and "<img src=x" not in text and "<b>" not in text and "<title>&lt;" in text
    assert page.images == ["%3Cimg%20src%3Dx%20onerror%3Dalert%281%29%3E.png"]
    assert {"plain.svg", "t.csv"} <= set(page.hrefs)
    assert page.cells[:2] == ["name", "value"] and page.cells[2] == "<b>0</b>"
    assert len(page.cells) == 2 * (CSV_ROWS + 1) and f"the first {CSV_ROWS} of {CSV_ROWS + 5} rows" in text


def test_index_bytes_depend_on_the_files_only(tmp_path):
    first = folder_index("t", "d", tmp_path / "a", _folder(tmp_path / "a"))
    second = folder_index("t", "d", tmp_path / "b", list(reversed(_folder(tmp_path / "b"))))
    assert first == second and str(tmp_path) not in first


def test_zwidth_writes_an_index_of_its_chart(tmp_path):
    for name in ("a", "b"):
        result = runner.invoke(app, ["zwidth", "--inertia", "0.04", "--damping", "0.5", "--points", "3",
                                     "--out", str(tmp_path / name), "--json"])
        assert result.exit_code == 0, result.output
        assert json.loads(result.stdout)["index"] == str(tmp_path / name / "index.html")
    index = (tmp_path / "a" / "index.html").read_text()
    assert _parse(index).images == ["zwidth.png"] and "zwidth.svg" in _parse(index).hrefs
    assert index == (tmp_path / "b" / "index.html").read_text()


def test_rcube_maps_index_shows_every_map(tmp_path):
    result = runner.invoke(app, ["rcube", "maps", "--out", str(tmp_path), "--n", "3", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    page = _parse(Path(out["index"]).read_text())
    assert sorted(page.images) == sorted(Path(f).name for f in out["files"])
