"""The wall-response figure of the rendering step simulates the searches' experiment on a closed loop.

Oracle: the five-bar file's ``home: {q1: 2.0, q2: 1.1}`` and the experiment of seed 000 Table 4.2-4.3 (type 1:
the wall joint starts at rest, the spring rests 0.01 rad from there, the other joint held); the stiffness is
half the 1-DOF limit ``b^2 / H_ww`` of full inertial compensation at home (seed 000 §4.1.2), so the wall settles.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.devices.device_file import load_device_file
from hapticdesign.simulation.criteria import Criteria
from hapticdesign.studies.phantom_rendering import wall_response

FIVE_BAR = Path(__file__).resolve().parents[2] / "examples" / "devices" / "five-bar.yaml"


def test_five_bar_wall_trace_starts_at_home_and_settles_at_home_plus_step():
    device = load_device_file(FIVE_BAR)
    home = np.array([2.0, 1.1])
    stiffness = 0.5 * device.damping[0] ** 2 / mass_matrix(device, home)[0, 0]
    trace = wall_response(device, stiffness)
    assert trace.status == 0
    assert trace.q[0, 0] == home[0]
    assert np.all(trace.q[:, 1] == home[1])
    tail = trace.q[trace.t >= trace.t[-1] - 0.5, 0]
    assert np.abs(tail - (home[0] + 0.01)).max() < Criteria().settle_tolerance
    assert np.abs(trace.q[:, 0] - home[0]).max() < 0.03
