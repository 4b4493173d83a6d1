"""hapticdesign: design kinesthetic haptic devices for high impedance performance.

The Python surface, in the order of the seeds (seed 000: Phantom, LN, rendering; seed 001:
R-CUBE):

- :func:`preset`, :func:`load_device`, :class:`Device`: devices and their parameters.
- :func:`mass_matrix`, :func:`coriolis_centrifugal`, :func:`coriolis_matrix`, :func:`gravity`,
  :func:`inverse_dynamics`, :func:`forward_dynamics` of a device, and :func:`dynamics_of` (the
  regressor model, vectorized over poses and parameter sets).
- :func:`linearity_form` (LN as a quadratic form; ``form.ln``, ``form.parts``) and
  :func:`linear_conditions` (the linear equations of LN = 0).
- :func:`impedance_range`, :func:`transparency`: the sampled-data rendering criteria.
- :mod:`hapticdesign.analysis.rcube` and :mod:`hapticdesign.optimization`: the R-CUBE.
"""

from hapticdesign.analysis.dynamics.device import (
    coriolis_centrifugal,
    coriolis_matrix,
    dynamics_of,
    forward_dynamics,
    gravity,
    inverse_dynamics,
    mass_matrix,
)
from hapticdesign.analysis.linearity.conditions import linear_conditions
from hapticdesign.analysis.linearity.form import device_form as linearity_form
from hapticdesign.devices.loading import load_device
from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.impedance import impedance_range
from hapticdesign.simulation.transparency import transparency
from hapticdesign.version import __version__

__all__ = [
    "__version__",
    "Device",
    "UserError",
    "coriolis_centrifugal",
    "coriolis_matrix",
    "dynamics_of",
    "forward_dynamics",
    "gravity",
    "impedance_range",
    "inverse_dynamics",
    "linear_conditions",
    "linearity_form",
    "load_device",
    "mass_matrix",
    "preset",
    "transparency",
]
