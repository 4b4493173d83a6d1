"""The work of ``explore``: a study's output folder served read-only on 127.0.0.1, with the card of any evaluated
design computed on demand (docs/optimization.md, *Exploring a study*).

:class:`StudyFolder` checks the folder before anything is served: it holds what ``optimize --out`` writes (report.html,
front.csv, evaluations.csv), the two CSV files have the study's columns and every cell where a number belongs is one
(a finite one on the front), and the study's copy (:data:`~hapticdesign.optimization.study_explorer.STUDY_COPY`) is
bound again to compute cards. :func:`server` answers GET (and HEAD) of the files inside the folder and
``/api/card?evaluation=N``: evaluation N's card (:func:`~hapticdesign.optimization.study_explorer.evaluation_card`)
from its variables in evaluations.csv, as JSON. Nothing is written; a path that leaves the folder (``..``, an absolute
path, a link pointing out) is refused, and so is a request naming another host than the server's (a page elsewhere
cannot reach the folder by rebinding a name to 127.0.0.1).
"""

from __future__ import annotations

import csv
import errno
import json
import math
import mimetypes
import sys
import threading
from dataclasses import dataclass
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path, PurePosixPath
from urllib.parse import parse_qs, unquote, urlsplit

from hapticdesign.errors import UserError
from hapticdesign.files import csv_cell, quote
from hapticdesign.optimization.study_evaluation import BoundStudy, bind_study
from hapticdesign.optimization.study_explorer import STUDY_COPY, evaluation_card, study_of_copy
from hapticdesign.optimization.study_methods import method_of
from hapticdesign.optimization.study_outputs import without_unit
from hapticdesign.optimization.study_run import constraint_labels
from hapticdesign.studies.spec import spec_summary

HOST = "127.0.0.1"
"""The only address the server listens on: this machine alone reaches it."""

PAGE = "report.html"
REQUIRED = (PAGE, "front.csv", "evaluations.csv")
"""The files that make a folder a study's output (``optimize --out`` writes them when the front is not empty)."""


def _rows(path: Path) -> tuple[list[str], list[list[str]]]:
    """The header and rows of one of the folder's CSV files (streamed: evaluations.csv may be larger than a data
    file read whole)."""
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            rows = list(csv.reader(handle))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise UserError(f"cannot read {path}: {getattr(exc, 'strerror', None) or exc}") from None
    if not rows:
        raise UserError(f"{path} is empty; it is not a file optimize wrote (run optimize again into the folder)")
    return rows[0], rows[1:]


def _tampered(path: Path, where: str, what: str) -> UserError:
    return UserError(f"{path}: {where} {what}; the file was changed after the run (run optimize again into the folder)")


def _number(path: Path, row: int, column: str, cell: str, blank: bool) -> float:
    """A cell that must hold a finite number (or be blank, with ``blank``: a value the design has none of)."""
    if blank and cell == "":
        return math.nan
    try:
        value = float(cell)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise _tampered(path, f"row {row}, column {quote(column)},", f"holds {quote(cell)}, not a finite number")
    return value


@dataclass(frozen=True)
class Evaluated:
    """One row of evaluations.csv as the card needs it: its generation and variables."""

    generation: int
    values: dict[str, float]


