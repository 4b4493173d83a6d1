"""A device's spec sheet: the quantities vendors print, computed from the device file at a pose.

With ``J_v`` the handle's translational Jacobian over the actuated coordinates (``J T`` with loops), ``H``
the mass matrix with the reflected rotor inertia, and the motors' transmission ``A`` (row k: the
combination ``a_k^T q`` motor k turns through ratio ``n_k``), one motor count, a motor torque and a motor's
friction reach the handle as follows:

- ``resolution`` (m): one count of motor k turns ``a_k^T q`` by ``Delta_k = 2 pi / (cpr_k quadrature_k n_k)``
  and moves the handle by ``J_v A^-1 e_k Delta_k``; the sheet gives the largest of these over k.
- ``force_continuous`` / ``force_peak`` (N): the radius of the largest ball inside the force polytope
  ``{F : |(A^-T J_v^T F)_k| <= n_k tau_k}`` (motor torques at their rating; gravity not included): the ``force``
  design index (:mod:`hapticdesign.analysis.metrics.indices`, option ``torque``). A device of fewer than three
  actuated coordinates is measured in the plane (or line) its handle moves in.
- ``apparent_mass`` (kg): the smallest and largest eigenvalue of ``(J_v H^-1 J_v^T)^+`` on that range (the largest
  is the ``apparent_mass`` design index).
- ``backdrive_friction`` (N): the motors' Coulomb friction ``f_k`` (on ``a_k^T q``) as a force at the handle:
  moving along a unit direction ``u`` at speed v dissipates ``sum_k f_k |a_k^T qd|`` with ``J_v qd = u v``,
  so the handle feels ``sum_k f_k |(A J_v^+ u)_k|``; its smallest and largest value over directions
  (exact, :func:`backdrive_friction`).
- ``stiffness`` (N/m): the ``stiffness`` design index, the smallest eigenvalue of the translational block of the VJM
  ``K_C`` on the directions the handle moves, where the file's links carry sections
  (:mod:`hapticdesign.analysis.stiffness.device`).
- ``workspace`` (mm): the edge of the largest cube (square for a planar device) centred on the home handle
  position that a study reaches as its workspace box (``box: {center: <the handle at home>, size: [edge, ...]}``
  on grid 3, its corners, edge midpoints and face centres, and on a study's default grid 5): every point reached
  by :func:`hapticdesign.analysis.workspace.reach_workspace`, the one meaning of "reached" (from the point before
  it, or else straight from home, without crossing a singularity, within the joint limits), found by bisection.
- ``renderable_stiffness`` (N/m), side by side, under one set of loop settings
  (:class:`~hapticdesign.analysis.sampled_loop.SampledLoop`, stated in the output; practice's by default: 1 kHz,
  one sample of delay, backward-difference velocity, gravity compensation):

  - ``exact``: the registry's ``kmax`` design index at the pose: the exact stability limit of the n-joint sampled
    loop, every joint free, H and B (the joint and motor viscous damping) at the pose, the smallest over the axes,
    the principal directions and 60 evenly spread directions (:mod:`hapticdesign.analysis.wall_stiffness`), and
    ``direction``, the worst one (:func:`~hapticdesign.analysis.wall_stiffness.worst_direction`), with the
    compliance between the motors and the handle the file gives (``compliance``: ``rigid``, ``transmissions``,
    ``links`` or both, :mod:`hapticdesign.analysis.stiffness.drive`; the simulated row, whose plant is rigid, is then
    not run). A pure spring uses the position only, so the velocity estimate does not enter. ``exact_lower``:
    the smallest spring stable in every direction, 0 unless gravity pulls the handle off a wall (an over-compensating
    model, an inverted pose); the sheet then says "stable from exact_lower to exact";
  - ``exact_with_hand``: ``kmax`` with the hand (``hand``: the default grasp,
    :data:`~hapticdesign.analysis.sampled_loop.GRASP`, unless the settings hold one) as a linear
    mass-spring-damper at the handle;
  - ``simulated``: the registry's ``kmax_simulated`` at the pose, the simulated growth boundary along the worst
    direction with the device's dry friction and its coarsest encoder's quantization (``simulated_counts`` per joint
    revolution), the wall's rest ``simulated_touch`` from the handle's start
    (:func:`hapticdesign.simulation.impedance.simulated_limit`);
  - the passivity bounds of Abbott & Okamura (2005) and Diolaiti et al. (2006): ``2 b / T`` (viscous) and
    ``2 f_c / Delta`` (Coulomb friction against encoder quantization), with the smallest damping (eigenvalue) and
    friction over directions and the resolution ``Delta``.

  The model's viscous damping alone is small on most devices, so ``exact`` is far below the walls vendors and
  CHAI3D render (Phantom Premium 1.5 800 N/m, Falcon 3000 N/m, Touch 400 N/m): the hand and the drives' dry
  friction dissipate the energy the sampled spring creates, which ``exact_with_hand`` and ``simulated`` show.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.dynamics.device import gravity_gradient
from hapticdesign.analysis.metrics import force as polytope
from hapticdesign.analysis.metrics.indices import INDICES, HandleStates, Index, Request, evaluate_at, requests_of
from hapticdesign.analysis.stiffness.drive import compliances
from hapticdesign.errors import UserError
from hapticdesign.model.actuators import transmission
from hapticdesign.model.device import Device
from hapticdesign.analysis.sampled_loop import GRASP, SampledLoop
from hapticdesign.analysis.wall_stiffness import worst_direction
from hapticdesign.analysis.workspace import cube_points, reach_workspace
from hapticdesign.simulation.config import loop_model

CUBE_SEARCH = (0.0, 0.4, 12)
"""Bisection of the workspace cube's half edge: lower and upper bound (m) and number of halvings."""
CUBE_GRIDS = (3, 5)
"""The grids (points per axis) of the study box the workspace cube is reached on: its corners, edge midpoints and
face centres (3) and a study's default grid (5)."""
Report = Callable[[str, int, int | None], None]
"""``progress(step, done, total)``: how far a long part of the sheet is (as the command line's progress bars take it)."""
CUBE_STEP = "workspace cube (bisection steps)"
RENDERING_STEP = "renderable stiffness (exact, with the hand, simulated)"


