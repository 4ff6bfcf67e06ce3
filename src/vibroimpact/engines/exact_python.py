"""Engine ``exact_python``: the ``exact`` engine's algorithm in pure Python (the compiled core, :mod:`~vibroimpact.engines.exact_core`, is
the same loop under numba; this copy cross-checks it and is the speed baseline of ``engine_cost``).

Between events the motion is linear with harmonic and constant loads, so it is propagated in closed form (the flows of
:mod:`~vibroimpact.engines.exact_flows`: exponentials plus the harmonic particular solution, and a polynomial on rigid-body modes).
Contacts with any of the stops are found by guaranteed root bracketing (:func:`.linear_flow.first_crossing`): no
contact is missed however tangent, and contact times are exact to round-off. An impact on stop k restitutes n_k . x'
by an impulse along M^-1 n_k (:meth:`.rigid_contact.RigidContact.kick`). When impacts accumulate (chattering, small R)
and the stop pushes the structure, it sticks: the flow held on the stop's surface runs until the holding force
(:meth:`~vibroimpact.model.problem.ImpactProblem.contact_holding`) turns negative (found by the same root search), or
an impact on another stop frees it (unless the impulse leaves it closed, at rest on it and pushed). Moments are integrated by Gauss-Legendre quadrature (the compiled core has them in
closed form: an independent check).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.registry import ENGINES, Capabilities
from vibroimpact.engines.base import MODE_FREE, MODE_STUCK, Trajectory, TrajectoryBuilder, start_state
from vibroimpact.engines.exact_flows import ExactModel, build_model
from vibroimpact.engines.linear_flow import HarmonicLinearFlow, Observable, Piece, escape_step, first_crossing, gauss_legendre
from vibroimpact.engines.rigid_kernels import RigidContact
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.problem import ImpactProblem

__all__ = ["PythonExactEngine"]


class PythonExactEngine:
    """The pure-Python exact engine (see module docstring): the compiled core's cross-check and speed baseline."""

    name = "exact_python"
    #: what it can do when built directly (the registry's row; :func:`~vibroimpact.engines.registry.make_engine` sets its own)
    capabilities: Capabilities = ENGINES["exact_python"].capabilities

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        self.settings = settings

    def integrate(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` (x, x') at ``t_start`` [s]."""
        run = _Run(RigidContact(self.name, problem, self.settings, periods), problem, TrajectoryBuilder(problem, moments))
        return run.go(start_state(problem, state, t_start), float(t_start), int(periods))

    def sample(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, times: NDArray[np.float64]) -> tuple[Trajectory, NDArray[np.float64]]:
        """Integrate ``periods`` periods from ``state`` at ``t_start`` [s] and give the states at ``times`` [s] (inside
        the run, increasing), shape (n, 2 N) [m, m s-1], exact (:meth:`dense`; at an event's time, the state after it)."""
        trajectory = self.integrate(problem, state, t_start, periods)
        return trajectory, self.dense(trajectory, times)

    def dense(self, trajectory: Trajectory, times: NDArray[np.float64], side: str = "right") -> NDArray[np.float64]:
        """States at arbitrary ``times`` inside a trajectory, shape (n, 2 N), exact (from its segments); at an event's
        time ``side="right"`` gives the state after it, ``"left"`` the state before it."""
        if side not in ("left", "right"):
            raise ValueError(f"side = {side!r} is not allowed: use 'left' or 'right'")
        problem = trajectory.problem
        run = _Run(RigidContact(self.name, problem, self.settings, 0), problem, TrajectoryBuilder(problem, False))
        times = np.asarray(times, dtype=float)
        index = np.clip(np.searchsorted(trajectory.segments[:, 0], times, side=side) - 1, 0, len(trajectory.segments) - 1)  # type: ignore[call-overload]
        out = np.empty((times.size, 2 * problem.size))
        for i in np.unique(index):
            start, _end, mode = trajectory.segments[i]
            held = int(trajectory.segment_stops[i]) if mode == MODE_STUCK else -1
            piece = run.flows[held + 1].start(start, trajectory.segment_states[i])
            chosen = index == i
            out[chosen] = [run._state(piece, t, held) for t in times[chosen]]
        return out


@lru_cache(maxsize=64)
def _prepared(problem: ImpactProblem, length_scale: float) -> tuple[ExactModel, tuple[HarmonicLinearFlow, ...]]:
    """The model and flows of a problem, once (``dense`` is called many times on one trajectory)."""
    model = build_model(problem, length_scale)
    return model, tuple(HarmonicLinearFlow.from_flow(flow) for flow in (model.free, *model.stuck))


class _Run:
    """One integration: the event loop of the exact engine."""

    def __init__(self, law: RigidContact, problem: ImpactProblem, builder: TrajectoryBuilder) -> None:
        self.law, self.problem, self.rec = law, problem, builder
        self.steps = self.events = 0
        self.length_scale = law.length_scale
        self.model, self.flows = _prepared(problem, self.length_scale)
        self.size = problem.size
        self.count = len(problem.stops)
        zero = np.zeros((self.count, self.size))
        self.gap_weights = np.hstack([self.model.normals, zero])
        self.tolerance = 1e-15 * self.length_scale
        self.resolution_velocity = 1e-14 * law.velocity_scale

    # ------------------------------------------------------------------ loop
    def go(self, y: NDArray[np.float64], t: float, periods: int) -> Trajectory:
        p, rec, count = self.problem, self.rec, self.count
        y = y.copy()
        if y.shape != (2 * self.size,):
            raise ValueError(f"state: expected {2 * self.size} values (x and x' of {self.size} coordinates), got shape {y.shape}")
        self.law.check_start(y)
        self._clamp(y, -1)  # round-off beyond a stop is the stop
        held = -1
        for k in range(count):
            if self._gap(k, y) >= -self.tolerance and abs(self.law.approach(y)[k]) <= self.resolution_velocity and self._pushed(k, t, y):
                if held >= 0:
                    raise NotImplementedError(f"the start would stick on two stops at once (stops {held} and {k}); the exact engine holds one stop at a time")
                held = k
        origin = t
        rec.strobe(t, y)
        k, piece, events_this_period = 1, None, 0
        impacts_this_period = np.zeros(count, dtype=int)
        leave = np.zeros(count, dtype=bool)
        events_at = np.full(count, math.nan)  # time of each observable's last event: a search starting there leaves it
        watch: list[Observable] = []
        while k <= periods:
            boundary = origin + k * p.period
            fresh = piece is None
            if piece is None:  # a new closed-form piece after each event
                piece = self.flows[held + 1].start(t, y)
                watch = []
                for j in range(count):
                    watch.append(self._observable(piece, j, held))
                    leave[j] = True if j == held else self._gap(j, y) >= -self.tolerance
                    if leave[j]:
                        events_at[j] = t
            self.steps += 1
            t_event, event, limit = None, -1, boundary
            for j in range(count):
                tolerance = self.model.force_tolerances[j] if j == held else self.tolerance
                found = first_crossing(watch[j], t, limit, tolerance, leaving=bool(leave[j]))
                leave[j] = False
                if found is not None and (t_event is None or found < t_event):
                    t_event, event, limit = found, j, found
            t_end = boundary if t_event is None else t_event
            if fresh:
                rec.segment(t, MODE_STUCK if held >= 0 else MODE_FREE, y, stop=held)
            self._moments(piece, t, t_end, held)
            y, t = self._state(piece, t_end, held), t_end
            if t_event is None:  # period boundary: strobe, keep the piece
                # a search cut short by the boundary right after an event there must still start by leaving the surface
                leave = t_end - events_at <= 1e-9 * p.period
                rec.strobe(t, y)
                k, events_this_period = k + 1, 0
                impacts_this_period[:] = 0
                continue
            events_this_period += 1
            if events_this_period > 10 * self.law.max_impacts:
                raise RuntimeError(f"no progress at t = {t!r} s: {events_this_period} events in one period")
            piece = None
            if event == held:
                rec.stats["releases"] += 1
                held = -1
                continue
            impacts_this_period[event] += 1
            held = self._contact(t, y, event, int(impacts_this_period[event]), held)
        return rec.build({"steps": self.steps, "events": self.events})

    def _gap(self, k: int, y: NDArray[np.float64]) -> float:
        """n_k . x - Delta_k (>= 0: at or beyond stop k)."""
        return float(self.gap_weights[k] @ y - self.model.clearances[k])

    def _clamp(self, y: NDArray[np.float64], held: int) -> None:
        """Round-off beyond a stop (other than the held one) is the stop: in place."""
        for k in range(self.count):
            if k != held and self._gap(k, y) > 0.0:
                self._snap(k, y)

    def _snap(self, k: int, y: NDArray[np.float64]) -> None:
        i = self.model.simple[k]
        if i >= 0:
            y[i] = self.model.normals[k, i] * self.model.clearances[k]
            return
        normal = self.model.normals[k]
        y[: self.size] -= self._gap(k, y) * normal / float(normal @ normal)

    def _observable(self, piece: Piece, k: int, held: int) -> Observable:
        """What ends the piece at stop k: minus the holding force if held there, else minus its gap."""
        m = self.model
        if k == held:
            return piece.observable(m.hold_weights[k], float(m.hold_offsets[k]), complex(m.hold_harmonics[k]))
        return piece.observable(self.gap_weights[k], -float(m.clearances[k]))

    def _pushed(self, k: int, t: float, y: NDArray[np.float64]) -> bool:
        """Would stop k have to push to hold the structure at rest on it here (holding force > 0, or = 0 and rising)?"""
        release = self._observable(self.flows[k + 1].start(t, y), k, k)  # minus the holding force
        value = release.derivatives(t, 1)[0]
        # a holding force of a few round-off units is zero: its sign is noise (the flow's particular solution can be
        # larger than the length scale when Delta = 0, so allow 64 units), and the derivatives decide; a force that
        # falls to touch zero and rises again within the round-off the held search allows is a push, as that search
        # finds (escape_step's band)
        tolerance = float(self.model.force_tolerances[k])
        if abs(value) > 64.0 * tolerance:
            return value < 0.0
        return escape_step(release, t, release.round_off(t, tolerance)) is not None

    def _state(self, piece: Piece, t: float, held: int) -> NDArray[np.float64]:
        y = piece.state(t)
        self._clamp(y, held)
        return y

    def _holds(self, k: int, t: float, y: NDArray[np.float64]) -> bool:
        """Does held stop k hold on after an impulse on another stop: still closed, at rest on it (n . x' within 1e-12
        of the velocities it is made of: a relative stop's two velocities cancel only to round-off) and pushed?"""
        terms = self.model.normals[k] * y[self.size :]
        if self._gap(k, y) < -self.tolerance or abs(float(np.sum(terms))) > 1e-12 * float(np.sum(np.abs(terms))):
            return False
        return self._pushed(k, t, y)

    def _contact(self, t: float, y: NDArray[np.float64], k: int, impacts_this_period: int, held: int) -> int:
        """Apply the contact with stop k at time t to ``y`` in place; return the stop held after it: k if it sticks
        there, ``held`` (the stop held before, -1 if none) if that one holds on through the impulse, else -1."""
        self.events += 1
        self._snap(k, y)
        raw = float(self.law.approach(y)[k])
        noise = 1e-12 * float(np.abs(self.model.normals[k]) @ np.abs(y[self.size :]))
        # below round-off (of the velocity scale, or of the velocities a relative stop's n . x' is made of): a touch
        velocity = raw if raw > self.resolution_velocity and raw > noise else 0.0
        if self.count > 1:
            others = [j for j in range(self.count) if j != k and self._gap(j, y) >= -self.tolerance]
        impact = self.law.collide(self.rec, t, velocity, impacts_this_period, lambda: self._pushed(k, t, y), stop=k)
        if impact.sticks and self.count > 1:
            for j in others:
                if self._pushed(j, t, y):
                    raise NotImplementedError(f"at t = {t!r} s the structure would stick on two stops at once (stops {k} and {j}); the exact engine holds one stop at a time")
        i = self.model.simple[k]
        if i >= 0:
            y[self.size + i] = self.model.normals[k, i] * impact.after
        else:
            y[:] = self.law.kick(y, k, (raw - impact.after) * self.model.masses[k])
        if held >= 0 and not impact.sticks and self._holds(held, t, y):
            # an impulse on another stop that leaves the held one closed, at rest and pushed: it holds on, its n . x'
            # made exactly 0 (a round-off approach would read as an impact on it next)
            self._snap(held, y)
            i = self.model.simple[held]
            if i >= 0:
                y[self.size + i] = 0.0
            else:
                y[:] = self.law.kick(y, held, float(self.law.approach(y)[held]) * self.model.masses[held])
            return held
        if held >= 0:
            self.rec.stats["releases"] += 1
        return k if impact.sticks else -1

    # --------------------------------------------------------------- moments
    def _moments(self, piece: Piece, t0: float, t1: float, held: int) -> None:
        """Add the segment's Fourier and square integrals (Gauss-Legendre, exact for smooth pieces)."""
        rec = self.rec
        if not rec.moments or t1 <= t0:
            return
        p, size = self.problem, self.size
        rates = piece.flow.eigenvalues
        fastest = (float(np.max(np.abs(rates))) if rates.size else 0.0) + p.omega
        nodes, weights = gauss_legendre(int(min(400, 16 + math.ceil(0.8 * fastest * (t1 - t0)))))
        times = t0 + (t1 - t0) * nodes
        w = (t1 - t0) * weights
        phasor = np.exp(-1j * p.omega * times)
        states = piece.state(times)
        x = states[:, :size]
        values = np.zeros(2 * size + self.count, dtype=complex)
        values[:size] = (w * phasor) @ x
        values[size + self.count :] = w @ x**2
        if held >= 0:
            m = self.model
            force = -(states @ m.hold_weights[held] + m.hold_offsets[held] + np.real(m.hold_harmonics[held] * np.exp(1j * p.omega * times)))
            values[size + held] = w @ (force * phasor)
        rec.add_moments(values)
