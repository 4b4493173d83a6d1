"""Regenerate the Phantom Premium's spec sheet of README.md and docs/device-files.md (Markdown rows).

Run: PYTHONPATH=src python docs/scripts/phantom_spec.py
"""

from __future__ import annotations

import warnings
from pathlib import Path

from hapticdesign.devices.device_file import load_device_file
from hapticdesign.studies.spec import spec_sheet

ROOT = Path(__file__).resolve().parents[2]


def main() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        device = load_device_file(ROOT / "examples" / "devices" / "phantom-premium.yaml")
    s = spec_sheet(device)
    walls = s["renderable_stiffness"]
    rows = [
        ("position resolution", f"{1000 * s['resolution']:.3f} mm", "0.03 mm"),
        ("continuous force", f"{s['force_continuous']:.2f} N", "1.4 N"),
        ("peak force", f"{s['force_peak']:.2f} N", "8.5 N"),
        ("apparent mass", f"{1000 * s['apparent_mass']['min']:.0f}-{1000 * s['apparent_mass']['max']:.0f} g",
         "under 75 g"),
        ("backdrive friction", f"{s['backdrive_friction']['min']:.3f}-{s['backdrive_friction']['max']:.3f} N", ""),
        ("workspace cube around home", f"{s['workspace']['cube']:.0f} mm", ""),
        ("renderable stiffness", f"{walls['exact']:.1f} N/m exact (1 kHz, one sample late, gravity compensation, "
         f"every joint free); {walls['exact_with_hand']:.0f} N/m with a light grasp ({walls['hand']['mass']:g} kg, "
         f"{walls['hand']['damping']:g} N s/m, {walls['hand']['stiffness']:g} N/m); {walls['simulated']:.0f} N/m "
         f"simulated with dry friction and quantization; passivity 2b/T = {walls['passivity_viscous']:.1f}, "
         f"2 f_c/Delta = {walls['passivity_coulomb']:.0f} N/m", "800 N/m (CHAI3D)"),
    ]
    print("| | hapticdesign, at home (q = 0) | vendor |")
    print("| --- | --- | --- |")
    for name, ours, theirs in rows:
        print(f"| {name} | {ours} | {theirs} |")


if __name__ == "__main__":
    main()
