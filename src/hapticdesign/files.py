"""Reading and writing the user's files safely: one helper for every reader and writer.

Every data file (parameters, devices, URDF, weights, R-CUBE designs, design sets, campaign cases)
is read through :func:`read_text` and, when structured, :func:`load_structured`; every output
goes through :func:`write_atomically`. The limits are stated here once:

- a data file may hold at most ``MAX_FILE_BYTES`` (20 MB) of UTF-8 text; larger (counted on what
  is read, never on the size a file reports), binary (a NUL byte) or non-UTF-8 files are refused
  with one line, and so are named pipes and devices (``/dev/zero``), even through a symlink;
- YAML aliases and anchors are refused (data files are data: an alias "bomb" of a few lines
  expands to gigabytes), as are Python-specific tags (``yaml.SafeLoader`` already refuses them);
- structures nested deeper than ``MAX_DEPTH`` (64) levels are refused, and so are texts holding a character
  of :data:`NOT_TEXT` (control characters, lone surrogates: a name that XML or UTF-8 cannot carry);
- a message quotes at most ``QUOTE_LIMIT`` (60) characters of a user's value (:func:`quote`);
- a CSV output is written by :func:`csv_rows`: a text cell that a spreadsheet would run as a formula is
  written as text (:func:`csv_cell`);
- a figure is rendered by :func:`figure_bytes`: the same figure gives the same bytes (SVG ids
  hashed with a fixed salt, no creation date in SVG or PDF);
- a signal that ends the process (Ctrl-C, SIGTERM, SIGHUP) while :func:`write_atomically` writes is held until
  the file is complete and in its place (:func:`signals_held`): an interrupted run leaves only complete files.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
import signal
import stat
import threading
import tomllib
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import yaml

from hapticdesign.errors import UserError

MAX_FILE_BYTES = 20 * 1024 * 1024
MAX_DEPTH = 64
QUOTE_LIMIT = 60


def quote(value: object, limit: int = QUOTE_LIMIT) -> str:
    """``repr(value)`` cut to ``limit`` characters (a message never echoes a whole hostile value)."""
    if isinstance(value, (dict, list, tuple)) and len(value) > 8:
        return f"<{type(value).__name__} of {len(value)} items>"
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def read_text(path: Path | str, what: str = "file") -> str:
    """The UTF-8 text of a user's file, or a one-line :class:`UserError` (missing, too large, binary,
    not a regular file).

    The file type is checked before opening (through symlinks): a named pipe is never opened (it
    would block until a writer comes), a device such as ``/dev/zero`` is never read (it has no
    end). At most ``MAX_FILE_BYTES + 1`` bytes are read, whatever size the file reports.
    """
    path = Path(path)
    if "\x00" in str(path):
        raise UserError(f"cannot read {what} {quote(str(path))}: a file name holds no NUL character")
    try:
        mode = os.stat(path).st_mode
        if stat.S_ISDIR(mode):
            raise UserError(f"cannot read {what} {path}: it is a directory")
        if not stat.S_ISREG(mode):
            raise UserError(f"cannot read {what} {path}: it is {_special_kind(mode)}, not a regular file")
        with open(path, "rb", opener=_nonblocking) as handle:
            if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):  # swapped after the check above
                raise UserError(f"cannot read {what} {path}: it is not a regular file")
            data = handle.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise UserError(f"cannot read {what} {path}: {exc.strerror or exc}") from None
    if len(data) > MAX_FILE_BYTES:
        raise UserError(f"{what} {path} is larger than {MAX_FILE_BYTES // 2**20} MB; data files are limited to "
                        f"{MAX_FILE_BYTES // 2**20} MB")
    if b"\x00" in data:
        raise UserError(f"{what} {path} is a binary file, not text")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise UserError(f"{what} {path} is not UTF-8 text (byte {exc.start})") from None


def _nonblocking(path: str, flags: int) -> int:
    """Open without waiting (a pipe swapped in after the type check must not block the read)."""
    return os.open(path, flags | os.O_NONBLOCK)


def _special_kind(mode: int) -> str:
    """Words for a file type that is not a regular file or a directory."""
    if stat.S_ISFIFO(mode):
        return "a named pipe"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a special file"


class _DataLoader(yaml.SafeLoader):
    """YAML's safe loader without aliases, reading ``1e-1`` as a number (YAML 1.2, as JSON and TOML do)."""

    def compose_node(self, parent, index):  # noqa: D102 - PyYAML hook
        if self.check_event(yaml.events.AliasEvent):
            event = self.peek_event()
            raise yaml.YAMLError(f"aliases (*{event.anchor}) are not allowed in data files, line "
                                 f"{event.start_mark.line + 1}")
        return super().compose_node(parent, index)


_FLOAT = re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$")
_DataLoader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT, list("-+0123456789"))


