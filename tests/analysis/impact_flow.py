"""An independent rigid-stop simulator for the closed-form checks: scipy's DOP853 between impacts, exact events on every
stop's gap, Newton's restitution along the stop's normal (impulse P = m_eff (1 + R) n . x'(t-), x'+ = x'- - P M^-1 n).

It shares nothing with the closed forms but the problem's matrices, normals and load (``ImpactProblem.first_order``):
no Green function, no receptance, no saltation matrix.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from vibroimpact.model.problem import ImpactProblem


@dataclass(frozen=True)
class Impact:
    """One impact: time [s], stop index, approach speed n . x'(t-) [m/s], impulse [N s], velocities before/after."""

    time: float
    stop: int
    speed: float
    impulse: float
    before: np.ndarray
    after: np.ndarray


class ImpactFlow:
    """DOP853 (rtol 1e-13) with terminal events on every gap Delta_k - n_k . x, for a problem with rigid stops."""

    def __init__(self, problem: ImpactProblem, rtol: float = 1e-13) -> None:
        self.problem = problem
        self.a, self.b, self.b0 = problem.first_order()
        self.normals = problem.normals()
        self.clearances = problem.clearances()
        mass = problem.structure.mass_matrix
        self.minv = np.linalg.inv(mass)
        self.meff = np.array([1.0 / (n @ self.minv @ n) for n in self.normals])
        self.restitution = np.array([stop.law.restitution for stop in problem.stops])
        self.size = problem.size
        self.omega = problem.omega
        self.rtol = rtol

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        return self.a @ y + (self.b * np.exp(1j * self.omega * t)).real + self.b0

    def gaps(self, y: np.ndarray) -> np.ndarray:
        return self.clearances - self.normals @ y[: self.size]

    def run(self, y: np.ndarray, t0: float, t1: float, max_impacts: int = 100_000) -> tuple[np.ndarray, list[Impact]]:
        """State at t1 and the impacts on the way."""
        events = []
        for k in range(len(self.normals)):

            def gap(t: float, state: np.ndarray, k: int = k) -> float:
                return self.clearances[k] - self.normals[k] @ state[: self.size]

            gap.terminal, gap.direction = True, -1.0
            events.append(gap)
        impacts: list[Impact] = []
        t, state = float(t0), np.array(y, dtype=float)
        while len(impacts) < max_impacts:
            run = solve_ivp(self.rhs, (t, t1), state, method="DOP853", rtol=self.rtol, atol=1e-18, events=events)
            if run.status != 1:
                return run.y[:, -1], impacts
            hits = [(float(te[0]), k) for k, te in enumerate(run.t_events) if te.size]
            t, k = min(hits)
            state = run.y_events[k][0].copy()
            n = self.normals[k]
            speed = float(n @ state[self.size :])
            if speed <= 0.0:  # the event fired at a separating touch: step on
                state = state.copy()
                continue
            impulse = self.meff[k] * (1.0 + self.restitution[k]) * speed
            before = state[self.size :].copy()
            state[self.size :] -= impulse * (self.minv @ n)
            impacts.append(Impact(t, k, speed, impulse, before, state[self.size :].copy()))
        raise RuntimeError("too many impacts (chattering?)")