def no_progress(step: str, done: int, total: int | None) -> None:
    """A progress report that shows nothing."""


@dataclass(frozen=True)
class Handle:
    """The handle at one pose: its actuated coordinates, position, ``J_v``, the basis ``U`` of its range and the
    design indices' states there (one pose)."""

    q: np.ndarray
    position: np.ndarray
    jacobian: np.ndarray
    basis: np.ndarray
    states: HandleStates


def handle_at(device: Device, q) -> Handle:
    q = np.asarray(q, dtype=float)
    configuration = configuration_of(device)
    states = HandleStates(device, configuration.full(q)[None])
    jv = states.J_v[0]
    u, s = states.svd
    rank = int(np.sum(s[0] > 1e-9 * s[0, 0]))
    if rank < device.n_dof:
        raise UserError(f"the pose ({', '.join(f'{v:.6g}' for v in q)}) is singular: the handle's Jacobian has rank "
                        f"{rank} < {device.n_dof}")
    return Handle(q, configuration.pose(q)[:3, 3], jv, u[0], states)


def _index(name: str, h: Handle, **options) -> float:
    """The design index ``name`` at the handle's pose (:data:`~hapticdesign.analysis.metrics.indices.INDICES`)."""
    return float(INDICES[name].values(h.states, options)[0])


def resolution(device: Device, h: Handle) -> float | None:
    inv = polytope.motor_map(device)
    if inv is None or any(a.encoder_cpr is None for a in device.actuators):
        return None
    steps = [h.jacobian @ inv[:, k] / a.counts_per_radian for k, a in enumerate(device.actuators)]
    return float(max(np.linalg.norm(s) for s in steps))


def inscribed_force(device: Device, h: Handle, which: str) -> float | None:
    """Radius of the largest ball in the force polytope (the ``force`` index), None without the motors' limits."""
    if polytope.motor_map(device) is None or polytope.torque_limits(device, which) is None:
        return None
    return _index("force", h, torque=which)


def apparent_mass(device: Device, h: Handle) -> tuple[float, float]:
    """The smallest eigenvalue of the handle's Cartesian mass and the largest (the ``apparent_mass`` index)."""
    return float(h.states.cartesian_mass[0].min()), _index("apparent_mass", h)


def backdrive_friction(device: Device, h: Handle) -> tuple[float, float] | None:
    """Smallest and largest ``||C u||_1`` over unit u, ``C = diag(f) A J_v^+ U`` (square when the motors are one
    per coordinate): the smallest is ``min_k 1 / |C^-1 e_k|`` (the vertices of ``{u : ||C u||_1 <= 1}``), the
    largest ``max_s |C^T s|`` over sign vectors s."""
    if not device.actuators or not any(a.coulomb for a in device.actuators):
        return None
    a = transmission(device.actuators, device.n_dof)
    c = np.array([x.coulomb for x in device.actuators])[:, None] * (a @ np.linalg.pinv(h.jacobian) @ h.basis)
    if c.shape[0] != c.shape[1]:
        return None
    inv = np.linalg.inv(c)
    signs = np.array(list(np.ndindex(*(2,) * c.shape[0]))) * 2.0 - 1.0
    return float(1.0 / np.linalg.norm(inv, axis=0).max()), float(np.linalg.norm(signs @ c, axis=1).max())


