"""Bookkeeping shared by the integrator-based rigid-stop engines: modes, contact map, sticking, strobes, moments.

An engine subclasses :class:`EventLoopEngine` and implements only :meth:`EventLoopEngine._begin` (set up its
integrator) and :meth:`EventLoopEngine._advance` (integrate from a state until the period boundary or the first
event). Any N-dof structure with any rigid stops: the integrated state is (w, v) of :mod:`~vibroimpact.engines.flow_layout` (each
stop's penetration u_k = n_k . x - Delta_k in place of one coordinate, so that positions near a stop keep their
absolute precision; for the paper's layout (X1, X2 - Delta, X1', X2'); a stop hit without one, the second side of a
two-sided stop, gets one by a switch of layout, :meth:`Model.carry`), followed, when harmonic moments are wanted, by
the 3 N + 2 K quadratures of :mod:`~vibroimpact.engines.rigid_kernels`. A stop is held closed (*stuck*) with the constrained flow of
:mod:`~vibroimpact.engines.flow_layout` and released when its holding force turns negative; an impact on another stop frees it unless
it is still closed, at rest on it and pushed after the impulse. Sticking on two stops at once is refused
(``NotImplementedError`` naming both). A relative stop's n . x' is set exactly (to -R v, or 0 at a stick or a
release) so that round-off of two velocities never reads as an approach.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from enum import Enum
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.registry import INTEGRATOR, Capabilities
from vibroimpact.engines.base import MODE_FREE, MODE_STUCK, Trajectory, TrajectoryBuilder, start_state
from vibroimpact.engines.flow_layout import flow_layout
from vibroimpact.engines.rigid_kernels import RigidContact, APEX, STUCK, events_kernel, holding_kernel, jacobian_kernel, pack_parameters, quadrature_count, rhs_kernel
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.problem import ImpactProblem

__all__ = ["EventLoopEngine", "Outputs", "Stop", "Model", "moment_row"]


def moment_row(q: NDArray[np.float64], size: int = 2, stops: int = 1) -> NDArray[np.complex128]:
    """Integrals of the quadratures over a period -> the Trajectory's moment row of 2 N + K entries (e^{-jwt} =
    cos - j sin): x_i, each stop's contact force, x_i^2 (see :mod:`~vibroimpact.engines.rigid_kernels` for the quadratures' order)."""
    coordinates = q[0 : 2 * size : 2] - 1j * q[1 : 2 * size : 2]
    forces = q[2 * size : 2 * size + 2 * stops : 2] - 1j * q[2 * size + 1 : 2 * size + 2 * stops : 2]
    return np.concatenate([coordinates, forces, q[2 * size + 2 * stops : 3 * size + 2 * stops].astype(complex)])


class Stop(Enum):
    """Why :meth:`EventLoopEngine._advance` returned."""

    BOUNDARY = 0
    CONTACT = 1
    RELEASE = 2


class Model:
    """Right-hand side, Jacobian and event functions of one problem, with a mutable mode (free, or stuck on a stop)
    and a mutable :attr:`layout` (the stop last hit carries its penetration, :meth:`carry`).

    Between impacts the flow is linear, y' = A y + c + Re(b e^{jwt}), one (A, c, b) per mode (:mod:`~vibroimpact.engines.flow_layout`).
    :attr:`rhs`, :attr:`jacobian` and :attr:`events` call the compiled kernels of :mod:`~vibroimpact.engines.rigid_kernels` over
    :attr:`parameters`, the same array the compiled CVODE callbacks read: the mode written there is seen by both.

    Parameters
    ----------
    problem : ImpactProblem
        Structure, rigid stops and harmonic excitation.
    with_moments : bool
        Add the moment quadratures to the state.
    """

    #: Number of event functions and their crossing directions for one stop (the paper's layout): penetration
    #: rising, holding force falling, apex (approach velocity falling); :attr:`num_events` and :attr:`directions`
    #: give them for any number of stops. Inactive events return a constant, so they never cross zero.
    NUM_EVENTS = 3
    DIRECTIONS = (1, -1, -1)

    def __init__(self, problem: ImpactProblem, with_moments: bool) -> None:
        self.problem, self.with_moments = problem, with_moments
        self.layout = flow_layout(problem)
        n, k = self.layout.size, self.layout.stop_count
        self.states = 2 * n
        self.size = self.states + (quadrature_count(n, k) if with_moments else 0)
        self.parameters = pack_parameters(self.layout, self.size)
        self.num_events = 2 * k + 1
        self.directions = (1,) * k + (-1,) + (-1,) * k
        self._calls = [0]
        self._stuck = -1  # mirrors parameters[STUCK] as a Python int (read at every event)
        self._packed = {self.layout.first: self.parameters.copy()}
        parameters, calls = self.parameters, self._calls

        def rhs(t: float, y: NDArray[np.float64], yp: NDArray[np.float64]) -> None:
            calls[0] += 1
            rhs_kernel(t, y, yp, parameters)

        def jacobian(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], jac: NDArray[np.float64]) -> None:
            jacobian_kernel(t, y, jac.T, parameters)

        def events(t: float, y: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            events_kernel(t, y, out, parameters)

        #: y' into ``yp`` (scikit-sundae convention ``rhs(t, y, yp)``).
        self.rhs: Callable[[float, NDArray[np.float64], NDArray[np.float64]], None] = rhs
        #: d y' / d y into ``jac`` (``jacobian(t, y, yp, jac)``, jac[i, j] = d y'_i / d y_j), exact: the flow is linear.
        self.jacobian: Callable[[float, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]], None] = jacobian
        #: The event functions into ``out`` (``events(t, y, out)``), see :attr:`num_events`.
        self.events: Callable[[float, NDArray[np.float64], NDArray[np.float64]], None] = events

    @property
    def stuck_on(self) -> int:
        """Index of the stop held closed (-1: free flight)."""
        return self._stuck

    @stuck_on.setter
    def stuck_on(self, stop: int) -> None:
        self._stuck = int(stop)
        self.parameters[STUCK] = float(stop)

    @property
    def stuck(self) -> bool:
        """Is a stop held closed? (Setting True holds stop 0: for one-stop callers.)"""
        return self._stuck >= 0

    @stuck.setter
    def stuck(self, value: bool) -> None:
        self.stuck_on = 0 if value else -1

    @property
    def apex_event(self) -> bool:
        """Is the grazing guard (apex events) on?"""
        return bool(self.parameters[APEX] != 0.0)

    @apex_event.setter
    def apex_event(self, value: bool) -> None:
        self.parameters[APEX] = 1.0 if value else 0.0

    def carry(self, y: NDArray[np.float64], stop: int) -> NDArray[np.float64]:
        """y in a layout where ``stop`` carries its penetration (:meth:`FlowLayout.carrying`), switching the model's
        layout and its parameter array (in place: the compiled callbacks keep reading it) when it has none. A stop
        held keeps its pivot: where it would lose it, the layout stays."""
        target = self.layout.carrying(stop)
        held = self._stuck
        if target is self.layout or (held >= 0 and target.pivots[held] < 0):
            return y
        if target.first not in self._packed:
            self._packed[target.first] = pack_parameters(target, self.size)
        y = target.convert(y, self.layout)
        flags = self.parameters[STUCK], self.parameters[APEX]
        self.parameters[:] = self._packed[target.first]
        self.parameters[STUCK], self.parameters[APEX] = flags
        self.layout = target
        return y

    @property
    def rhs_calls(self) -> int:
        """Right-hand-side evaluations so far."""
        return self._calls[0]

    def derivative(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """y' as a new array."""
        yp = np.empty(self.size)
        rhs_kernel(t, np.ascontiguousarray(y, dtype=float), yp, self.parameters)
        return yp

    def holding(self, t: float, y: NDArray[np.float64], stop: int | None = None) -> float:
        """Holding force [N] of ``stop`` (default: the stop held) in state y at time t."""
        return float(holding_kernel(t, np.ascontiguousarray(y, dtype=float), self.parameters, self.stuck_on if stop is None else stop))