class StudyFolder:
    """A study's output folder, checked (see the module): ``evaluations`` (evaluations.csv's rows, 1-based by their
    number), ``bound`` (the study bound again from its copy; None, and ``why`` says so, where cards cannot be
    computed here) and ``front`` (front.csv's rows)."""

    def __init__(self, root: Path):
        root = Path(root)
        if not root.is_dir():
            raise UserError(f"{root} is not a folder; explore serves a study's output folder (optimize --out)")
        missing = [name for name in REQUIRED if not (root / name).is_file()]
        if missing:
            raise UserError(f"{root} is not a study's output folder: it has no {', '.join(missing)} (optimize --out "
                            "writes them)")
        self.root = root.resolve()
        self.bound, self.why = self._bind()
        quantities = self._check_front()
        self.evaluations = self._check_evaluations(quantities)

    def _bind(self) -> tuple[BoundStudy | None, str]:
        copy = self.root / STUDY_COPY
        if not copy.is_file():
            return None, (f"the folder has no {STUDY_COPY} (optimize writes it since hapticdesign explore exists: run "
                          "it again into the folder)")
        study = study_of_copy(copy)
        if not method_of(study.spec).evaluates_designs:
            return None, f"method {study.spec.algorithm.method} solves one program; its design is the front's"
        try:
            return bind_study(study), ""
        except UserError as exc:  # an index of the user's own (optimize --indices), which is not run here
            return None, f"the study cannot be bound here: {exc}"

    def _names(self) -> list[str] | None:
        """The study's variables, objectives and constrained values, as the CSV headers name them (None without the
        study's copy)."""
        if self.bound is None:
            return None
        spec = self.bound.study.spec
        return [csv_cell(name) for name in (*spec.variables, *(o.name for o in spec.objectives),
                                            *constraint_labels(spec))]

    def _check_front(self) -> list[str]:
        """front.csv's quantity columns, every cell a finite number (front designs are feasible)."""
        path = self.root / "front.csv"
        header, rows = _rows(path)
        polished = header[-1:] == ["polished"]
        quantities = header[1:len(header) - polished]
        names = self._names()
        if header[:1] != ["design"] or not quantities or (
                names is not None and [without_unit(h) for h in quantities] != names):
            raise _tampered(path, "its header", f"is not the study's columns ({quote(','.join(header))})")
        if not rows:
            raise _tampered(path, "it", "has no design")
        for n, row in enumerate(rows, start=1):
            if len(row) != len(header):
                raise _tampered(path, f"row {n}", f"has {len(row)} cells, not {len(header)}")
            if row[0] != str(n):
                raise _tampered(path, f"row {n}", f"is numbered {quote(row[0])}")
            for column, cell in zip(quantities, row[1:]):
                _number(path, n, column, cell, blank=False)
            if polished and row[-1] not in ("yes", "no"):
                raise _tampered(path, f"row {n}, column polished,", f"holds {quote(row[-1])}, not yes or no")
        return quantities

    def _check_evaluations(self, quantities: list[str]) -> list[Evaluated]:
        """evaluations.csv's rows, with the front's quantity columns: numbered 1, 2, ...; variables finite numbers,
        the other quantities finite numbers or blank."""
        path = self.root / "evaluations.csv"
        header, rows = _rows(path)
        start = ["evaluation", "generation", *quantities, "feasible", "reason"]
        if header[:len(start)] != start or header[len(start):] not in ([], ["polished"]):
            raise _tampered(path, "its header", f"is not front.csv's columns ({quote(','.join(header))})")
        variables = [] if self.bound is None else list(self.bound.study.spec.variables)
        out = []
        for n, row in enumerate(rows, start=1):
            if len(row) != len(header):
                raise _tampered(path, f"row {n}", f"has {len(row)} cells, not {len(header)}")
            if row[0] != str(n):
                raise _tampered(path, f"row {n}", f"is numbered {quote(row[0])}")
            if not (row[1].isascii() and row[1].isdigit()):
                raise _tampered(path, f"row {n}, column generation,", f"holds {quote(row[1])}, not a whole number")
            values = [_number(path, n, column, cell, blank=k >= len(variables))
                      for k, (column, cell) in enumerate(zip(quantities, row[2:]))]
            if row[2 + len(quantities)] not in ("yes", "no"):
                raise _tampered(path, f"row {n}, column feasible,", f"holds {quote(row[2 + len(quantities)])}")
            out.append(Evaluated(int(row[1]), dict(zip(variables, values))))
        return out


