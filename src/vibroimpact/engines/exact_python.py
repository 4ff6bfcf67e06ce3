"""Engine ``exact_python``: the ``exact`` engine's algorithm in pure Python (the compiled core, :mod:`.exact_core`, is
the same loop under numba; this copy cross-checks it and is the speed baseline of ``engine_cost``).

Between events the motion is linear with harmonic forcing, so it is propagated in closed form (eigenvectors of the
state matrix plus the harmonic particular solution, :mod:`.linear_flow`). Contacts are found by guaranteed root
bracketing (:func:`.linear_flow.first_crossing`): no contact is missed however tangent, and contact times are exact
to round-off. At a contact X2' -> -R X2'. When impacts accumulate (chattering, small R) and the stop pushes the
absorber, it sticks: X2 = Delta, X2' = 0, only the primary mass moves, until the holding force
B2 X1' + K2 (X1 - Delta) turns negative (found by the same root search).
"""

from __future__ import annotations

import math
import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.base import MODE_FREE, MODE_STUCK, Trajectory, TrajectoryBuilder
from vibroimpact.engines.linear_flow import HarmonicLinearFlow, Observable, Piece, escape_step, first_crossing, gauss_legendre
from vibroimpact.engines.rigid_contact import RigidContact
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.problem import ImpactProblem

__all__ = ["PythonExactEngine"]

_GAP = np.array([0.0, 1.0, 0.0, 0.0])