def _kmax_options(loop: SampledLoop) -> dict:
    """The loop settings ``loop`` as options of the registry's ``kmax`` and ``kmax_simulated`` (their names are the
    :class:`SampledLoop`'s; a hand as its mass, damping and stiffness)."""
    hand = None if loop.hand is None else {k: v for k, v in loop.hand.as_dict().items() if k != "name"}
    return {"period": loop.period, "delay": loop.delay, "velocity": loop.velocity, "compensation": loop.compensation,
            "error_percent": loop.error_percent, "wall_damping": loop.wall_damping, "hand": hand}


def renderable(device: Device, h: Handle, loop: SampledLoop, res: float | None,
               friction: tuple[float, float] | None, simulate: bool = True, progress: Report = no_progress) -> dict:
    """The renderable-stiffness rows: the exact limit without the hand and with it (the registry's ``kmax``) and the
    direction it is taken along, the simulated limit along that direction with the device's dry friction and
    encoder quantization (the registry's ``kmax_simulated``), and the passivity bounds from the sheet's resolution
    ``res`` and backdrive ``friction`` (see the module docstring); ``progress`` hears of each of the three
    (:data:`RENDERING_STEP`)."""
    from hapticdesign.simulation.impedance import TOUCH, device_counts

    progress(RENDERING_STEP, 0, 3)
    bare = replace(loop, hand=None)
    exact = _index("kmax", h, **_kmax_options(bare))
    _, direction, lower = worst_direction(h.jacobian, h.states.H[0], device.damping_matrix, bare,
                                          gravity_gradient(device, h.q), loop_model(device, loop, h.q),
                                          h.states.drive)
    progress(RENDERING_STEP, 1, 3)
    hand = loop.hand or GRASP
    with_hand = _index("kmax", h, **_kmax_options(replace(loop, hand=hand)))
    progress(RENDERING_STEP, 2, 3)
    simulated = None
    if simulate and h.states.drive is None:  # the simulated loop's plant is rigid
        simulated = _index("kmax_simulated", h, **_kmax_options(bare))
    progress(RENDERING_STEP, 3, 3)
    return {
        "exact": exact, "exact_lower": lower, "direction": direction, "compliance": compliances(device),
        "exact_with_hand": with_hand, "hand": hand.as_dict(),
        "simulated": simulated, "simulated_counts": device_counts(device), "simulated_touch": TOUCH,
        "passivity_viscous": 2.0 * float(np.linalg.eigvalsh(h.states.cartesian_damping[0]).min()) * loop.rate,
        "passivity_coulomb": None if friction is None or res is None else 2.0 * friction[0] / res,
        "settings": bare.as_dict(), "rate": loop.rate, "delay": loop.delay,
    }


def workspace_cube(device: Device, h: Handle, progress: Report = no_progress) -> float:
    """Edge (m) of the largest cube (square for a planar device) centred on the handle's position whose study box is
    reached: its points on each grid of :data:`CUBE_GRIDS` (:func:`~hapticdesign.analysis.workspace.cube_points`),
    reached by :func:`~hapticdesign.analysis.workspace.reach_workspace` from the sheet's pose (home by default, as a
    study reaches its box), found by bisection; ``progress`` hears of each bisection step (:data:`CUBE_STEP`)."""

    def reaches(half: float) -> bool:
        for grid in CUBE_GRIDS:
            try:
                reach_workspace(device, cube_points(h.position, h.basis, 2 * half, grid), start=h.q)
            except UserError:
                return False
        return True

    lo, hi, halvings = CUBE_SEARCH
    progress(CUBE_STEP, 0, halvings + 1)
    if reaches(hi):
        progress(CUBE_STEP, halvings + 1, halvings + 1)
        return 2 * hi
    for k in range(halvings):
        progress(CUBE_STEP, k + 1, halvings + 1)
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if reaches(mid) else (lo, mid)
    progress(CUBE_STEP, halvings + 1, halvings + 1)
    return 2 * lo