class Outputs:
    """Times at which a run records its state, and the states recorded there (a sampled run, :meth:`EventLoopEngine.sample`).

    Parameters
    ----------
    times : array_like
        Increasing times inside the run [s].
    t_start, t_end : float
        The run's span [s].
    width : int
        Entries of a state (2 N).
    """

    def __init__(self, times: NDArray[np.float64], t_start: float, t_end: float, width: int) -> None:
        self.times = np.asarray(times, dtype=float).reshape(-1)
        if self.times.size and (np.any(np.diff(self.times) < 0.0) or self.times[0] < t_start or self.times[-1] > t_end):
            raise ValueError(f"times: expected increasing times inside the run [{t_start!r}, {t_end!r}] s, got [{self.times.min()!r}, {self.times.max()!r}] s")
        self.states = np.full((self.times.size, width), math.nan)
        self.next = 0

    def next_time(self) -> float:
        """The next time to record [s] (inf when all are recorded)."""
        return float(self.times[self.next]) if self.next < self.times.size else math.inf

    def due(self, t: float) -> NDArray[np.float64]:
        """The times still to record before t [s] (strictly), in order."""
        return self.times[self.next : self.next + int(np.searchsorted(self.times[self.next :], t, side="left"))]

    def record(self, state: NDArray[np.float64]) -> None:
        """The state (x, x') at :meth:`next_time`."""
        self.states[self.next] = state
        self.next += 1

    def reached(self, t: float, state: NDArray[np.float64]) -> None:
        """The run stands at t [s] in ``state`` (x, x'): every time up to t (within the round-off an integrator
        cannot step over, 16 eps t) gets it."""
        close = t + 16.0 * np.finfo(float).eps * max(1.0, abs(t))
        while self.next < self.times.size and self.times[self.next] <= close:
            self.record(state)

    def finished(self, engine: str) -> NDArray[np.float64]:
        """The states, shape (len(times), 2 N); ``RuntimeError`` if the run left any time unrecorded."""
        if self.next < self.times.size:
            raise RuntimeError(f"engine {engine!r} recorded {self.next} of {self.times.size} output times (the first missing: {self.times[self.next]!r} s)")
        return self.states


