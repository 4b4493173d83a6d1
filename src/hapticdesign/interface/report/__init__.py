"""Self-contained HTML reports of studies: figures embedded, tables also as CSV, figures also as PNG and SVG.

:func:`write_report` writes ``report.html`` (readable offline: images are base64 PNG, styles inline,
no scripts), ``tables/<name>.csv``, ``figures/<name>.png|svg`` and ``summary.json``.
"""

from hapticdesign.interface.report.writer import write_report

__all__ = ["write_report"]
