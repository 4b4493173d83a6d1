"""Equations of motion of a closed-loop mechanism in its actuated coordinates (seed 000 eq. 2.44-2.52).

``tau_a = H_a(q_a) qdd_a + C_a(q_a) qd_a^2 + G_a(q_a)`` with ``H_a = T^T H T``, ``G_a = T^T G`` and
``C_a`` from ``T^T (H Tdot + C-terms T)`` (:mod:`.actuated_kernel`), where ``H, C, G`` are the
loop-opened tree's (the same kernel as every tree device) and ``T`` comes from the loop solver
(:mod:`hapticdesign.analysis.loops.solver`). Every entry stays linear in the standard inertial
parameters, so this model is an :class:`~.model.EquationsOfMotion` whose entries come from a regressor
evaluated pose by pose instead of an exact trigonometric basis (it is no :class:`~.model.ExactBasis`): H,
C (eq. 2.50's columns), C_cvt (eq. 2.52, from the Christoffel symbols of ``H_a``), G, inverse and forward
dynamics are inherited.

A batch of actuated poses is a motion (:meth:`~hapticdesign.analysis.loops.solver.LoopSolver.solve`): passive values
are continued along it from the home assembly.
"""

from __future__ import annotations

import copy

import numpy as np

from hapticdesign.analysis.dynamics.actuated_kernel import (
    Bodies,
    actuated_entries,
    actuated_regressor,
    motion_entries,
    passive_paths,
    pose_dynamics,
    terms_into,
)
from hapticdesign.analysis.configuration import Configuration
from hapticdesign.analysis.dynamics.model import EquationsOfMotion, pair_index
from hapticdesign.analysis.loops.closure_kernel import SINGULAR
from hapticdesign.analysis.loops.solver import MESSAGES, SINGULAR_RATIO
from hapticdesign.errors import UserError
from hapticdesign.model.walk import MotionPlan

CHUNK = 4096
"""Poses per kernel call when a regressor (E x n_params per pose) is returned."""