class EventLoopEngine(ABC):
    """Template: integrate period by period, apply the contact map and the sticking rules between calls."""

    name = "event-loop"
    #: what it can do when built directly (:func:`~vibroimpact.engines.registry.make_engine` sets its registry row's)
    capabilities: Capabilities = INTEGRATOR

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        self.settings = settings

    @abstractmethod
    def _begin(self, model: Model) -> None:
        """Prepare the integrator for ``model`` (called once per :meth:`integrate`)."""

    @abstractmethod
    def _advance(self, model: Model, t: float, y: NDArray[np.float64], t_stop: float, outputs: Outputs | None = None) -> tuple[Stop, float, NDArray[np.float64], int]:
        """Integrate from (t, y) to ``t_stop`` or to the first event of the current mode; return why, when, the
        state, and the stop of a contact or release (-1 at the boundary). With ``outputs``, record on the way the
        state (x, x') at each of its times before the one returned (:meth:`Outputs.next_time`,
        :meth:`Outputs.record`), interpolated by the integrator without changing its steps."""

    def _counters(self) -> dict[str, int]:
        """Integrator counters to add to the trajectory's stats."""
        return {}

    def _compiled_rhs_calls(self) -> int:
        """Right-hand-side evaluations made outside :attr:`Model.rhs` (by compiled callbacks)."""
        return 0

    def _end(self) -> None:
        """Release what :meth:`_begin` set up (called once per :meth:`integrate`, also after an error)."""

    def integrate(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` (x_1 ... x_N, x_1' ... x_N') at ``t_start`` [s]."""
        return self._run(problem, state, t_start, periods, moments, None)

    def sample(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, times: NDArray[np.float64]) -> tuple[Trajectory, NDArray[np.float64]]:
        """Integrate ``periods`` periods from ``state`` at ``t_start`` [s] and give the states (x, x') at ``times`` [s]
        (inside the run, increasing), shape (n, 2 N) [m, m s-1]: the integrator's own interpolation between events
        (:meth:`_advance` with :class:`Outputs`), the state just after the events at an event's time, the strobe
        state at a period boundary. The events are handled as :meth:`integrate` handles them."""
        outputs = Outputs(times, t_start, t_start + periods * problem.period, 2 * problem.size)
        trajectory = self._run(problem, state, t_start, periods, False, outputs)
        return trajectory, outputs.finished(self.name)

    def _run(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool, outputs: Outputs | None) -> Trajectory:
        """:meth:`integrate`, recording the states at the times of ``outputs`` if given."""
        law = RigidContact(self.name, problem, self.settings, periods)
        state = start_state(problem, state, t_start)  # finite, 2 N values
        n = problem.size
        law.check_start(state)
        model = Model(problem, moments)
        layout = model.layout
        y = np.zeros(model.size)
        y[: 2 * n] = layout.internal(state)
        for p in layout.pivots:
            if p >= 0:
                y[p] = min(y[p], 0.0)  # round-off beyond a stop is the stop
        resting = [k for k in range(layout.stop_count) if layout.penetration(y, k) >= 0.0 and layout.approach(y, k) == 0.0 and self._pushed(model, t_start, y, k)]
        if len(resting) > 1:
            raise NotImplementedError(f"the initial state rests on stops {resting[0]} and {resting[1]} at once, both pushing: sticking on two stops at once is not supported")
        if resting and layout.pivots[resting[0]] < 0:
            y = model.carry(y, resting[0])
            model.layout.close(y, resting[0])
        model.stuck_on = resting[0] if resting else -1
        touching = _touch_probe(model)
        self._begin(model)
        try:
            rec = TrajectoryBuilder(problem, moments)
            rec.strobe(t_start, model.layout.physical(y))
            rec.segment(t_start, MODE_STUCK if model.stuck else MODE_FREE, model.layout.physical(y), stop=model.stuck_on)
            quadratures = y[2 * n :].copy()
            t = float(t_start)
            period, limit, advance, contact, segment = problem.period, 10 * law.max_impacts, self._advance, self._contact, rec.segment
            for k in range(1, periods + 1):
                boundary = t_start + k * period
                impacts = events = 0
                while True:
                    which = touching(y)
                    if which >= 0:
                        # at a stop and moving into it (a start there, or an impact exactly on a period boundary, or
                        # a stop freed by an impact on another): integrators do not report a root at their initial
                        # time, so the contact is applied here
                        stop = Stop.CONTACT
                    elif boundary - t <= 4.0 * math.ulp(boundary):
                        stop, t = Stop.BOUNDARY, boundary  # nothing left of this period to integrate
                    elif outputs is None:
                        stop, t, y, which = advance(model, t, y, boundary)
                    else:
                        outputs.reached(t, model.layout.physical(y))  # the outputs at t: the state after its events
                        stop, t, y, which = advance(model, t, y, boundary, outputs)
                    if stop is Stop.BOUNDARY:
                        if touching(y) >= 0:
                            continue  # an impact exactly at the boundary is applied before the strobe
                        break
                    events += 1
                    if events > limit:
                        raise RuntimeError(f"no progress at t = {t!r} s: {events} events in one period")
                    if stop is Stop.RELEASE:
                        rec.stats["releases"] += 1
                        model.layout.set_approach(y, which, 0.0)  # held: n . x' = 0 but for the stuck flight's round-off
                        model.stuck_on = -1
                    else:
                        impacts += 1
                        y = contact(model, law, rec, t, y, which, impacts)
                    held = model._stuck
                    segment(t, MODE_FREE if held < 0 else MODE_STUCK, model.layout.physical(y), stop=held)
                if moments:
                    q = y[2 * n :] - quadratures
                    quadratures = y[2 * n :].copy()
                    rec.add_moments(moment_row(q, n, layout.stop_count))
                rec.strobe(t, model.layout.physical(y))
                if outputs is not None:
                    outputs.reached(t, model.layout.physical(y))
        finally:
            self._end()
        return rec.build(self._counters() | {"rhs_calls": model.rhs_calls + self._compiled_rhs_calls()})

    def _contact(self, model: Model, law: RigidContact, rec: TrajectoryBuilder, t: float, y: NDArray[np.float64], which: int, impacts: int) -> NDArray[np.float64]:
        """Apply stop ``which``'s impact law at time t to the state y (its gap closed exactly, and carried by the
        integrator from here on: :meth:`Model.carry`); return the new state."""
        held = model._stuck
        if held == which:
            raise RuntimeError(f"stop {which} is held closed and reported a contact at t = {t!r} s")
        y = y.copy()
        if model.layout.pivots[which] < 0:
            y = model.carry(y, which)
        layout = model.layout
        if held >= 0:
            model.stuck_on = -1  # an impact on another stop frees the one held
        layout.close(y, which)
        velocity = max(layout.approach(y, which), 0.0)

        def pushed() -> bool:  # asked only of a chattering impact
            resting = y.copy()
            self._kick(model, resting, which, float(law.masses[which]) * velocity, 0.0)
            return self._pushed(model, t, resting, which)

        outcome = law.collide(rec, t, velocity, impacts, pushed, stop=which)
        self._kick(model, y, which, outcome.impulse, outcome.after)
        # the stop held before: still closed, not driven off by this impulse and still pushed, it holds on (an
        # impulse on another stop that leaves its coordinates alone); driven into it, the next contact applies
        holds = held >= 0 and self._holds(model, t, y, held)
        if outcome.sticks:
            if holds:
                raise NotImplementedError(f"at t = {t!r} s the motion sticks on stop {which} while held on stop {held}: sticking on two stops at once is not supported")
            model.stuck_on = which
        elif holds:
            layout.set_approach(y, held, 0.0)
            model.stuck_on = held
        return y

    def _holds(self, model: Model, t: float, y: NDArray[np.float64], stop: int) -> bool:
        """Is ``stop`` closed in y, at rest on it (n . x' = 0 to round-off of the velocities) and pushed?"""
        layout, n = model.layout, model.layout.size
        i, _, j, _ = layout.probes[stop]
        noise = 1e-12 * (abs(y[n + i]) + (abs(y[n + j]) if j >= 0 else 0.0))
        if layout.penetration(y, stop) < 0.0 or abs(layout.approach(y, stop)) > noise:
            return False
        resting = y.copy()
        layout.set_approach(resting, stop, 0.0)
        return self._pushed(model, t, resting, stop)

    @staticmethod
    def _kick(model: Model, y: NDArray[np.float64], stop: int, impulse: float, after: float) -> None:
        """x' -> x' - impulse M^-1 n_k in place, with n_k . x'(t+) = ``after`` made exact (when the impulse moves one
        coordinate only, an absolute stop on a decoupled mass, that velocity is set to it directly)."""
        layout, n = model.layout, model.layout.size
        if layout.kicked[stop] < 0:
            y[n : 2 * n] -= impulse * layout.kicks[stop]
        layout.set_approach(y, stop, after)

    def _pushed(self, model: Model, t: float, y: NDArray[np.float64], stop: int) -> bool:
        """Stop ``stop`` must push to hold the structure in y (its gap closed and at rest): holding force > 0, or = 0
        and rising (its first non-zero derivative along the stuck flight decides; the flow is linear, so they are
        exact: lambda' = H . y' + Re(jw hb e^{jwt}), y'' = A y' + Re(jw b e^{jwt}))."""
        layout, n = model.layout, model.layout.size
        rows, constants, harmonic = layout.holding
        was = model.stuck_on
        model.stuck_on = stop
        try:
            force = model.holding(t, y, stop)
            scale = 1e-12 * (float(np.abs(rows[stop]) @ np.abs(y[: 2 * n])) + abs(constants[stop]) + abs(harmonic[stop])) + 1e-300
            if abs(force) > scale:
                return bool(force > 0.0)
            omega = layout.omega
            turn = complex(math.cos(omega * t), math.sin(omega * t))
            rate = model.derivative(t, y)[: 2 * n]
            first = float(rows[stop] @ rate) + (1j * omega * harmonic[stop] * turn).real
            if abs(first) > scale * omega:
                return bool(first > 0.0)
            a, _, b = layout.stuck[stop]
            second_rate = a @ rate + (1j * omega * b * turn).real
            return bool(float(rows[stop] @ second_rate) - (omega**2 * harmonic[stop] * turn).real > 0.0)
        finally:
            model.stuck_on = was


def _touch_probe(model: Model) -> Callable[[NDArray[np.float64]], int]:
    """A function of the state: the first stop (not held) at or beyond its gap and moving into it, else -1. Written
    with Python scalars: it runs at every event and period boundary."""
    n = model.layout.size
    probes: dict[int, tuple[tuple[int, int, int, int, float, float], ...]] = {}
    current: list = [None, ()]  # the layout last seen and its probes (the layout changes only at a carry)

    def touching(y: NDArray[np.float64]) -> int:
        held = model._stuck
        layout = model.layout  # it changes where a stop without a pivot is hit (Model.carry)
        if layout is current[0]:
            table = current[1]
        else:
            table = probes.get(layout.first)
            if table is None:
                table = probes[layout.first] = tuple((k, layout.pivots[k], n + i, n + j, a, b) for k, (i, a, j, b) in enumerate(layout.probes))
            current[0], current[1] = layout, table
        for k, p, i, j, a, b in table:
            if k == held or (y[p] if p >= 0 else layout.penetration(y, k)) < 0.0:
                continue
            if j < 0:
                if a * y[i] > 0.0:
                    return k
            # a relative stop's n . x' after a kick along M^-1 n (or in a stuck flight) is 0 only to round-off of
            # the two velocities: closer to 0 than 1e-12 of them, it is not an approach (a phantom impact otherwise)
            elif a * y[i] + b * y[j] > 1e-12 * (abs(y[i]) + abs(y[j])):
                return k
        return -1

    return touching
