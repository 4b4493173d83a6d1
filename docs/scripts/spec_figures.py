"""Regenerates the spec sheet's figures shown in docs/device-files.md: the workspace sections and the quantities over
them for examples/devices/falcon-assumed-motors.yaml and phantom-premium.yaml, as ``hapticdesign spec --out`` draws
them, into docs/figures/spec/<device>-sections.png and <device>-quantities.png.

Run: ``.venv/bin/python docs/scripts/spec_figures.py`` (a minute or two per device on a shared 2-core machine).
"""

from __future__ import annotations

from pathlib import Path

from hapticdesign.devices.loading import load_device
from hapticdesign.studies.spec import spec_sheet
from hapticdesign.studies.spec_maps import quantity_png, sheet_sections, workspace_png

ROOT = Path(__file__).resolve().parents[2]
DEVICES = ("falcon-assumed-motors", "phantom-premium")
TARGET = ROOT / "docs" / "figures" / "spec"


def main() -> None:
    TARGET.mkdir(parents=True, exist_ok=True)
    for name in DEVICES:
        device = load_device(ROOT / "examples" / "devices" / f"{name}.yaml")
        sheet = spec_sheet(device, simulate=False)
        sections, edge = sheet_sections(device, sheet)
        (TARGET / f"{name}-sections.png").write_bytes(workspace_png(device, sections, edge))
        quantities = quantity_png(device, sections, edge)
        if quantities is not None:
            (TARGET / f"{name}-quantities.png").write_bytes(quantities)
        print(f"{name}: cube {sheet['workspace']['cube']:.4g} mm, figures in {TARGET.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
