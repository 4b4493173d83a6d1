"""The numba evaluator of the coefficient tables against DynamicsModel.H/C/G."""

import numpy as np
import pytest

from hapticdesign.analysis.dynamics.device import coriolis_centrifugal, gravity, mass_matrix
from hapticdesign.devices.registry import preset
from hapticdesign.simulation.tables import DynamicsTables, evaluate_entries, unpack_entries, workspace_size


def _numba_terms(tables, q):
    n = tables.n_dof
    values = np.zeros((n, workspace_size(tables)))
    entries, phi = np.zeros(tables.n_entries), np.zeros(tables.index.shape[0])
    evaluate_entries(q, *tables.sparse, tables.index, tables.kinds, tables.degrees, values, phi, entries)
    h, c, g = np.zeros((n, n)), np.zeros((n, n * (n + 1) // 2)), np.zeros(n)
    unpack_entries(entries, n, h, c, g)
    return h, c, g


@pytest.mark.parametrize("overrides", [{}, {"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05, "Ixz3": 1e-3, "r2az": 0.02}])
def test_numba_terms_match_dynamics_model(overrides):
    device = preset("phantom-3dof").with_params(overrides)
    tables = DynamicsTables.from_device(device)
    rng = np.random.default_rng(4)
    for q in rng.uniform(-np.pi, np.pi, (6, 3)):
        h, c, g = _numba_terms(tables, q)
        scale = np.abs(mass_matrix(device, q)).max()
        assert np.allclose(h, mass_matrix(device, q), rtol=0, atol=1e-13 * scale)
        assert np.allclose(c, coriolis_centrifugal(device, q), rtol=0, atol=1e-13 * scale)
        assert np.allclose(g, gravity(device, q), rtol=0, atol=1e-12 * max(np.abs(gravity(device, q)).max(), 1.0))


def test_constant_inertia_table_is_a_pure_inertia():
    h, c, g = _numba_terms(DynamicsTables.constant_inertia(0.02), np.array([1.3]))
    assert h[0, 0] == 0.02 and c[0, 0] == 0.0 and g[0] == 0.0
