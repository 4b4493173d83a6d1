"""Small design files built from the preset's parameters (stand-ins for the Linearity issue's sets)."""

import csv
from pathlib import Path

from hapticdesign.devices.registry import preset
from hapticdesign.simulation.campaign import META_COLUMNS

PERTURBATIONS = [
    (0.0, {}),
    (0.0, {"Izz1": 0.003}),
    (1.0, {"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05}),
    (1.0, {"Ixz3": 1e-3, "Ixz2": 1e-3, "r2az": 0.02}),
]


def write_designs(path: Path, rows=PERTURBATIONS, drop: str | None = None, edit: dict | None = None) -> Path:
    device = preset("phantom-3dof")
    names = device.inertial_names()
    columns = ["design", *META_COLUMNS, *names]
    with Path(path).open("w", newline="") as handle:
        writer = csv.DictWriter(handle, [c for c in columns if c != drop])
        writer.writeheader()
        for i, (level, overrides) in enumerate(rows):
            values = {**{n: device.params[n] for n in names}, **overrides, **(edit or {})}
            row = {"design": f"x{i}", "level": level, "ln": level, "ln_H": 0.0, "ln_C": 0.0, "ln_G": level, **values}
            writer.writerow({k: v for k, v in row.items() if k != drop})
    return Path(path)
