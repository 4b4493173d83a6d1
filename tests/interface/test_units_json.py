"""JSON outputs carry units, and round-off is not printed as data.

Oracles: SI units of the seed's quantities (rad, m, kg; K_C in N/m, N/rad and N m/rad blocks, seed 001 eq. 6.54);
the R-CUBE's K_C at its symmetric home has exact zeros off its x-rz, y-rx, z-ry couplings (the three chains are
the same chain turned about the diagonal), so every printed entry is 0 or within 1e-12 of the largest's scale.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.interface.cli import app
from hapticdesign.simulation.figures import colour_scale

runner = CliRunner()


def _json(*args: str) -> dict:
    done = runner.invoke(app, [*args, "--json"])
    assert done.exit_code == 0, done.output
    return json.loads(done.stdout)


def test_rcube_stiffness_has_units_and_no_round_off():
    out = _json("rcube", "stiffness")
    k = np.array(out["K_C"])
    largest = np.abs(k).max()
    assert np.all((k == 0) | (np.abs(k) >= 1e-12 * largest))
    assert np.count_nonzero(k) == 12 and np.allclose(k, k.T, rtol=1e-12, atol=0)
    assert set(out["units"]) >= {"position", "K_C"} and "N m/rad" in out["units"]["K_C"]


@pytest.mark.parametrize("command, keys", [
    (["rcube", "ik", "--position", "0.1117,0.1117,0.1117"], {"q": "rad"}),
    (["rcube", "mass"], {"position": "m", "M_C": "kg", "link_mass": "kg"}),
    (["stability-boundary", "--inertia", "0.04", "--damping", "0.5", "--period", "0.001", "--samples", "40",
      "--substeps", "1"], {"k_max_exact": "N m/rad", "two_b_over_t": "N m/rad"}),
])
def test_json_has_units(command, keys):
    out = _json(*command)
    assert {k: out["units"][k] for k in keys} == keys


def test_a_constant_map_has_one_tick_not_a_round_off_scale():
    constant = 2.5 * (1 + 1e-15 * np.arange(6.0).reshape(2, 3))
    lo, hi, ticks = colour_scale(constant)
    assert ticks == [pytest.approx(2.5, rel=1e-14)] and lo < 2.5 < hi and hi - lo == pytest.approx(5e-3)
    varied = np.array([[1.0, 2.0], [3.0, np.nan]])
    assert colour_scale(varied) == (1.0, 3.0, None)