def _depth(value: object, limit: int) -> int:
    """Nesting depth of lists and mappings, without recursion (stops counting past ``limit``)."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        item, level = stack.pop()
        if isinstance(item, (dict, list)):
            deepest = max(deepest, level)
            if deepest > limit:
                return deepest
            children = item.values() if isinstance(item, dict) else item
            stack.extend((child, level + 1) for child in children)
    return deepest


NOT_TEXT = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
"""Characters no text of a data file may hold: control characters other than tab and line breaks, lone
surrogates (not characters: they cannot be written as UTF-8) and U+FFFE/U+FFFF (XML 1.0 forbids all of them,
so a name holding one would make a malformed MJCF or URDF file)."""


def _first_not_text(value: object) -> tuple[str, str] | None:
    """The first string (key or value) holding a :data:`NOT_TEXT` character, and that character."""
    stack = [value]
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            found = NOT_TEXT.search(item)
            if found:
                return item, found.group()
        elif isinstance(item, dict):
            stack.extend(item.keys())
            stack.extend(item.values())
        elif isinstance(item, list):
            stack.extend(item)
    return None


def parse_structured(text: str, kind: str, where: str) -> object:
    """Parse JSON, YAML or TOML text (``kind``: json, yaml, toml) with the limits above."""
    try:
        if kind == "json":
            data = json.loads(text)
        elif kind == "yaml":
            data = yaml.load(text, Loader=_DataLoader)  # noqa: S506 - a SafeLoader subclass
        elif kind == "toml":
            data = tomllib.loads(text)
        else:
            raise UserError(f"{where}: unknown file type {kind!r} (use .json, .yaml, .yml or .toml)")
    except RecursionError:
        raise UserError(f"{where}: nested too deeply (at most {MAX_DEPTH} levels)") from None
    except (json.JSONDecodeError, yaml.YAMLError, tomllib.TOMLDecodeError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise UserError(f"{where}: malformed {kind.upper()} ({first[:200]})") from None
    if _depth(data, MAX_DEPTH) > MAX_DEPTH:
        raise UserError(f"{where}: nested too deeply (at most {MAX_DEPTH} levels)")
    bad = _first_not_text(data)
    if bad is not None:
        raise UserError(f"{where}: {quote(bad[0])} holds the character U+{ord(bad[1]):04X}, which no text of a data "
                        "file may hold (a control character, a lone surrogate or a non-character)")
    return data


def structured_kind(path: Path | str) -> str:
    """The kind of data file :func:`parse_structured` reads by ``path``'s suffix (json, yaml or toml), "" for another."""
    return {".json": "json", ".yaml": "yaml", ".yml": "yaml", ".toml": "toml"}.get(Path(path).suffix.lower(), "")


def load_structured(path: Path | str, what: str = "file") -> object:
    """Read and parse a JSON, YAML or TOML file chosen by its suffix."""
    path = Path(path)
    kind = structured_kind(path)
    if not kind:
        raise UserError(f"{path}: unknown file type {quote(path.suffix)} (use .json, .yaml, .yml or .toml)")
    return parse_structured(read_text(path, what), kind, str(path))


FORMULA_START = ("=", "+", "-", "@", "\t", "\r")
"""First characters by which a spreadsheet takes a cell for a formula (OWASP's CSV injection rule)."""


def csv_cell(value: object) -> object:
    """A CSV cell a spreadsheet shows as it is: a text that begins with a :data:`FORMULA_START` character and is not
    a number (an objective named ``=HYPERLINK(...)``, an expression ``-l1 + l2``) gets a leading ``'``; numbers
    (``-0.5``) and other values are unchanged."""
    if not isinstance(value, str) or not value.startswith(FORMULA_START):
        return value
    try:
        float(value)
        return value
    except ValueError:
        return "'" + value


def csv_rows(header: list[str], rows) -> str:
    """CSV text (newline-terminated lines) of ``header`` and ``rows``, every cell through :func:`csv_cell`: the one
    CSV writer of the outputs."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([csv_cell(v) for v in header])
    writer.writerows([csv_cell(v) for v in row] for row in rows)
    return buffer.getvalue()


def to_jsonable(value):
    """NumPy arrays and scalars to plain lists and floats."""
    if isinstance(value, dict):
        return {k: to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def _first_non_finite(value, path: str = "") -> str | None:
    if isinstance(value, float) and not math.isfinite(value):
        return path or "the result"
    if isinstance(value, dict):
        for k, v in value.items():
            found = _first_non_finite(v, f"{path}.{k}" if path else str(k))
            if found:
                return found
    if isinstance(value, list):
        for i, v in enumerate(value):
            found = _first_non_finite(v, f"{path}[{i}]")
            if found:
                return found
    return None


def require_finite(value) -> object:
    """``value`` as plain data (lists, floats), or a :class:`UserError` naming the first NaN or infinity in it."""
    plain = to_jsonable(value)
    bad = _first_non_finite(plain)
    if bad is not None:
        raise UserError(f"the result is not finite ({bad}); check that the inputs are within physical ranges")
    return plain


def dumps_json(value, **kwargs) -> str:
    """Strict JSON: a NaN or infinity is refused with the key that holds it (it is not JSON)."""
    return json.dumps(require_finite(value), **kwargs)


def _refuse_in_place(path: Path) -> None:
    """Refuse an output ``path`` that exists and is not a regular file (or a link to one, or to nothing): a
    directory, a named pipe, a device, a socket is never replaced or opened (replacing ``/dev/full`` as root
    would remove the machine's device)."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None
    if stat.S_ISLNK(mode):  # the link is replaced, never followed; but a link to a special file says a mistake
        try:
            mode = os.stat(path).st_mode
        except OSError:
            return
    if stat.S_ISDIR(mode):
        raise UserError(f"cannot write {path}: it is a directory")
    if not stat.S_ISREG(mode):
        raise UserError(f"cannot write {path}: it is {_special_kind(mode)}, not a regular file; it is left as it is")


def output_folder(path: Path | str) -> Path:
    """``path`` as a real folder to write into (created when missing): a symbolic link or a file in its place is
    refused, so that nothing is written through a link out of the output folder (``OUT/checkpoint`` linked to
    another place), and so is a folder this process may not write into."""
    path = Path(path)
    if path.is_symlink() or (path.exists() and not path.is_dir()):
        kind = "a symbolic link" if path.is_symlink() else "not a folder"
        raise UserError(f"{path} is {kind}; outputs go only into real folders inside the output folder (remove it "
                        "or choose another output folder)")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"cannot write into {path}: {exc.strerror or exc}") from None
    if not os.access(path, os.W_OK | os.X_OK):  # said now, not after the work (a read-only folder)
        raise UserError(f"cannot write into {path}: permission denied")
    return path


