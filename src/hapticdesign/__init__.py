"""hapticdesign: design kinesthetic haptic devices for high impedance performance.

The Python surface, in the order of the seeds (seed 000: Phantom, LN, rendering; seed 001:
R-CUBE):

- :func:`preset`, :class:`Device` (``Device.from_file``): devices and their parameters;
  ``device.H/C/C_cvt/G/inverse_dynamics/forward_dynamics`` and ``device.model`` (the regressor
  model, vectorized over poses and parameter sets).
- :func:`linearity_form` (LN as a quadratic form; ``form.ln``, ``form.parts``) and
  :func:`linear_conditions` (the linear equations of LN = 0).
- :func:`impedance_range`, :func:`transparency`: the sampled-data rendering criteria.
- :mod:`hapticdesign.analysis.rcube` and :mod:`hapticdesign.optimization`: the R-CUBE.
"""

from importlib.metadata import PackageNotFoundError, version

from hapticdesign.analysis.linearity.conditions import linear_conditions
from hapticdesign.analysis.linearity.service import device_form as linearity_form
from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device
from hapticdesign.simulation.impedance import impedance_range
from hapticdesign.simulation.transparency import transparency

try:
    __version__ = version("hapticdesign")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0+unknown"

__all__ = [
    "__version__",
    "Device",
    "UserError",
    "impedance_range",
    "linear_conditions",
    "linearity_form",
    "preset",
    "transparency",
]
