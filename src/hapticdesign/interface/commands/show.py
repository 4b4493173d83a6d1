"""Command ``show``: a picture of a device, an interactive 3D HTML page and a static PNG."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from hapticdesign.errors import UserError
from hapticdesign.interface.common import note, print_json, user_errors
from hapticdesign.interface.options import DEVICE, FORCE, FORCE_HINT, JSON_OUT, PARAMS, PRESET, QUIET, STRICT
from hapticdesign.workload import allow_large


def show(
    preset: Optional[str] = PRESET,
    device: Optional[Path] = DEVICE,
    params: Optional[Path] = PARAMS,
    out: Path = typer.Option(Path("device-view"), "--out", help="Directory for device.html and device.png."),
    q: Optional[str] = typer.Option(None, help="Actuated joint values, comma-separated (rad or m); default zeros or the file's home (mid-range where "
                                               "zero is outside a joint's limits)."),
    strict: bool = STRICT,
    json_out: bool = JSON_OUT,
    quiet: bool = QUIET,
    force: bool = FORCE,
) -> None:
    """Draw a device (frames and links of seed 000 §2.1-2.3): OUT/device.html and OUT/device.png.

    The page is a self-contained 3D view with a slider per actuated joint; the PNG is for papers."""
    from hapticdesign.analysis.view.figure import render_png
    from hapticdesign.analysis.view.page import render_page
    from hapticdesign.analysis.view.skeleton import export, parse_pose
    from hapticdesign.files import write_atomically
    from hapticdesign.interface.commands.pose_adapter import assembly_branch, branch_line

    with user_errors(quiet=quiet), allow_large(force, FORCE_HINT):
        from hapticdesign.devices.loading import resolve_device

        dev = resolve_device(preset, device, params, strict=strict)
        pose = parse_pose(q, dev)
        for message in dev.limit_warnings(pose):
            note(f"warning: {message}", quiet)
        if out.exists() and not out.is_dir():
            raise UserError(f"--out: {out} is a file; give a directory for device.html and device.png")
        html_path, png_path = out / "device.html", out / "device.png"
        write_atomically(html_path, render_page(export(dev, pose)))
        write_atomically(png_path, render_png(dev, pose))
        branch = assembly_branch(dev)
        if json_out:
            print_json({"device": dev.name, "q": pose, "html": str(html_path), "png": str(png_path),
                        **({"assembly_branch": branch} if branch is not None else {})})
            return
        note(f"wrote {html_path} and {png_path}", quiet)
        if branch is not None:
            note(branch_line(branch), quiet)


def register(app: typer.Typer) -> None:
    app.command("show")(show)