def _write_new(path: Path, data: bytes) -> None:
    """Write ``data`` to a file that this call creates (never through a file, link or pipe already there)."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags, 0o666)
    except FileExistsError:  # a leftover of an earlier run of this process id (or something put there): replaced
        path.unlink()
        fd = os.open(path, flags, 0o666)
    with os.fdopen(fd, "wb") as handle:
        handle.write(data)


HELD_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))
"""The signals :func:`signals_held` holds: Ctrl-C, a ``kill`` and a closed terminal."""


@contextmanager
def signals_held() -> Iterator[None]:
    """Hold :data:`HELD_SIGNALS` over the block and deliver them after it, to the handlers there were before (a
    SIGTERM then ends the process as it would have, once the block is done). Off the main thread (where Python
    cannot set a handler) the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    previous = {number: signal.signal(number, lambda signum, frame: caught.append(signum))
                for number in HELD_SIGNALS}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, signal.SIG_DFL if handler is None else handler)
        for number in dict.fromkeys(caught):
            signal.raise_signal(number)


def write_atomically(path: Path | str, content: str | bytes) -> None:
    """Write a file so that an interruption or a failure never leaves it (or a ``.tmp``) half-written.

    The content goes to a new temporary file beside ``path``, which then replaces ``path``: a symbolic link
    at ``path`` is replaced, not followed; a directory, named pipe, device or socket there is refused
    (:func:`_refuse_in_place`). Any problem with the output place (a read-only folder, a full disk) is a
    one-line :class:`UserError`; text that cannot be UTF-8 (a lone surrogate) is refused before anything is
    written. A signal that would end the process meanwhile (SIGTERM to a run's checkpoints) waits until the file
    is in its place (:func:`signals_held`).
    """
    path = Path(path)
    _refuse_in_place(path)
    if isinstance(content, str):
        try:
            content = content.encode("utf-8")
        except UnicodeEncodeError as exc:
            raise UserError(f"cannot write {path}: the text holds {quote(exc.object[exc.start:exc.end])}, "
                            "which is not a character (a lone surrogate)") from None
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with signals_held():
            path.parent.mkdir(parents=True, exist_ok=True)
            _write_new(tmp, content)
            tmp.replace(path)
    except OSError as exc:
        try:
            tmp.unlink(missing_ok=True)
        except OSError:  # the place itself is broken (a file where a folder should be): nothing was written
            pass
        raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None
    except BaseException:  # a Ctrl-C between writing and renaming: no .tmp left behind
        tmp.unlink(missing_ok=True)
        raise


FIGURE_SALT = "hapticdesign"
"""``svg.hashsalt`` of every figure: matplotlib hashes SVG ids with a random salt unless one is set."""
_UNDATED = {"svg": {"Date": None}, "pdf": {"CreationDate": None, "ModDate": None}}


def figure_bytes(fig, fmt: str, **options) -> bytes:
    """A matplotlib figure as ``fmt`` (png, svg, pdf) bytes, identical for identical figures (no date,
    a fixed SVG hash salt); ``options`` go to ``savefig`` (dpi, bbox_inches)."""
    import matplotlib

    buffer = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": FIGURE_SALT}):
        fig.savefig(buffer, format=fmt, metadata=_UNDATED.get(fmt), **options)
    return buffer.getvalue()


def save_figure(fig, path: Path | str, **options) -> Path:
    """Write ``fig`` to ``path`` in the format its suffix names (PNG without one), through
    :func:`figure_bytes` and :func:`write_atomically`."""
    path = Path(path)
    write_atomically(path, figure_bytes(fig, path.suffix[1:].lower() or "png", **options))
    return path
