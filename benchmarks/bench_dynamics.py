"""Equations-of-motion benchmarks (issue 2).

1. 6-DOF Phantom, from nothing to compiled numeric H, C, G with all 80 inertial parameters as
   inputs, in a fresh process with an empty numba cache (cold) and with a warm cache. Baseline
   in the same run: a plain SymPy Lagrangian build (kinetic energy of eq. 2.44, Hessian in the
   rates, Christoffel symbols) and its ``lambdify``, as the seed's Mathematica route does it.
2. 3-DOF Phantom: H, C, G evaluated for a batch of poses on one core (poses per second),
   next to ``lambdify`` of our exact symbolic equations evaluated on the same batch.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import textwrap
import time

ONE_CORE = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}

BUILD = textwrap.dedent(
    """
    import time
    t0 = time.perf_counter()
    import numpy as np
    from hapticdesign.analysis.dynamics.device import dynamics_of
    from hapticdesign.devices.registry import preset
    device = preset("{name}")
    model = dynamics_of(device)
    pi = device.standard_parameters()
    model.H(np.zeros(model.n_dof), pi); model.C(np.zeros(model.n_dof), pi); model.G(np.zeros(model.n_dof), pi)
    print(time.perf_counter() - t0)
    """
)

PLAIN_SYMPY = textwrap.dedent(
    """
    import time
    t0 = time.perf_counter()
    import sympy as sp
    from hapticdesign.devices.registry import preset
    device = preset("{name}")
    mech = device.mechanism
    comp = mech.compiled
    n = mech.n_dof
    q = sp.symbols(f"q1:{{n + 1}}")
    qd = sp.symbols(f"qd1:{{n + 1}}")
    def elementary(axis, v):
        c, s = sp.cos(v), sp.sin(v)
        if axis == 0: return sp.Matrix([[1,0,0,0],[0,c,-s,0],[0,s,c,0],[0,0,0,1]])
        if axis == 1: return sp.Matrix([[c,0,s,0],[0,1,0,0],[-s,0,c,0],[0,0,0,1]])
        if axis == 2: return sp.Matrix([[c,-s,0,0],[s,c,0,0],[0,0,1,0],[0,0,0,1]])
        t = sp.eye(4); t[axis - 3, 3] = v; return t
    poses = []
    for node in range(len(comp.node_parent)):
        v = sp.nsimplify(comp.node_offset[node], [sp.pi]) + sum(int(c) * q[k] for k, c in enumerate(comp.node_coef[node]) if c)
        parent = sp.eye(4) if comp.node_parent[node] < 0 else poses[comp.node_parent[node]]
        poses.append(parent * elementary(int(comp.node_axis[node]), v))
    kinetic, potential = 0, 0
    g = sp.Symbol("g")
    for b, body in enumerate(device.body_names):
        t = poses[comp.body_node[b]]
        R, p = t[:3, :3], t[:3, 3]
        m = sp.Symbol(f"m{{body}}"); r = sp.Matrix(sp.symbols(f"r{{body}}x r{{body}}y r{{body}}z"))
        xx, yy, zz, xy, xz, yz = sp.symbols(f"Ixx{{body}} Iyy{{body}} Izz{{body}} Ixy{{body}} Ixz{{body}} Iyz{{body}}")
        inertia = sp.Matrix([[xx, -xy, -xz], [-xy, yy, -yz], [-xz, -yz, zz]])
        com = p + R * r
        v = com.jacobian(q) * sp.Matrix(qd)
        Rdot = sum((R.diff(q[k]) * qd[k] for k in range(n)), sp.zeros(3, 3))
        w_skew = Rdot * R.T
        w = sp.Matrix([w_skew[2, 1], w_skew[0, 2], w_skew[1, 0]])
        kinetic += (m * v.dot(v) + (w.T * R * inertia * R.T * w)[0]) / 2
        potential += m * g * com[2]
    H = sp.hessian(kinetic, qd)
    G = sp.Matrix([potential.diff(qk) for qk in q])
    gamma = [[[(H[i, j].diff(q[k]) + H[i, k].diff(q[j]) - H[j, k].diff(q[i])) / 2 for k in range(n)] for j in range(n)] for i in range(n)]
    t_build = time.perf_counter() - t0
    symbols = sorted((H.free_symbols | G.free_symbols) - set(q), key=str)
    t1 = time.perf_counter()
    f = sp.lambdify([q, symbols], [H, G, gamma], "numpy")
    print(t_build, time.perf_counter() - t1)
    """
)

BATCH = textwrap.dedent(
    """
    import time
    import numpy as np
    import sympy as sp
    from hapticdesign.devices.registry import preset
    from hapticdesign.analysis.dynamics.symbolic import derive
    from hapticdesign.analysis.dynamics.device import dynamics_of
    device = preset("phantom-3dof")
    model = dynamics_of(device)
    pi = device.standard_parameters()
    rng = np.random.default_rng(0)
    qs = rng.uniform(-np.pi, np.pi, ({poses}, 3))
    model.entries(qs[:10], pi)
    best = 1e9
    for _ in range(5):
        t = time.perf_counter()
        model.entries(qs, pi)
        best = min(best, time.perf_counter() - t)
    eqs = derive(device, "none")
    f = sp.lambdify([eqs.theta], [*eqs.H, *eqs.C, *eqs.G], "numpy")
    th = [qs[:, 0], qs[:, 1], qs[:, 2]]
    t = time.perf_counter(); f(th); lam = time.perf_counter() - t
    print({poses} / best, {poses} / lam)
    """
)


def _run(code: str, env: dict | None = None, timeout: float | None = None) -> list[float]:
    full_env = {**os.environ, **(env or {})}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=full_env, timeout=timeout, check=True)
    return [float(x) for x in out.stdout.split()]


def main() -> None:
    with tempfile.TemporaryDirectory() as cache:
        cold = _run(BUILD.format(name="phantom-6dof"), {"NUMBA_CACHE_DIR": cache})[0]
        warm = _run(BUILD.format(name="phantom-6dof"), {"NUMBA_CACHE_DIR": cache})[0]
    print(f"6-DOF numeric H, C, G, all 80 inertial parameters as inputs: {cold:.2f} s cold (JIT), {warm:.2f} s warm cache (goal < 20 s)")
    t = time.perf_counter()
    _run("from hapticdesign.devices.registry import preset\nfrom hapticdesign.analysis.dynamics.symbolic import derive\nderive(preset('phantom-6dof'), 'all')")
    print(f"6-DOF exact symbolic H, C, G (all parameters symbolic), process included: {time.perf_counter() - t:.2f} s")
    for name, limit in (("phantom-3dof", 600), ("phantom-6dof", 900)):
        try:
            build, lam = _run(PLAIN_SYMPY.format(name=name), timeout=limit)
            print(f"baseline plain SymPy {name}: build {build:.1f} s, lambdify {lam:.1f} s")
        except subprocess.TimeoutExpired:
            print(f"baseline plain SymPy {name}: not finished within {limit} s")
    per_s, lam_per_s = _run(BATCH.format(poses=1_000_000), ONE_CORE)
    print(f"3-DOF H, C, G on one core: {per_s:,.0f} poses/s (goal >= 1e6); lambdify of the exact symbolic form: {lam_per_s:,.0f} poses/s")


if __name__ == "__main__":
    main()
