"""Linearity Number: batched LN per design (3 and 6 DOF), set-up, closed form, the 600-design set."""

from __future__ import annotations

import time

import numpy as np

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.analysis.dynamics.model import DynamicsModel
from hapticdesign.analysis.linearity.bounds import practical_bounds
from hapticdesign.analysis.linearity.closed_form import closed_form
from hapticdesign.analysis.linearity.conditions import linear_conditions
from hapticdesign.analysis.linearity.design_sets import design_set
from hapticdesign.analysis.linearity.form import linearity_form
from hapticdesign.devices.registry import preset


def _per_design(form, device, count: int = 20000) -> float:
    rng = np.random.default_rng(0)
    designs = np.tile(device.seed_parameters().ravel(), (count, 1)) * rng.uniform(0.5, 1.5, (count, form.n_params))
    form.ln_seed(designs[:10])
    start = time.perf_counter()
    form.ln_seed(designs)
    return (time.perf_counter() - start) / count


def main() -> None:
    for name in ("phantom-3dof", "phantom-6dof"):
        device = preset(name)
        start = time.perf_counter()
        model = DynamicsModel(device.mechanism)
        form = linearity_form(model)
        setup = time.perf_counter() - start
        print(f"{name}: set-up (model + LN form) {setup:.2f} s; LN per design (batch of 20000) "
              f"{1e6 * _per_design(form, device):.2f} us")
        start = time.perf_counter()
        closed = closed_form(device, form)
        build = time.perf_counter() - start
        start = time.perf_counter()
        closed.export("latex"), closed.export("python")
        print(f"{name}: closed-form LN from Q {build:.2f} s ({len(closed.terms())} terms); "
              f"LaTeX + Python export {time.perf_counter() - start:.2f} s")
    device = preset("phantom-3dof")
    form = linearity_form(dynamics_of(device))
    start = time.perf_counter()
    result = design_set(device, form, linear_conditions(device, form), practical_bounds(device), count=100, seed=1)
    print(f"phantom-3dof: 600-design set (6 levels x 100, fast method) {time.perf_counter() - start:.1f} s, "
          f"max relative level error {np.max(np.abs(result.ln[100:] / result.levels[100:] - 1)):.1e}")


if __name__ == "__main__":
    main()
