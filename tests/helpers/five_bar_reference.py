"""An independent 60-digit model of examples/devices/five-bar.yaml: the planar Lagrangian in mpmath.

The five-bar moves in a vertical plane (the file's ``plane`` frame: x along base x, y up). Each body's mass
centre ``O + R(angle) (rx, ry)`` and angle come from the four joint angles; only ``Izz`` (about the mass centre)
enters a planar motion, and gravity pulls along -y. The passive angles ``p1, p2`` close the loop (the two tips
meet in the plane) and are found by mpmath's Newton at 60 digits from a nearby guess. The reduced mass matrix is
``H_ij = sum m dc/dq_i . dc/dq_j + Izz da/dq_i da/dq_j`` with the derivatives of the closed poses taken by
central differences at 1e-30; G is the derivative of the potential; C follows from H by the Christoffel symbols
of seed 000 eq. 2.50-2.52. Shares no code with the package.
"""

from __future__ import annotations

import mpmath as mp

D, L1, L2, GRAVITY = "0.08", "0.10", "0.14", "9.81"
BODIES = {  # m, rx, ry, Izz about the mass centre; body h sits at the tip of the left distal link
    "1": ("0.060", "0.050", "0", "5.5e-5"),
    "2": ("0.060", "0.050", "0", "5.5e-5"),
    "3": ("0.040", "0.070", "0.002", "7.0e-5"),
    "4": ("0.035", "0.065", "0", "6.0e-5"),
    "h": ("0.020", "0", "0", "1.0e-6"),
}


class FiveBar:
    """The reference at actuated angles ``q_a`` on the branch of ``passive_guess`` (the passive angles there)."""

    def __init__(self, q_a, passive_guess, digits: int = 60):
        mp.mp.dps = digits
        self.d, self.l1, self.l2, self.g = (mp.mpf(v) for v in (D, L1, L2, GRAVITY))
        self.bodies = {k: tuple(mp.mpf(v) for v in row) for k, row in BODIES.items()}
        self.q_a = [mp.mpf(float(v)) for v in q_a]
        self.guess = [mp.mpf(float(v)) for v in passive_guess]

    def _elbows(self, q1, q2):
        return ((-self.d / 2 + self.l1 * mp.cos(q1), self.l1 * mp.sin(q1)),
                (self.d / 2 + self.l1 * mp.cos(q2), self.l1 * mp.sin(q2)))

    def _closure(self, q1, q2, p1, p2):
        e1, e2 = self._elbows(q1, q2)
        return [e1[0] + self.l2 * mp.cos(q1 + p1) - e2[0] - self.l2 * mp.cos(q2 + p2),
                e1[1] + self.l2 * mp.sin(q1 + p1) - e2[1] - self.l2 * mp.sin(q2 + p2)]

    def passive(self, q_a) -> list:
        tol = mp.mpf(10) ** (-(2 * mp.mp.dps) + 20)
        return list(mp.findroot(lambda p1, p2: self._closure(q_a[0], q_a[1], p1, p2), self.guess, tol=tol))

    def _centres(self, q_a) -> dict:
        q1, q2 = q_a
        p1, p2 = self.passive(q_a)
        e1, e2 = self._elbows(q1, q2)
        tip = (e1[0] + self.l2 * mp.cos(q1 + p1), e1[1] + self.l2 * mp.sin(q1 + p1))
        frames = {"1": (-self.d / 2, 0, q1), "2": (self.d / 2, 0, q2), "3": (*e1, q1 + p1), "4": (*e2, q2 + p2),
                  "h": (*tip, q1 + p1)}
        out = {}
        for name, (x, y, a) in frames.items():
            _, rx, ry, _ = self.bodies[name]
            out[name] = (x + mp.cos(a) * rx - mp.sin(a) * ry, y + mp.sin(a) * rx + mp.cos(a) * ry, a)
        return out

    def H(self, q_a=None) -> mp.matrix:
        q_a = self.q_a if q_a is None else q_a
        step = mp.mpf(10) ** -30
        rates = []
        for i in range(2):
            hi, lo = list(q_a), list(q_a)
            hi[i] += step
            lo[i] -= step
            a, b = self._centres(hi), self._centres(lo)
            rates.append({k: [(a[k][c] - b[k][c]) / (2 * step) for c in range(3)] for k in a})
        h = mp.matrix(2, 2)
        for name, (m, _, _, izz) in self.bodies.items():
            for i in range(2):
                for j in range(2):
                    u, v = rates[i][name], rates[j][name]
                    h[i, j] += m * (u[0] * v[0] + u[1] * v[1]) + izz * u[2] * v[2]
        return h

    def G(self) -> list:
        def potential(q_a):
            centres = self._centres(q_a)
            return sum(self.bodies[k][0] * self.g * centres[k][1] for k in centres)

        step = mp.mpf(10) ** -30
        out = []
        for i in range(2):
            hi, lo = list(self.q_a), list(self.q_a)
            hi[i] += step
            lo[i] -= step
            out.append((potential(hi) - potential(lo)) / (2 * step))
        return out

    def C(self) -> list:
        """Columns (1,1), (1,2), (2,2): ``Gamma_ijk`` for j = k, ``2 Gamma_ijk`` for j < k (eq. 2.50)."""
        step = mp.mpf(10) ** -15
        dH = [[[None, None] for _ in range(2)] for _ in range(2)]
        for k in range(2):
            hi, lo = list(self.q_a), list(self.q_a)
            hi[k] += step
            lo[k] -= step
            a, b = self.H(hi), self.H(lo)
            for i in range(2):
                for j in range(2):
                    dH[i][j][k] = (a[i, j] - b[i, j]) / (2 * step)

        def gamma(i, j, k):
            return (dH[i][j][k] + dH[i][k][j] - dH[j][k][i]) / 2

        return [[gamma(i, 0, 0), 2 * gamma(i, 0, 1), gamma(i, 1, 1)] for i in range(2)]
