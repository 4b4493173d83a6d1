"""Command ``explore``: a study's output folder served on 127.0.0.1, read-only, its explorer computing the card of any
evaluated design on demand (docs/optimization.md, *Exploring a study*)."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from hapticdesign.interface.common import note, print_json, user_errors
from hapticdesign.interface.options import JSON_OUT, QUIET

FOLDER = typer.Argument(..., help="A study's output folder (optimize --out): report.html, front.csv, evaluations.csv "
                        "and study.json.")
PORT = typer.Option(0, "--port", min=0, max=65535, help="The port on 127.0.0.1 (0, the default: a free one).")


def register(app: typer.Typer) -> None:
    @app.command()
    def explore(out: Path = FOLDER, port: int = PORT, json_out: bool = JSON_OUT, quiet: bool = QUIET) -> None:
        """Serve a study's output folder on 127.0.0.1 (read-only) until Ctrl-C: its report.html, the explorer of the front and every evaluated design (seed 001 §7.2 selects among them), with any design's card computed on demand."""
        from hapticdesign.interface.commands.explore_adapter import StudyFolder, address, server

        with user_errors(quiet=quiet):
            folder = StudyFolder(out)
            httpd = server(folder, port)
        try:
            if folder.bound is None:
                note(f"cards of the designs off the front cannot be computed: {folder.why}", quiet)
            if json_out:
                print_json({"address": address(httpd), "folder": str(folder.root), "cards": folder.bound is not None,
                            "evaluations": len(folder.evaluations)})
            else:
                typer.echo(f"serving {folder.root} at {address(httpd)} (read-only; Ctrl-C stops)")
            sys.stdout.flush()
            httpd.serve_forever()
        except KeyboardInterrupt:
            note("stopped", quiet)
        finally:
            httpd.server_close()
