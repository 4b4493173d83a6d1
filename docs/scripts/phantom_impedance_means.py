"""Regenerates README.md's rendering rows for the Phantom (seed 000 Table 4.4, Fig. 4.11).

The maximum stable impedance of joint 1, types 1 and 2, for the 600 realizable designs of
``hapticdesign designs --levels 0,0.001,0.01,0.1,1,2 --count 100 --seed 1`` and for the seed's 30
printed Appendix C designs (link 1 as the built-in default), by the campaign's own case
(:func:`hapticdesign.simulation.campaign.run_case`) with the analytic method: for type 1 the loop
linearized at the start pose, for type 2 the linear time-varying loop along the driven motion, both
equal to the simulated verdicts (tests/simulation/test_sim_analytic.py, docs/simulation.md's type-2
agreement table). Prints, per LN level, the mean k_max of each type and the share of designs whose
types agree.

Run: ``.venv/bin/python docs/scripts/phantom_impedance_means.py`` (a few CPU minutes).
"""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from hapticdesign.errors import PhysicalConsistencyWarning
from hapticdesign.interface.commands.linearity_adapter import write_design_set
from hapticdesign.simulation.campaign import CampaignOptions, read_designs, run_case
from hapticdesign.studies.phantom import PhantomSettings
from hapticdesign.studies.phantom_rendering import _appendix_c_csv

LEVELS = "0,0.001,0.01,0.1,1,2"


def table(designs) -> list[tuple[float, float, float, float]]:
    options = CampaignOptions(method="analytic")
    rows = []
    for d in designs:
        k = [run_case("phantom-3dof", d.params, "impedance", t, options)["value"] for t in (1, 2)]
        rows.append((d.level, *k))
    out = []
    data = np.array(rows)
    for level in np.unique(data[:, 0]):
        r = data[data[:, 0] == level]
        out.append((level, r[:, 1].mean(), r[:, 2].mean(), float(np.mean(r[:, 1] == r[:, 2]))))
    return out


def main() -> None:
    warnings.simplefilter("ignore", PhysicalConsistencyWarning)
    with tempfile.TemporaryDirectory() as tmp:
        sets = Path(tmp) / "designs.csv"
        write_design_set("phantom-3dof", None, None, False, LEVELS, 100, 1, sets, "fast", "rigid-body")
        appendix = Path(tmp) / "appendix_c.csv"
        _appendix_c_csv(SimpleNamespace(settings=PhantomSettings()), appendix, 5)
        for name, path in (("600 realizable designs", sets), ("Appendix C, 30 designs", appendix)):
            print(f"{name}: LN, mean k_max type 1, type 2 [N m/rad], share type 1 = type 2")
            for level, t1, t2, same in table(read_designs(path)):
                print(f"  {level:g}: {t1:.2f}, {t2:.2f}, {100 * same:.0f} %")


if __name__ == "__main__":
    main()