class _Handler(BaseHTTPRequestHandler):
    """GET and HEAD of the folder's files and of ``/api/card``; nothing else (see the module)."""

    server_version = "hapticdesign-explore"
    folder: StudyFolder
    cards: dict[int, bytes]
    lock: threading.Lock

    def log_message(self, format: str, *args) -> None:  # noqa: A002 - the base class's name
        """No line per request."""

    def do_GET(self) -> None:  # noqa: N802 - http.server's name
        self._answer(body=True)

    def do_HEAD(self) -> None:  # noqa: N802 - http.server's name
        self._answer(body=False)

    def _send(self, status: HTTPStatus, data: bytes, kind: str, body: bool) -> None:
        self.send_response(status)
        self.send_header("Content-Type", kind)
        self.send_header("Content-Length", str(len(data)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.end_headers()
        if body:
            self.wfile.write(data)

    def _refuse(self, status: HTTPStatus, why: str, body: bool) -> None:
        self._send(status, json.dumps({"error": why}).encode(), "application/json", body)

    def _answer(self, body: bool) -> None:
        port = self.server.server_address[1]
        if self.headers.get("Host", "") not in (f"{HOST}:{port}", f"localhost:{port}"):
            self._refuse(HTTPStatus.FORBIDDEN, "this server answers only its own address", body)
            return
        split = urlsplit(self.path)
        if split.path == "/api/card":
            self._card(split.query, body)
            return
        path = unquote(split.path)
        if not path.startswith("/"):
            self._refuse(HTTPStatus.BAD_REQUEST, "not a path", body)
            return
        relative = path[1:] or PAGE
        parts = PurePosixPath(relative).parts
        if "\x00" in relative or "\\" in relative or PurePosixPath(relative).is_absolute() or ".." in parts:
            self._refuse(HTTPStatus.FORBIDDEN, "only the files inside the study's folder are served", body)
            return
        target = (self.folder.root / relative).resolve()
        if not target.is_relative_to(self.folder.root):  # a link pointing out of the folder
            self._refuse(HTTPStatus.FORBIDDEN, "only the files inside the study's folder are served", body)
            return
        if not target.is_file():
            self._refuse(HTTPStatus.NOT_FOUND, "no such file in the study's folder", body)
            return
        kind = mimetypes.guess_type(target.name)[0] or "application/octet-stream"
        if kind.startswith("text/") or kind in ("application/javascript", "application/json"):
            kind += "; charset=utf-8"
        try:
            data = target.read_bytes()
        except OSError:
            self._refuse(HTTPStatus.NOT_FOUND, "the file cannot be read", body)
            return
        self._send(HTTPStatus.OK, data, kind, body)

    def _card(self, query: str, body: bool) -> None:
        asked = parse_qs(query, keep_blank_values=True)
        text = asked.get("evaluation", [""])
        count = len(self.folder.evaluations)
        if set(asked) != {"evaluation"} or len(text) != 1 or not (text[0].isascii() and text[0].isdigit()) \
                or not 1 <= int(text[0]) <= count:
            self._refuse(HTTPStatus.BAD_REQUEST, f"ask for ?evaluation=N, N from 1 to {count} (evaluations.csv's rows)",
                         body)
            return
        if self.folder.bound is None:
            self._refuse(HTTPStatus.NOT_FOUND, self.folder.why, body)
            return
        n = int(text[0])
        with self.lock:  # one card at a time: study_outputs keeps the last design's poses
            if n not in self.cards:
                row = self.folder.evaluations[n - 1]
                try:
                    card = evaluation_card(self.folder.bound, n, row.generation, row.values, spec_summary)
                    self.cards[n] = json.dumps(card, allow_nan=False).encode()
                except UserError as exc:
                    self._refuse(HTTPStatus.UNPROCESSABLE_ENTITY, str(exc), body)
                    return
                except Exception as exc:  # noqa: BLE001 - a server answers every request: the failure in one line
                    self._refuse(HTTPStatus.INTERNAL_SERVER_ERROR, f"{type(exc).__name__}: {exc}", body)
                    return
            data = self.cards[n]
        self._send(HTTPStatus.OK, data, "application/json", body)


class _Server(ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request, client_address) -> None:
        """A connection the browser dropped (a page left while a file was sent) is no error; another is one line on
        stderr, not a traceback."""
        kind, exc = sys.exc_info()[:2]
        if kind is not None and not issubclass(kind, ConnectionError):
            print(f"error: a request failed: {kind.__name__}: {exc}", file=sys.stderr)


def server(folder: StudyFolder, port: int = 0) -> ThreadingHTTPServer:
    """The server of ``folder`` on 127.0.0.1 at ``port`` (0: a free one), not yet serving; a port in use or not
    allowed is a one-line UserError."""
    handler = type("Handler", (_Handler,), {"folder": folder, "cards": {}, "lock": threading.Lock()})
    try:
        httpd = _Server((HOST, port), handler)
    except OSError as exc:
        if exc.errno == errno.EADDRINUSE:
            raise UserError(f"port {port} on {HOST} is in use (choose another --port, or leave it out for a free "
                            "one)") from None
        raise UserError(f"cannot serve on {HOST} port {port}: {exc.strerror or exc}") from None
    return httpd


def address(httpd: ThreadingHTTPServer) -> str:
    """The page's address on ``httpd``."""
    return f"http://{HOST}:{httpd.server_address[1]}/{PAGE}"
