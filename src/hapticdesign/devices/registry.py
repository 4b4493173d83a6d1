"""Built-in device presets by name."""

from __future__ import annotations

from collections.abc import Callable

from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.devices.phantom import phantom_3dof, phantom_6dof

PRESETS: dict[str, Callable[[], Device]] = {
    "phantom-3dof": phantom_3dof,
    "phantom-6dof": phantom_6dof,
}

DEFAULT_PRESET = "phantom-3dof"


def preset(name: str) -> Device:
    """The preset device ``name`` with its default parameters."""
    try:
        return PRESETS[name]()
    except KeyError:
        raise UserError(f"unknown preset {name!r}; choose one of {', '.join(sorted(PRESETS))}") from None