def spec_sheet(device: Device, q=None, loop: SampledLoop | None = None, workspace: bool = True,
               simulate: bool = True, indices: Sequence[str | Request] = (),
               registry: Mapping[str, Index] = INDICES, progress: Report = no_progress) -> dict:
    """Every quantity of the module docstring at pose ``q`` (default: home), as a JSON-ready dict; the renderable
    stiffness under the loop settings ``loop`` (default: practice's, :class:`SampledLoop`), its simulated limit
    only with ``simulate``; and, as ``indices`` (name -> value, its unit in ``units``), the design ``indices`` of
    ``registry`` at the pose (a user's own among them, docs/indices.md); ``progress(step, done, total)`` hears how far
    the long parts are (the workspace cube's bisection, the renderable stiffness)."""
    from hapticdesign.studies.spec_page import check_reference

    if device.reference:
        check_reference(device.reference)  # refused before the work
    loop = loop or SampledLoop()
    q = configuration_of(device).home.copy() if q is None else np.asarray(q, dtype=float)
    h = handle_at(device, q)
    res = resolution(device, h)
    friction = backdrive_friction(device, h)
    mass = apparent_mass(device, h)
    sheet = {
        "device": device.name, **({"reference": device.reference} if device.reference else {}),
        "q": q, "handle": h.position, "dimensions": h.basis.shape[1],
        "resolution": res,
        "force_continuous": inscribed_force(device, h, "continuous"),
        "force_peak": inscribed_force(device, h, "peak"),
        "apparent_mass": {"min": mass[0], "max": mass[1]},
        "backdrive_friction": None if friction is None else {"min": friction[0], "max": friction[1]},
        "stiffness": _stiffness(device, h),
        "workspace": {"cube": 1000.0 * workspace_cube(device, h, progress)} if workspace else None,
        "renderable_stiffness": renderable(device, h, loop, res, friction, simulate, progress),
        "units": {"resolution": "m", "force_continuous": "N", "force_peak": "N", "apparent_mass": "kg",
                  "backdrive_friction": "N", "stiffness": "N/m", "workspace": "mm", "renderable_stiffness": "N/m",
                  "rate": "Hz", "handle": "m", "q": "rad or m"},
    }
    if indices:
        checked = requests_of(indices, registry)
        found = evaluate_at(device, configuration_of(device).full(q)[None], checked, registry=registry).values
        sheet["indices"] = {key: float(value[0]) for key, value in found.items()}
        sheet["units"]["indices"] = {r.key: registry[r.index].unit for r in checked}
    return sheet


SUMMARY = (
    ("force_continuous", "continuous force (largest ball in the force polytope)", "N"),
    ("force_peak", "peak force (largest ball in the force polytope)", "N"),
    ("resolution", "resolution (one motor count at the handle, the largest)", "m"),
    ("apparent_mass.min", "apparent mass, lightest direction", "kg"),
    ("apparent_mass.max", "apparent mass, heaviest direction", "kg"),
    ("renderable_stiffness.exact", "renderable wall, exact limit (worst direction)", "N/m"),
    ("renderable_stiffness.exact_with_hand", "renderable wall with the hand, exact limit", "N/m"),
)
"""The spec sheet's headline numbers (:func:`spec_summary`): the name as a path into ``spec.json`` (``a.b`` is
``sheet["a"]["b"]``), what it is, its unit."""


def spec_summary(device: Device, q=None, loop: SampledLoop | None = None) -> list[dict]:
    """The :data:`SUMMARY` rows of :func:`spec_sheet` at pose ``q`` (default: home) under ``loop`` (default: practice's,
    :class:`SampledLoop`), computed by the sheet's own functions (the force polytope, the resolution, the apparent mass,
    :func:`renderable` without its simulation) but without the workspace cube, the stiffness and the simulated limit,
    so that it costs a fraction of the sheet: ``[{"name", "label", "value", "unit"}]`` in SI units, None where the
    device file lacks what a row needs (motors' limits, encoders). A singular pose raises
    :class:`~hapticdesign.errors.UserError` as the sheet does."""
    loop = loop or SampledLoop()
    q = configuration_of(device).home.copy() if q is None else np.asarray(q, dtype=float)
    h = handle_at(device, q)
    res = resolution(device, h)
    mass = apparent_mass(device, h)
    wall = renderable(device, h, loop, res, backdrive_friction(device, h), simulate=False)
    values = {"force_continuous": inscribed_force(device, h, "continuous"),
              "force_peak": inscribed_force(device, h, "peak"), "resolution": res,
              "apparent_mass.min": mass[0], "apparent_mass.max": mass[1],
              "renderable_stiffness.exact": wall["exact"], "renderable_stiffness.exact_with_hand": wall["exact_with_hand"]}
    return [{"name": name, "label": label, "value": values[name], "unit": unit} for name, label, unit in SUMMARY]


def _stiffness(device: Device, h: Handle) -> float | None:
    """The ``stiffness`` index where the file's links or joints are elastic, else None."""
    elasticity = device.elasticity
    if elasticity is None or not (elasticity.links or elasticity.joints):
        return None
    return _index("stiffness", h)
