"""Load a device from a file, and resolve the device a command works on (a preset or a file, plus overrides)."""

from __future__ import annotations

from pathlib import Path

from hapticdesign.devices.registry import DEFAULT_PRESET, preset
from hapticdesign.errors import InputError
from hapticdesign.model.device import Device
from hapticdesign.model.params_io import read_parameters


def load_device(path: str | Path) -> Device:
    """A device from a device file (YAML, TOML, JSON) or a URDF file (``.urdf``; see docs/device-files.md)."""
    path = Path(path)
    if path.suffix.lower() == ".urdf":
        from hapticdesign.devices.urdf import load_urdf

        return load_urdf(path)
    from hapticdesign.devices.device_file import load_device_file

    return load_device_file(path)


def resolve_device(
    preset_name: str | None = None,
    device_file: Path | None = None,
    params_file: Path | None = None,
    strict: bool = False,
    check: bool = True,
) -> Device:
    """The device named by ``--preset`` or ``--device``, with ``--params`` applied and checked.

    Physical consistency errors raise :class:`~hapticdesign.errors.UserError`; bodies that are positive definite but
    break the triangle inequality warn (``strict`` makes them errors).
    """
    if preset_name and device_file:
        raise InputError("give either a preset or a device file, not both", "preset", "device")
    if device_file is not None:
        device = load_device(device_file)
    else:
        device = preset(preset_name or DEFAULT_PRESET)
    if params_file is not None:
        device = device.with_params(read_parameters(Path(params_file)))
    if check:
        device.check(strict=strict)
    return device
