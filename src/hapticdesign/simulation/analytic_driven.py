"""Type 2 without simulating: the wall joint's sampled loop along the driven motion (seed 000 §4.1.3, Table 4.3).

In type 2 the other joints follow ``0.52 sin(3 pi t)``, so the wall joint ``w`` sees an inertia, a
Coriolis coupling and a torque that change along the motion. Linearized in ``delta = q_w - q_w0``
about the reference ``q_ref(t)`` (wall joint at its start, the others on their paths) its equation
(seed eq. 2.50 with joint damping ``b``) is the linear time-varying system

    J(t) delta'' + (b + gamma(t)) delta' + kappa(t) delta + rho(t) = u,

with ``J = H_ww(q_ref)``, ``rho`` the inverse dynamics of row w at ``(q_ref, qd_ref, qdd_ref)`` (the
driven joints' reaction, Coriolis and gravity torques), ``gamma = 2 sum_k Gamma_wwk qd_ref,k`` its
derivative in ``delta'`` (``= dJ/dt`` for a cyclic wall joint) and ``kappa`` its derivative in ``q_w``.
For a cyclic wall joint (joint 1 of the Phantom: H, C, G do not depend on it, ``kappa = 0``) the
equation is not an approximation: the wall joint's dynamics are exactly linear in ``delta``.

The digital side is linearized the same way: the compensator's row w at the sensed state is
``rho_m + kappa_m delta + gamma_m delta' + s_H J_m a_w`` (its own model, switches and errors), the
sampled acceleration ``a_w`` is the plant's just before the sample under the held torque (0 at t = 0),
the wall ``-K (delta - x_eq) - B delta'``; a delay of N samples reads sample ``k - N`` (the first
sample before that).

Over each plant step ``h`` the plant's transition on ``(delta, delta', u, 1)`` is the classical RK4
map of that linear equation (coefficients at ``t``, ``t + h/2``, ``t + h``: the integrator and stage
times of the simulation, :mod:`.kernel`); their products give the one-sample transitions
``(Phi_k, Gamma_k, e_k)`` and, with the digital side, one closed-loop map per sample,
``M_k(K) = M0_k + K M1_k``. The response is the product of these maps over the run, checked at
every plant step; the seed's overshoot and settling criteria apply to it as to the simulation. Where
the motion is periodic (period ``2/3 s``; with ``T = 1 ms`` the maps repeat every 2000 samples,
three motion periods) the product over one period is the monodromy matrix, and its eigenvalues, the
Floquet multipliers, decide asymptotic stability (:meth:`DrivenLoop.floquet_radius`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hapticdesign.analysis.dynamics.device import dynamics_of
from hapticdesign.model.device import Device
from hapticdesign.simulation.paths import Path, Sine
from hapticdesign.workload import require_memory

FD_STEP = 1e-6  # rad, central difference of the torques in q_w for a non-cyclic wall joint


@dataclass(frozen=True)
class RowTerms:
    """Row w of the equations along the reference at P times: ``J``, ``gamma``, ``kappa``, ``rho`` (P,)."""

    inertia: np.ndarray
    gamma: np.ndarray
    kappa: np.ndarray
    rho: np.ndarray


def reference(paths: dict[int, Path], start: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, ...]:
    """``q_ref, qd_ref, qdd_ref`` (P, N): the driven joints on their paths, the others at ``start``."""
    q = np.tile(np.asarray(start, dtype=float), (len(times), 1))
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    for j, path in paths.items():
        q[:, j], qd[:, j], qdd[:, j] = path.sample(times)
    return q, qd, qdd


def row_terms(device: Device, w: int, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
              switches: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> RowTerms:
    """Row w of ``s_H H qdd + s_C C qd^2 + s_G G`` linearized in ``q_w, qd_w`` about the reference
    (``qd_w = qdd_w = 0`` there); ``switches`` are the compensator's (all 1 for the plant)."""
    model, pi = dynamics_of(device), device.standard_parameters()
    s_h, s_c, s_g = switches

    n = model.n_dof
    packed = {pair: col for col, pair in enumerate(zip(*np.triu_indices(n)))}
    h_cols = [packed[min(w, j), max(w, j)] for j in range(n)]

    def terms(poses: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``H_w.``, ``Gamma_w..`` and the row's torque at the poses, from one evaluation of the entries."""
        entries = model.entries(poses, pi)
        h = entries[:, model.slice_h][:, h_cols]
        c = entries[:, model.slice_c].reshape(len(poses), n, len(model.pairs))[:, w]
        christoffel = np.zeros((len(poses), n, n))
        for col, (j, k) in enumerate(model.pairs):
            christoffel[:, j, k] += 0.5 * c[:, col]
            christoffel[:, k, j] += 0.5 * c[:, col]
        coriolis = np.einsum("pjk,pj,pk->p", christoffel, qd, qd)
        g = entries[:, model.slice_g][:, w]
        return h, christoffel, s_h * np.einsum("pj,pj->p", h, qdd) + s_c * coriolis + s_g * g

    h, christoffel, rho = terms(q)
    gamma = s_c * 2.0 * np.einsum("pk,pk->p", christoffel[:, w], qd)
    if model.cyclic[w]:
        kappa = np.zeros(len(q))
    else:
        up, down = q.copy(), q.copy()
        up[:, w] += FD_STEP
        down[:, w] -= FD_STEP
        kappa = (terms(up)[2] - terms(down)[2]) / (2.0 * FD_STEP)
    return RowTerms(h[:, w], gamma, kappa, rho)


def rk4_maps(plant: RowTerms, damping: float, step: float) -> np.ndarray:
    """RK4 maps (steps, 4, 4) of ``z = (delta, delta', u, 1)`` under a held u over each plant step;
    ``plant`` holds the coefficients at the half-step times ``0, h/2, h, ..., steps h``."""
    a = np.zeros((len(plant.inertia), 4, 4))
    a[:, 0, 1] = 1.0
    a[:, 1, 0] = -plant.kappa / plant.inertia
    a[:, 1, 1] = -(damping + plant.gamma) / plant.inertia
    a[:, 1, 2] = 1.0 / plant.inertia
    a[:, 1, 3] = -plant.rho / plant.inertia
    a0, am, a1 = a[0:-1:2], a[1::2], a[2::2]
    eye = np.eye(4)
    k1 = a0
    k2 = am @ (eye + 0.5 * step * k1)
    k3 = am @ (eye + 0.5 * step * k2)
    k4 = a1 @ (eye + step * k3)
    return eye + step / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def motion_period(paths: dict[int, Path]) -> float | None:
    """The common period of the driven motion (None unless every path is a sine with commensurate periods)."""
    periods = []
    for path in paths.values():
        if not isinstance(path, Sine):
            return None
        periods.append(2.0 * math.pi / abs(path.omega))
    base = periods[0]
    if any(abs(p / base - round(p / base)) > 1e-9 and abs(base / p - round(base / p)) > 1e-9 for p in periods):
        return None
    return max(periods)


@dataclass
class DrivenLoop:
    """The sampled closed loop of the wall joint along the driven motion, ``M_k(K) = M0_k + K M1_k`` on
    ``S = (delta, delta', u_prev, y_(k-1), ..., y_(k-N), 1)`` with ``y = (delta, delta', a_w)``."""

    constant: np.ndarray  # M0 (samples, n, n)
    gain: np.ndarray  # M1 (samples, n, n)
    torque: np.ndarray  # rows giving u_k from S_k: U0 (samples, n)
    torque_gain: np.ndarray  # U1 (samples, n)
    position: np.ndarray  # (samples, sub, 4): delta at each plant step from (delta, delta', u, 1) at the sample
    period_samples: int | None

    @classmethod
    def build(cls, device: Device, model: Device, w: int, paths: dict[int, Path], start: np.ndarray, damping: float,
              switches: tuple[float, float, float], period: float, sub: int, samples: int, delay: int,
              wall_damping: float, equilibrium: float) -> "DrivenLoop":
        step = period / sub
        n_dof, n = device.n_dof, 4 + 3 * delay
        entries = dynamics_of(device).coefficients.shape[1]
        require_memory(f"the time-varying type-2 loop of {samples * sub:,} plant steps",
                       8.0 * ((2 * samples * sub + 1) * (entries + 2 * n_dof * n_dof + 4 * n_dof + 16)
                              + samples * sub * 16 * 6 + samples * (2 * n * n + 2 * n)))
        half = np.arange(2 * samples * sub + 1) * (0.5 * step)
        plant = row_terms(device, w, *reference(paths, start, half))
        maps = rk4_maps(plant, damping, step).reshape(samples, sub, 4, 4)
        partial = np.empty((samples, sub + 1, 4, 4))
        partial[:, 0] = np.eye(4)
        for i in range(sub):
            partial[:, i + 1] = maps[:, i] @ partial[:, i]
        at_samples = np.arange(samples) * sub * 2
        comp = row_terms(model, w, *reference(paths, start, half[at_samples]), switches=switches)
        one, u_col = n - 1, 2
        # the acceleration sensed at sample k, a row over S_k (0 at k = 0)
        acc = np.zeros((samples, n))
        j_k, g_k, k_k, r_k = (x[at_samples] for x in (plant.inertia, plant.gamma, plant.kappa, plant.rho))
        acc[:, 0] = -k_k / j_k
        acc[:, 1] = -(damping + g_k) / j_k
        acc[:, u_col] = 1.0 / j_k
        acc[:, one] = -r_k / j_k
        acc[0] = 0.0
        sensed = np.zeros((samples, 3, n))  # y_(k-N) as rows over S_k
        if delay == 0:
            sensed[:, 0, 0] = sensed[:, 1, 1] = 1.0
            sensed[:, 2] = acc
        else:
            base = 3 + 3 * (delay - 1)
            for r in range(3):
                sensed[:, r, base + r] = 1.0
        lag = np.maximum(np.arange(samples) - delay, 0)
        law = np.stack([comp.kappa[lag], comp.gamma[lag] - wall_damping, switches[0] * comp.inertia[lag]], axis=1)
        u0 = np.einsum("kr,krn->kn", law, sensed)
        u0[:, one] += comp.rho[lag]
        u1 = -sensed[:, 0].copy()
        u1[:, one] += equilibrium
        m0, m1 = np.zeros((samples, n, n)), np.zeros((samples, n, n))
        full = partial[:, sub]
        for m, u, plain in ((m0, u0, True), (m1, u1, False)):
            m[:, :2] = full[:, :2, u_col, None] * u[:, None, :]
            m[:, u_col] = u
            if plain:
                m[:, :2, :2] += full[:, :2, :2]
                m[:, :2, one] += full[:, :2, 3]
                m[:, one, one] = 1.0
                if delay:
                    m[:, 3, 0] = m[:, 4, 1] = 1.0
                    m[:, 5] = acc
                    for slot in range(1, delay):
                        for r in range(3):
                            m[:, 3 + 3 * slot + r, 3 + 3 * (slot - 1) + r] = 1.0
        motion = motion_period(paths)
        ratio = None if motion is None else motion / period
        period_samples = None
        if ratio is not None:
            for cycles in range(1, 101):
                if abs(cycles * ratio - round(cycles * ratio)) < 1e-9 * cycles * ratio:
                    period_samples = int(round(cycles * ratio))
                    break
        return cls(m0, m1, u0, u1, partial[:, :sub, 0], period_samples)

    @property
    def samples(self) -> int:
        return self.constant.shape[0]

    def response(self, stiffness: float) -> np.ndarray:
        """``delta`` at every plant step (samples + 1 rows of ``sub`` columns, the last row's first entry the
        end of the run), from the product of the sample maps applied to the start (at rest, delta = 0)."""
        maps = self.constant + stiffness * self.gain
        rows = self.torque + stiffness * self.torque_gain
        n = maps.shape[1]
        states = np.empty((self.samples + 1, n))
        s = np.zeros(n)
        s[-1] = 1.0
        states[0] = s
        with np.errstate(over="ignore", invalid="ignore"):
            for k in range(self.samples):
                s = maps[k] @ s
                states[k + 1] = s
            u = np.einsum("kn,kn->k", rows, states[:-1])
            z = np.stack([states[:-1, 0], states[:-1, 1], u, np.ones(self.samples)], axis=1)
            inside = np.einsum("kjc,kc->kj", self.position, z)
        out = np.full((self.samples + 1, self.position.shape[1]), np.nan)
        out[:-1] = inside
        out[-1, 0] = states[-1, 0]
        return out

    def floquet_radius(self, stiffness: float, start: int = 1) -> float:
        """Largest Floquet multiplier of the homogeneous loop over one period of the sampled motion
        (from sample ``start``, past the delay line's start-up); ``nan`` when the motion is not periodic
        or the run is shorter than a period."""
        p = self.period_samples
        if p is None or start + p > self.samples:
            return math.nan
        maps = (self.constant + stiffness * self.gain)[start:start + p, :-1, :-1]
        monodromy = np.eye(maps.shape[1])
        with np.errstate(over="ignore", invalid="ignore"):
            for m in maps:
                monodromy = m @ monodromy
                scale = float(np.abs(monodromy).max())
                if not math.isfinite(scale):
                    return math.inf
        return float(np.max(np.abs(np.linalg.eigvals(monodromy))))

