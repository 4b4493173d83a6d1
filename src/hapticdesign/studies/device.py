"""Study ``device``: seed 000's analyses on a device of one's own (a device file or a preset).

Equations of motion, the Linearity Number, the analytic linearization with realizable linear
designs, the verdict whether a realizable fully linear design exists, and the rendering
simulations of its first joint. Design sets and campaigns stay with ``study phantom``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

from hapticdesign.errors import PhysicalConsistencyWarning
from hapticdesign.studies import device_steps, phantom_rendering
from hapticdesign.studies.steps import Step

@dataclass(frozen=True)
class DeviceSettings:
    """The device (``--device FILE`` or ``--preset NAME``, the built-in default without either); one size."""

    device_file: str | None = None
    preset: str | None = None
    seed: int = 1
    k_limit: int = 200

    @classmethod
    def for_device(cls, device_file: Path | None, preset: str | None, seed: int = 1) -> "DeviceSettings":
        settings = cls(str(device_file) if device_file else None, preset, seed)
        settings.device()  # a bad file or name fails now, with its one-line message
        return settings

    def device(self):
        from hapticdesign.devices.loading import resolve_device

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PhysicalConsistencyWarning)
            return resolve_device(self.preset, Path(self.device_file) if self.device_file else None)

    def design_note(self) -> str:
        return ""

    def estimate_seconds(self) -> float:
        """Run time on a quiet 2-core machine with compiled kernels (measured warm: five-bar 15 s, arm-3r
        12 s of CPU; 50 s and 39 s of wall time under a load average of 9-10)."""
        return 30.0 + 10.0 * self.device().n_dof


def steps() -> list[Step]:
    return [
        Step("device", "The device (seed 000 §2.1-2.3)", device_steps.device_view),
        Step("eom", "Equations of motion (seed 000 eq. 2.50-2.52)", device_steps.equations_of_motion),
        Step("ln", "Linearity Number (seed 000 eq. 3.1-3.4)", device_steps.linearity_number),
        Step("linearization", "Analytic linearization and realizable linear designs (seed 000 §3.2.1)",
             device_steps.linearization),
        Step("verdict", "Can it be made fully linear? (seed 000 §3.3)", device_steps.verdict),
        Step("rendering", "Rendering on joint 1: stable impedance and transparency (seed 000 §4.1-4.2)",
             phantom_rendering.default_design),
    ]


TITLE = "Device study: equations of motion, linearity and haptic rendering"
INTRO = ("Seed 000's analyses (Kizilbey 2019) on the given device: exact equations of motion, the Linearity Number, "
         "the conditions for fully linear dynamics with realizable designs that meet them, the verdict whether one "
         "exists, and the maximum stable impedance and transparency bandwidth of joint 1 at the seed's settings.")


def run(settings: DeviceSettings, work_dir, progress=None):
    from hapticdesign.studies.study import run_pipeline

    return run_pipeline("device", f"{TITLE} ({settings.device().name})", INTRO, steps(), settings, work_dir, progress)
