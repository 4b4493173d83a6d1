"""Design indices that run the sampled loop itself, registered in the one registry of design indices
(:mod:`hapticdesign.analysis.metrics.indices`) as any package's are: this module is named by the package's own
``hapticdesign.indices`` entry point (``simulation``), and the registry imports it the first time an index it does
not hold is asked for.

``kmax_simulated`` (N/m) is the wall a device renders with what real devices have and the linear loop leaves out
(issue 35; seed 000 ch. 4): at each pose, along the worst direction of the exact limit (``kmax``, the same loop
settings, ``wall_damping`` the simulated wall's damper on the sampled velocity), the spring at which the simulated
loop's oscillation starts to grow with the device's dry friction and
its encoders' quantization in it (:func:`~hapticdesign.simulation.impedance.simulated_limit`, the wall resting
:data:`~hapticdesign.simulation.impedance.TOUCH` from the pose), the ``simulated`` row of the spec sheet at any
pose. With ``hand`` a study can ask for a 1000-N/m wall under a hand, with friction. Each value is a bisection of
2-s runs (about a second of CPU per pose on the example devices), so it counts as :data:`COST` ordinary evaluations
in a study's workload limit; where the loop is linear (``friction`` and ``quantization`` off) it is ``kmax`` to the
bisection's tolerance (the tests check it).
"""

from __future__ import annotations

import numpy as np

from hapticdesign.analysis.metrics.indices import HandleStates, index
from hapticdesign.analysis.stiffness.drive import compliances
from hapticdesign.analysis.wall_stiffness import KMAX_OPTIONS, kmax_loop, worst_direction
from hapticdesign.errors import UserError
from hapticdesign.simulation.impedance import SIMULATED_CAP, TOUCH, device_counts, simulated_limit

COST = 1000.0
"""Ordinary evaluations one pose of ``kmax_simulated`` counts as (a bisection of loop runs)."""


@index(unit="N/m", formula="simulated growth boundary of the sampled wall with dry friction and encoder quantization "
       "along kmax's worst direction", source="seed 000 ch. 4; hapticdesign.simulation.impedance.simulated_limit",
       needs=("device",), cost=COST)
def kmax_simulated(pose: HandleStates, period: float = 0.001, delay: int = 1, velocity: str = "difference",
                   compensation: str = "gravity", error_percent: float = 0.0, hand: object = None,
                   friction: bool = True, quantization: bool = True, rel_tol: float = 1e-2,
                   wall_damping: float = 0.0) -> np.ndarray:
    for name, value in (("friction", friction), ("quantization", quantization)):
        if not isinstance(value, bool):
            raise UserError(f"index kmax_simulated: {name} is true or false, got {value!r}")
    if isinstance(rel_tol, bool) or not isinstance(rel_tol, (int, float)) or not 1e-4 <= rel_tol <= 0.5:
        raise UserError(f"index kmax_simulated: rel_tol is a number from 1e-4 to 0.5, got {rel_tol!r}")
    options = {**KMAX_OPTIONS, "period": period, "delay": delay, "velocity": velocity, "compensation": compensation,
               "error_percent": error_percent, "hand": hand, "wall_damping": wall_damping}
    loop, _ = kmax_loop(options)
    device = pose.device
    if compliances(device) != "rigid":
        raise UserError("index kmax_simulated: the simulated loop's plant is rigid; a device whose actuators state a "
                        "transmission_stiffness or whose links are elastic has the exact limit kmax, which models it")
    counts = device_counts(device) if quantization else None
    model = None if error_percent == 0 else pose.compensator(error_percent)
    out = np.empty(len(pose.full))
    for k in range(len(pose.full)):
        exact, direction, _ = worst_direction(pose.J_v[k], pose.H[k], pose.B[k], loop, pose.gravity[k],
                                              None if model is None else (model[0][k], model[1][k]))
        out[k] = simulated_limit(device, loop, direction=direction, equilibrium=TOUCH, counts=counts,
                                 rel_tol=float(rel_tol), start=max(exact, 1.0), k_limit=SIMULATED_CAP,
                                 friction=friction, pose=pose.q[k])
    return out
