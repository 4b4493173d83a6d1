"""The generic engines read the Phantom's own data from the device (its preset's data), not from its name.

A preset renamed keeps the seed's practical bounds (eq. 3.29-3.32, the numbers written out here), the seed's
dependent variables (eq. 3.12-3.26) and the seed's loop settings; a device called ``phantom-3dof`` whose source gives
no such data gets the generic ones, as any device file does.
"""

from __future__ import annotations

from dataclasses import replace

import pytest

from hapticdesign.analysis.linearity.bounds import GENERIC, BodyBounds, practical_bounds
from hapticdesign.analysis.linearity.conditions import linear_conditions, seed_conditions
from hapticdesign.interface.commands.simulation import seed_settings
from hapticdesign.model.device import PresetData

# Seed 000 eq. 3.29-3.32: links 2 and 3a from 0.15 to 0.30 kg, links 2a and 3 from 0.02 to 0.15 kg, every mass centre
# coordinate within +-0.25 m, moments from 1e-5 to 1e-2 kg m^2, products within +-1e-2 kg m^2.
SEED_BOUNDS = {
    "2": BodyBounds((0.15, 0.30), (-0.25, 0.25), (1e-5, 1e-2), 1e-2),
    "3a": BodyBounds((0.15, 0.30), (-0.25, 0.25), (1e-5, 1e-2), 1e-2),
    "2a": BodyBounds((0.02, 0.15), (-0.25, 0.25), (1e-5, 1e-2), 1e-2),
    "3": BodyBounds((0.02, 0.15), (-0.25, 0.25), (1e-5, 1e-2), 1e-2),
}
SEED_DEPENDENTS = {"r2x", "r2y", "r2z", "r2ay", "r3x", "r3y", "r3z", "r3ax", "r3az", "Iyy2a", "Izz3a", "Ixy2", "Iyz2",
                   "Ixy3", "Ixz3"}


def test_a_renamed_preset_keeps_the_seeds_bounds_and_settings(phantom3, phantom6):
    renamed = replace(phantom3, name="my-phantom")
    assert practical_bounds(phantom3) == SEED_BOUNDS
    assert practical_bounds(renamed) == SEED_BOUNDS
    six = practical_bounds(replace(phantom6, name="my-phantom-6"))
    assert {b: six[b] for b in SEED_BOUNDS} == SEED_BOUNDS
    assert set(six) == {*SEED_BOUNDS, "4", "5", "6"}
    assert all(six[b].mass == (0.005, 0.05) for b in ("4", "5", "6"))
    assert seed_settings(renamed, None) and seed_settings(phantom6, None)
    assert not seed_settings(renamed, "practice") and not seed_settings(None, None)


def test_a_device_named_phantom_without_its_data_is_generic(phantom3, form3):
    impostor = replace(phantom3, preset_data=PresetData())
    assert impostor.name == "phantom-3dof"
    bodies = practical_bounds(impostor)
    assert set(bodies) == {b for b in phantom3.body_names if phantom3.body(b).m > 0}
    assert all(b == GENERIC for b in bodies.values())
    assert not seed_settings(impostor, None)


def test_the_seeds_dependents_come_with_the_device(phantom3, form3):
    """The seed's own choice of dependent variables (eq. 3.12-3.26) and their pivots are the device's, under any
    name; without them the search pivots on its own preference (first moments, products, moments, masses)."""
    renamed = replace(phantom3, name="my-phantom")
    conditions = linear_conditions(renamed, form3)
    assert {s.name for s in seed_conditions(renamed, conditions).solution} == SEED_DEPENDENTS
    assert conditions.pivots == linear_conditions(phantom3, form3).pivots
    plain = linear_conditions(replace(phantom3, preset_data=PresetData()), form3)
    assert len(plain.pivots) == len(conditions.pivots) and plain.pivots != conditions.pivots


@pytest.mark.parametrize("name", ["phantom-3dof", "phantom-6dof"])
def test_a_device_file_is_never_the_seeds_by_name(tmp_path, name):
    """A device file called like a preset is an ordinary device: practice's loop settings, generic bounds."""
    from hapticdesign.devices.loading import resolve_device

    path = tmp_path / "slider.yaml"
    path.write_text(f"name: {name}\njoints:\n  - {{name: x, type: prismatic, damping: 2.0}}\nframes:\n"
                    "  - {name: handle, parent: base, transforms: [tx: x]}\nend_effector: handle\n"
                    "bodies:\n  - {name: h, frame: handle, m: 0.5}\n")
    device = resolve_device(None, path, None)
    assert device.name == name and not seed_settings(device, None)
    assert practical_bounds(device) == {"h": GENERIC}