class PythonExactEngine:
    """The pure-Python exact engine (see module docstring): the compiled core's cross-check and speed baseline."""

    name = "exact_python"

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        self.settings = settings

    def integrate(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` (X1, X2, X1', X2') at ``t_start`` [s]."""
        run = _Run(RigidContact(self.name, problem, self.settings, periods), problem, TrajectoryBuilder(problem, moments))
        return run.go(np.asarray(state, dtype=float), float(t_start), int(periods))

    def dense(self, trajectory: Trajectory, times: NDArray[np.float64]) -> NDArray[np.float64]:
        """States at arbitrary ``times`` inside a trajectory, shape (n, 4), exact (from its segments)."""
        run = _Run(RigidContact(self.name, trajectory.problem, self.settings, 0), trajectory.problem, TrajectoryBuilder(trajectory.problem, False))
        times = np.asarray(times, dtype=float)
        index = np.clip(np.searchsorted(trajectory.segments[:, 0], times, side="right") - 1, 0, len(trajectory.segments) - 1)
        out = np.empty((times.size, 4))
        for i in np.unique(index):
            start, _end, mode = trajectory.segments[i]
            piece, _watch = run._piece(start, trajectory.segment_states[i], mode == MODE_STUCK)
            chosen = index == i
            out[chosen] = [run._state(piece, t, mode == MODE_STUCK) for t in times[chosen]]
        return out


class _Run:
    """One integration: the event loop of the exact engine."""

    def __init__(self, law: RigidContact, problem: ImpactProblem, builder: TrajectoryBuilder) -> None:
        self.law, self.problem, self.rec = law, problem, builder
        self.steps = self.events = 0
        s = problem.system
        self.free = HarmonicLinearFlow(s.state_matrix, np.array([0, 0, problem.amplitude * np.exp(1j * problem.phase) / s.m1, 0]), np.zeros(4), problem.omega)
        stuck_matrix = np.array([[0.0, 1.0], [-(s.k1 + s.k2) / s.m1, -(s.b1 + s.b2) / s.m1]])
        self.stuck = HarmonicLinearFlow(
            stuck_matrix, np.array([0, problem.amplitude * np.exp(1j * problem.phase) / s.m1]), np.array([0.0, s.k2 * problem.clearance / s.m1]), problem.omega
        )
        self.length_scale = law.length_scale
        self.tolerance = 1e-15 * self.length_scale
        self.force_tolerance = 1e-15 * (s.k2 + s.b2 * problem.omega) * self.length_scale
        self.resolution_velocity = 1e-14 * problem.velocity_scale()

    # ------------------------------------------------------------------ loop
    def go(self, y: NDArray[np.float64], t: float, periods: int) -> Trajectory:
        p, rec = self.problem, self.rec
        y = y.copy()
        self.law.check_start(y)
        y[1] = min(y[1], p.clearance)  # round-off above the stop is the stop
        stuck = bool(y[1] == p.clearance and y[3] == 0.0 and self._pushed(t, y))
        leaving = y[1] == p.clearance
        origin = t
        rec.strobe(t, y)
        k, piece, impacts_this_period, events_this_period = 1, None, 0, 0
        events_at = t if leaving else math.nan  # time of the last event: a search starting there leaves the surface
        while k <= periods:
            boundary = origin + k * p.period
            fresh = piece is None
            if piece is None:  # a new closed-form piece after each event
                piece, watch = self._piece(t, y, stuck)
            self.steps += 1
            tolerance = self.force_tolerance if stuck else self.tolerance
            t_event = first_crossing(watch, t, boundary, tolerance, leaving=leaving)
            leaving = False
            t_end = boundary if t_event is None else t_event
            if fresh:
                rec.segment(t, MODE_STUCK if stuck else MODE_FREE, y)
            self._moments(piece, t, t_end, MODE_STUCK if stuck else MODE_FREE)
            y, t = self._state(piece, t_end, stuck), t_end
            if t_event is None:  # period boundary: strobe, keep the piece
                # a search cut short by the boundary right after an event there must still start by leaving the surface
                leaving = t_end - events_at <= 1e-9 * p.period
                rec.strobe(t, y)
                k, impacts_this_period, events_this_period = k + 1, 0, 0
                continue
            events_this_period += 1
            events_at = t
            if events_this_period > 10 * self.law.max_impacts:
                raise RuntimeError(f"no progress at t = {t!r} s: {events_this_period} events in one period")
            if stuck:
                rec.stats["releases"] += 1
                stuck = False
            else:
                impacts_this_period += 1
                stuck = self._contact(t, y, impacts_this_period)
            piece, leaving = None, True  # leaving the stop, or the free flight into sticking
        return rec.build({"steps": self.steps, "events": self.events})

    def _pushed(self, t: float, y: NDArray[np.float64]) -> bool:
        """Would the stop have to push to hold the absorber at rest here (holding force > 0, or = 0 and rising)?"""
        _piece, release = self._piece(t, y, stuck=True)  # release = -holding force
        value = release.derivatives(t, 1)[0]
        # a holding force of a few round-off units is zero: its sign is noise (the flow's particular solution can be
        # larger than the length scale when Delta = 0, so allow 64 units), and the derivatives decide
        if abs(value) > 64.0 * self.force_tolerance:
            return value < 0.0
        return escape_step(release, t) is not None

    def _piece(self, t: float, y: NDArray[np.float64], stuck: bool) -> tuple[Piece, Observable]:
        """Closed-form motion from (t, y) and the function whose first zero ends it (gap, or holding force)."""
        p = self.problem
        if stuck:
            piece = self.stuck.start(t, y[[0, 2]])
            return piece, piece.observable(np.array([-p.system.k2, -p.system.b2]), p.system.k2 * p.clearance)
        piece = self.free.start(t, y)
        return piece, piece.observable(_GAP, -p.clearance)

    def _state(self, piece: Piece, t: float, stuck: bool) -> NDArray[np.float64]:
        if stuck:
            x1, v1 = piece.state(t)
            return np.array([x1, self.problem.clearance, v1, 0.0])
        y = piece.state(t)
        y[1] = min(y[1], self.problem.clearance)  # round-off above the stop is the stop
        return y

    def _contact(self, t: float, y: NDArray[np.float64], impacts_this_period: int) -> bool:
        """Apply the contact at time t to ``y`` in place; return True if the absorber sticks."""
        self.events += 1
        y[1] = self.problem.clearance
        velocity = y[3] if y[3] > self.resolution_velocity else 0.0  # below round-off: a touch, not an impact
        impact = self.law.collide(self.rec, t, velocity, impacts_this_period, lambda: self._pushed(t, y))
        y[3] = impact.after
        return impact.sticks

    # --------------------------------------------------------------- moments
    def _moments(self, piece: Piece, t0: float, t1: float, mode: int) -> None:
        """Add the segment's Fourier and square integrals (Gauss-Legendre, exact for smooth pieces)."""
        rec = self.rec
        if not rec.moments or t1 <= t0:
            return
        p = self.problem
        fastest = max(abs(x) for x in piece.flow.eigenvalues) + p.omega
        nodes, weights = gauss_legendre(int(min(400, 16 + math.ceil(0.8 * fastest * (t1 - t0)))))
        times = t0 + (t1 - t0) * nodes
        w = (t1 - t0) * weights
        phasor = np.exp(-1j * p.omega * times)
        states = piece.state(times)
        if mode == MODE_FREE:
            x1, x2 = states[:, 0], states[:, 1]
            contact = np.zeros_like(x1)
        else:
            x1, x2 = states[:, 0], np.full(times.shape, p.clearance)
            contact = np.asarray(p.holding_force(states[:, 0], states[:, 1]))
        rec.add_moments(np.array([w @ (x1 * phasor), w @ (x2 * phasor), w @ (contact * phasor), w @ x1**2, w @ x2**2]))
