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
- :func:`optimize`: a study file's optimization (docs/optimization.md), answering the front as ``optimize --json``; its
  progress goes to stderr unless ``quiet=True``.
- :func:`index`: register your own design index (a decorator; docs/indices.md), usable in study files.
- :mod:`hapticdesign.analysis.rcube` and :mod:`hapticdesign.optimization`: the R-CUBE.
"""

from importlib import import_module

_HOMES = {
    "__version__": "hapticdesign.version",
    "coriolis_centrifugal": "hapticdesign.analysis.dynamics.device",
    "coriolis_matrix": "hapticdesign.analysis.dynamics.device",
    "dynamics_of": "hapticdesign.analysis.dynamics.device",
    "forward_dynamics": "hapticdesign.analysis.dynamics.device",
    "gravity": "hapticdesign.analysis.dynamics.device",
    "inverse_dynamics": "hapticdesign.analysis.dynamics.device",
    "mass_matrix": "hapticdesign.analysis.dynamics.device",
    "linear_conditions": "hapticdesign.analysis.linearity.conditions",
    "load_device": "hapticdesign.devices.loading",
    "preset": "hapticdesign.devices.registry",
    "optimize": "hapticdesign.interface.commands.optimize_adapter",
    "UserError": "hapticdesign.errors",
    "Device": "hapticdesign.model.device",
    "impedance_range": "hapticdesign.simulation.impedance",
    "index": "hapticdesign.analysis.metrics.indices",
    "transparency": "hapticdesign.simulation.transparency",
}
_RENAMED = {"linearity_form": ("hapticdesign.analysis.linearity.form", "device_form")}


def __getattr__(name: str):
    """The names below are imported on first use (PEP 562), so ``hapticdesign --help`` loads no solver."""
    if name in _HOMES:
        home, attribute = _HOMES[name], name
    elif name in _RENAMED:
        home, attribute = _RENAMED[name]
    else:
        raise AttributeError(f"module 'hapticdesign' has no attribute {name!r}")
    value = getattr(import_module(home), attribute)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)


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
    "index",
    "inverse_dynamics",
    "linear_conditions",
    "linearity_form",
    "load_device",
    "mass_matrix",
    "optimize",
    "preset",
    "transparency",
]
