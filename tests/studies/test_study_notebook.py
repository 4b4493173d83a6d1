"""examples/quickstart.ipynb runs top to bottom (executed with nbclient, not only checked)."""

from __future__ import annotations

import importlib
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

import hapticdesign

pytestmark = pytest.mark.slow  # end to end: deselect with -m "not slow"

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

# The top-level names the notebook uses and the engine objects they must be.
TOP_LEVEL = {
    "preset": "hapticdesign.devices.registry:preset",
    "load_device": "hapticdesign.devices.loading:load_device",
    "mass_matrix": "hapticdesign.analysis.dynamics.device:mass_matrix",
    "gravity": "hapticdesign.analysis.dynamics.device:gravity",
    "inverse_dynamics": "hapticdesign.analysis.dynamics.device:inverse_dynamics",
    "forward_dynamics": "hapticdesign.analysis.dynamics.device:forward_dynamics",
    "linearity_form": "hapticdesign.analysis.linearity.form:device_form",
    "linear_conditions": "hapticdesign.analysis.linearity.conditions:linear_conditions",
    "impedance_range": "hapticdesign.simulation.impedance:impedance_range",
    "transparency": "hapticdesign.simulation.transparency:transparency",
}


def _target(spec: str):
    module, name = spec.split(":")
    return getattr(importlib.import_module(module), name)


def test_exported_names_are_the_engines():
    for name, spec in TOP_LEVEL.items():
        assert getattr(hapticdesign, name) is _target(spec), name


def test_notebook_executes():
    nb = nbformat.read(EXAMPLES / "quickstart.ipynb", as_version=4)
    used = {name for name in TOP_LEVEL if any(f"hd.{name}" in c.source for c in nb.cells)}
    assert used == set(TOP_LEVEL)
    NotebookClient(nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(EXAMPLES)}}).execute()
    outputs = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.outputs)
    assert "maximum stable impedance" in outputs and "LN after projection" in outputs
    assert not any(o.output_type == "error" for c in nb.cells if c.cell_type == "code" for o in c.outputs)