class ClosedLoopModel(EquationsOfMotion):
    """Regressor model of a closed-loop mechanism in its actuated coordinates (see module docstring)."""

    def __init__(self, configuration: Configuration):
        mechanism = configuration.mechanism
        self.configuration = configuration
        """The device's configuration space (:func:`~hapticdesign.analysis.configuration.configuration_of`)."""
        self.mechanism = mechanism
        self.compiled = mechanism.compiled
        self.solver = configuration.solver
        a, tree = self.solver.closures, self.compiled.tree
        ptr, nodes = passive_paths(tree.parent, self.solver.plan, tree.body_node, a.passive)
        self.bodies = Bodies(
            body_node=tree.body_node, gravity=self.compiled.gravity,
            motion=MotionPlan.of(tree, [*tree.body_node, *a.frame_a, *a.frame_b]), path_ptr=ptr, path_nodes=nodes,
        )
        """The kernels' bodies: their nodes, gravity, the nodes whose motions the velocity terms read (the
        bodies' and the closures') and per body the nodes on its path to the base the passive coordinates move."""
        self.n_dof = mechanism.n_actuated
        self.n_params = 10 * len(mechanism.bodies)
        self.pairs = pair_index(self.n_dof)
        n, m = self.n_dof, len(self.pairs)
        self.slice_h = slice(0, m)
        self.slice_c = slice(m, m + n * m)
        self.slice_g = slice(m + n * m, m + n * m + n)
        self.n_entries = m + n * m + n

    # -- kernel -------------------------------------------------------------------------------
    def _kernel(self, q_full: np.ndarray, params: np.ndarray | None) -> np.ndarray:
        """Entries for parameter sets (P, S, E), or the regressor (P, E, n_params) when ``params`` is None."""
        s, a = self.solver, self.solver.closures
        args = (np.ascontiguousarray(q_full, dtype=float), s.tree, s.plan, self.bodies, a)
        if params is None:
            out, ratios = actuated_regressor(*args)
        else:
            out, ratios = actuated_entries(*args, np.ascontiguousarray(params, dtype=float))
        self._check_ratios(q_full, ratios)
        return out

    def _check_ratios(self, q_full: np.ndarray, ratios: np.ndarray) -> None:
        """Refuse the poses where ``Phi_p`` is singular (pivot ratio at most the solver's)."""
        bad = np.flatnonzero(ratios <= SINGULAR_RATIO)
        if bad.size:
            pose = ", ".join(f"{v:.6g}" for v in q_full[bad[0], self.solver.closures.actuated])
            raise UserError(f"at q = ({pose}): {MESSAGES[SINGULAR]}")

    def full_coordinates(self, q: np.ndarray) -> np.ndarray:
        """Actuated poses (n_a,) or a motion (P, n_a) -> closed full coordinates (continued from home)."""
        out = self.configuration.full(self._poses(q))
        return out[0] if np.asarray(q).ndim == 1 else out

    def entries_at(self, q_full: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """Entries at closed full poses (P, N): (P, E), or (S, P, E) for parameter sets (S, n_params)."""
        pi = self._params(pi)
        sets = np.atleast_2d(pi)
        out = self._kernel(np.atleast_2d(q_full), sets)  # (P, S, E)
        if self.constant is not None:
            out += self.constant
        return out[:, 0, :] if pi.ndim == 1 else np.moveaxis(out, 1, 0)

    def entries(self, q: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """All entries (unique H, C, G) at actuated poses, a motion continued from home (as
        :meth:`full_coordinates`): (P, E) or (S, P, E) for parameter sets (S, n); one compiled pass that solves
        each pose and evaluates its entries (:func:`.actuated_kernel.motion_entries`). Where the continuation
        fails, the poses are closed by the solver, which tries other paths and says what failed
        (:meth:`~hapticdesign.analysis.loops.solver.LoopSolver.solve`), and the entries evaluated there."""
        pi = self._params(pi)
        path = np.ascontiguousarray(self._poses(q))
        s = self.solver
        out, status, first = motion_entries(path, s.home, s.branch, s.tree, s.plan, self.bodies, s.closures, s.settings,
                                            np.ascontiguousarray(np.atleast_2d(pi), dtype=float))
        if first >= 0:
            return self.entries_at(s.solve(path), pi)
        if self.constant is not None:
            out += self.constant
        return out[:, 0, :] if pi.ndim == 1 else np.moveaxis(out, 1, 0)

    def terms_at(self, q_full: np.ndarray, pi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """H_a (P, n_a, n_a) and G_a (P, n_a) at closed full poses (P, N) for one parameter set (n_params,): the
        numbers of :meth:`entries_at` without the velocity terms, from the kernel a design batch's ``H`` takes too
        (:func:`.actuated_kernel.terms_into`), which compiles in a fraction of the time of the whole entries."""
        pi = self._params(pi)
        if pi.ndim != 1:
            raise UserError(f"expected one set of {self.n_params} standard inertial parameters, got shape {pi.shape}")
        q_full = np.ascontiguousarray(np.atleast_2d(q_full), dtype=float)
        s, a = self.solver, self.solver.closures
        n_pose = len(q_full)
        h, g, ratios = np.zeros((n_pose, self.n_dof, self.n_dof)), np.zeros((n_pose, self.n_dof)), np.zeros(n_pose)
        terms_into(q_full, s.tree, s.plan, self.bodies, a, np.ascontiguousarray(pi[None]),
                   pose_dynamics(len(s.tree.parent), a, self.bodies, q_full.shape[1]), h, g, ratios)
        self._check_ratios(q_full, ratios)
        if self.constant is not None:
            h += self._h_from(self.constant)
        return h, g

    def H_at(self, q_full: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """H_a (eq. 2.50 in the actuated coordinates) at closed full poses (P, N): (P, n_a, n_a), or (S, P, n_a, n_a)
        for parameter sets (S, n_params)."""
        if np.ndim(pi) == 1:
            return self.terms_at(q_full, pi)[0]
        return self._h_from(self.entries_at(np.atleast_2d(q_full), pi))

    def H(self, q: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """H_a (eq. 2.50) at actuated poses as :meth:`entries` gives it; at one pose (n_a,) for one parameter set from
        :meth:`terms_at` at the pose continued from home (the pose and the numbers :meth:`entries` has there), so that
        a mass matrix compiles no velocity terms."""
        if np.ndim(q) == 1 and np.ndim(pi) == 1:
            return self.terms_at(self.full_coordinates(q), pi)[0][0]
        return super().H(q, pi)

    def G(self, q: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """G_a (eq. 2.50) at actuated poses, at one pose for one parameter set from :meth:`terms_at` (as :meth:`H`)."""
        if np.ndim(q) == 1 and np.ndim(pi) == 1:
            return self.terms_at(self.full_coordinates(q), pi)[1][0]
        return super().G(q, pi)

    def regressor_at(self, q_full: np.ndarray) -> np.ndarray:
        """Every entry as a row of the standard parameters at closed full poses: (P, E, n_params)."""
        q_full = np.atleast_2d(q_full)
        return np.concatenate([self._kernel(q_full[i:i + CHUNK], None)
                               for i in range(0, len(q_full), CHUNK)] or [np.zeros((0, self.n_entries, self.n_params))])

    def entry_regressor(self, q: np.ndarray) -> np.ndarray:
        return self.regressor_at(self.full_coordinates(q))

    def with_constant_inertia(self, h: np.ndarray) -> "ClosedLoopModel":
        """This model with a constant (N_a x N_a) matrix added to H_a (reflected rotor inertia of the motors)."""
        h = np.asarray(h, dtype=float)
        if h.shape != (self.n_dof, self.n_dof) or not np.allclose(h, h.T) or not np.all(np.isfinite(h)):
            raise UserError(f"a constant inertia must be a finite symmetric {self.n_dof} x {self.n_dof} matrix")
        out = copy.copy(self)
        constant = np.zeros(self.n_entries)
        iu, ju = np.triu_indices(self.n_dof)
        constant[self.slice_h] = h[iu, ju]
        out.constant = constant + (0.0 if self.constant is None else self.constant)
        return out
