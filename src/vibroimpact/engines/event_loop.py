"""Bookkeeping shared by the integrator-based engines: modes, contact map, sticking, strobes, harmonic moments.

An engine subclasses :class:`EventLoopEngine` and implements only :meth:`EventLoopEngine._begin` (set up its
integrator) and :meth:`EventLoopEngine._advance` (integrate from
a state until the period boundary or the first event). The integrated state is (X1, u, X1', X2') with the gap
u = X2 - Delta in place of X2, so that positions near the stop keep their absolute precision (with X2 itself, a
gap of 1e-20 m vanishes in X2 - Delta and the event function looks identically zero); it is followed, when harmonic
moments are wanted, by eight quadrature states: the integrals of X1 cos, X1 sin, X2 cos, X2 sin (of w t), of the
holding force times cos and sin (non-zero only while stuck), and of X1^2 and X2^2.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from enum import Enum
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.base import MODE_FREE, MODE_STUCK, Trajectory, TrajectoryBuilder
from vibroimpact.engines.rigid_contact import RigidContact
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.problem import ImpactProblem

__all__ = ["EventLoopEngine", "Stop", "Model"]

QUADRATURES = 8


def write_quadratures(yp: NDArray[np.float64], first: int, t: float, omega: float, x1: float, x2: float, contact: float) -> None:
    """Write the eight moment integrands into ``yp[first:first + 8]``: X1, X2 and the contact force times cos and
    sin of w t, then X1^2 and X2^2."""
    c, s = math.cos(omega * t), math.sin(omega * t)
    yp[first], yp[first + 1], yp[first + 2], yp[first + 3] = x1 * c, x1 * s, x2 * c, x2 * s
    yp[first + 4], yp[first + 5] = contact * c, contact * s
    yp[first + 6], yp[first + 7] = x1 * x1, x2 * x2


def moment_row(q: NDArray[np.float64]) -> NDArray[np.complex128]:
    """Integrals of the eight quadratures over a period -> the Trajectory's moment row (e^{-jwt} = cos - j sin)."""
    return np.array([q[0] - 1j * q[1], q[2] - 1j * q[3], q[4] - 1j * q[5], q[6], q[7]])


class Stop(Enum):
    """Why :meth:`EventLoopEngine._advance` returned."""

    BOUNDARY = 0
    CONTACT = 1
    RELEASE = 2


@dataclass
class Model:
    """Right-hand side, Jacobian and event functions of one problem, with a mutable mode flag (free or stuck).

    Between impacts the flow is linear: y' = A y + c + e q cos(w t + phase), with one constant matrix A per mode.
    :attr:`rhs`, :attr:`jacobian` and :attr:`events` are closures over those coefficients as Python floats (built once
    per model): a solver calls them at every step, where numpy scalars and attribute lookups cost more than the
    arithmetic.
    """

    problem: ImpactProblem
    with_moments: bool
    stuck: bool = False
    apex_event: bool = True
    size: int = field(init=False)
    #: y' into ``yp`` (scikit-sundae convention ``rhs(t, y, yp)``).
    rhs: Callable[[float, NDArray[np.float64], NDArray[np.float64]], None] = field(init=False, repr=False)
    #: d y' / d y into ``jac`` (scikit-sundae convention ``jacobian(t, y, yp, jac)``), exact: the flow is linear.
    jacobian: Callable[[float, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]], None] = field(init=False, repr=False)
    #: The three event functions into ``out`` (``events(t, y, out)``), see :data:`NUM_EVENTS`.
    events: Callable[[float, NDArray[np.float64], NDArray[np.float64]], None] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.size = 4 + (QUADRATURES if self.with_moments else 0)
        self._calls = [0]
        self.rhs = self._make_rhs()
        self.jacobian = self._make_jacobian()
        self.events = self._make_events()

    @property
    def rhs_calls(self) -> int:
        """Right-hand-side evaluations so far."""
        return self._calls[0]

    def matrix(self, stuck: bool) -> NDArray[np.float64]:
        """The constant matrix A (4, 4) of the flow of (X1, u, X1', X2') in one mode [SI]."""
        s = self.problem.system
        a = np.zeros((4, 4))
        a[0, 2] = 1.0
        a[2, 0], a[2, 2] = -(s.k1 + s.k2) / s.m1, -(s.b1 + s.b2) / s.m1
        if not stuck:
            a[1, 3] = 1.0
            a[2, 1], a[2, 3] = s.k2 / s.m1, s.b2 / s.m1
            a[3] = [s.k2 / s.m2, -s.k2 / s.m2, s.b2 / s.m2, -s.b2 / s.m2]
        return a

    def coefficients(self) -> tuple[float, ...]:
        """The flow's numbers as Python floats: rows 2 and 3 of the free-flight :meth:`matrix` (a20 ... a33), the
        constant accelerations c2 = K2 Delta / M1 and c3 = -K2 Delta / M2 [m s-2], q / M1 [m s-2], w [rad s-1],
        phase [rad], Delta [m], K2 [N m-1], B2 [N s m-1]. X1'' = a20 X1 + a21 u + a22 X1' + a23 X2' + c2 + (q / M1)
        cos(w t + phase), X2'' = a30 X1 + ... + c3; stuck, a21 and a23 drop out (u = X2' = 0) and X2'' = 0."""
        s, p = self.problem.system, self.problem
        rows = [float(v) for v in self.matrix(False)[2:].ravel()]
        k2, delta = float(s.k2), float(p.clearance)
        return (*rows, k2 * delta / s.m1, -k2 * delta / s.m2, p.amplitude / s.m1, float(p.omega), float(p.phase), delta, k2, float(s.b2))

    def _make_rhs(self) -> Callable[[float, NDArray[np.float64], NDArray[np.float64]], None]:
        model, calls = self, self._calls
        a20, a21, a22, a23, a30, a31, a32, a33, c2, c3, f2, w, phase, delta, k2, b2 = self.coefficients()
        cos, sin = math.cos, math.sin

        def rhs(t: float, y: NDArray[np.float64], yp: NDArray[np.float64]) -> None:
            calls[0] += 1
            x1, u, v1, v2 = y.tolist()  # Python floats: their arithmetic is several times cheaper than numpy's
            yp[0] = v1
            if model.stuck:
                yp[1] = 0.0
                yp[2] = a20 * x1 + a22 * v1 + c2 + f2 * cos(w * t + phase)
                yp[3] = 0.0
            else:
                yp[1] = v2
                yp[2] = a20 * x1 + a21 * u + a22 * v1 + a23 * v2 + c2 + f2 * cos(w * t + phase)
                yp[3] = a30 * x1 + a31 * u + a32 * v1 + a33 * v2 + c3

        def rhs_with_moments(t: float, y: NDArray[np.float64], yp: NDArray[np.float64]) -> None:
            calls[0] += 1
            x1, u, v1, v2 = y[:4].tolist()
            forcing = c2 + f2 * cos(w * t + phase)
            if model.stuck:
                holding = b2 * v1 + k2 * (x1 - delta)
                a2, a3 = a20 * x1 + a22 * v1 + forcing, 0.0
            else:
                holding = 0.0
                a2 = a20 * x1 + a21 * u + a22 * v1 + a23 * v2 + forcing
                a3 = a30 * x1 + a31 * u + a32 * v1 + a33 * v2 + c3
            x2, c, sn = u + delta, cos(w * t), sin(w * t)
            yp[:] = (v1, 0.0 if model.stuck else v2, a2, a3, x1 * c, x1 * sn, x2 * c, x2 * sn, holding * c, holding * sn, x1 * x1, x2 * x2)

        return rhs_with_moments if self.with_moments else rhs

    def _make_jacobian(self) -> Callable[[float, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]], None]:
        free, stuck = self.matrix(False), self.matrix(True)
        p, s, model, with_moments = self.problem, self.problem.system, self, self.with_moments
        delta, w = float(p.clearance), float(p.omega)

        def jacobian(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], jac: NDArray[np.float64]) -> None:
            jac[:4, :4] = stuck if model.stuck else free
            if with_moments:
                # the quadratures' rows: d/dy of X1 cos, X1 sin, X2 cos, X2 sin, H cos, H sin, X1^2, X2^2 (X2 = u + Delta)
                c, sn = math.cos(w * t), math.sin(w * t)
                x1, x2 = float(y[0]), float(y[1]) + delta
                jac[4:, :] = 0.0
                jac[4, 0], jac[5, 0], jac[6, 1], jac[7, 1] = c, sn, c, sn
                if model.stuck:
                    jac[8, 0], jac[8, 2], jac[9, 0], jac[9, 2] = s.k2 * c, s.b2 * c, s.k2 * sn, s.b2 * sn
                jac[10, 0], jac[11, 1] = 2.0 * x1, 2.0 * x2

        return jacobian

    def _make_events(self) -> Callable[[float, NDArray[np.float64], NDArray[np.float64]], None]:
        p, model = self.problem, self
        delta, k2, b2 = float(p.clearance), float(p.system.k2), float(p.system.b2)

        def events(t: float, y: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            if model.stuck:
                out[0] = -1.0
                out[1] = b2 * float(y[2]) + k2 * (float(y[0]) - delta)  # the holding force
                out[2] = 1.0
            else:
                out[0] = y[1]
                out[1] = 1.0
                out[2] = y[3] if model.apex_event else 1.0

        return events

    def derivative(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """y' as a new array."""
        yp = np.empty(self.size)
        self.rhs(t, y, yp)
        return yp

    #: Number of event functions and their crossing directions: gap rising, holding force falling, apex (X2' falling).
    #: Inactive events return a constant, so they never cross zero: free flight has the gap X2 - Delta and the apex
    #: X2', the stuck mode the holding force.
    NUM_EVENTS = 3
    DIRECTIONS = (1, -1, -1)


class EventLoopEngine(ABC):
    """Template: integrate period by period, apply the contact map and the sticking rules between calls."""

    name = "event-loop"

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        self.settings = settings

    @abstractmethod
    def _begin(self, model: Model) -> None:
        """Prepare the integrator for ``model`` (called once per :meth:`integrate`)."""

    @abstractmethod
    def _advance(self, model: Model, t: float, y: NDArray[np.float64], t_stop: float) -> tuple[Stop, float, NDArray[np.float64]]:
        """Integrate from (t, y) to ``t_stop`` or to the first event of the current mode; return why, when, state."""

    def _counters(self) -> dict[str, int]:
        """Integrator counters to add to the trajectory's stats."""
        return {}

    def _compiled_rhs_calls(self) -> int:
        """Right-hand-side evaluations made outside :attr:`Model.rhs` (by compiled callbacks)."""
        return 0

    def _end(self) -> None:
        """Release what :meth:`_begin` set up (called once per :meth:`integrate`, also after an error)."""

    def integrate(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` (X1, X2, X1', X2') at ``t_start`` [s]."""
        law = RigidContact(self.name, problem, self.settings, periods)
        state = np.asarray(state, dtype=float)
        law.check_start(state)
        model = Model(problem, moments)
        y = np.zeros(model.size)
        y[:4] = state
        y[1] = min(y[1] - problem.clearance, 0.0)  # integrate the gap u = X2 - Delta; round-off above is the stop
        model.stuck = bool(y[1] == 0.0 and y[3] == 0.0 and self._pushed(model, t_start, y))
        self._begin(model)
        try:
            rec = TrajectoryBuilder(problem, moments)

            def physical(y: NDArray[np.float64]) -> NDArray[np.float64]:
                return np.array([y[0], y[1] + problem.clearance, y[2], y[3]])  # the gap u back to X2

            rec.strobe(t_start, physical(y))
            rec.segment(t_start, MODE_STUCK if model.stuck else MODE_FREE, physical(y))
            quadratures = y[4:].copy()
            t = float(t_start)
            for k in range(1, periods + 1):
                boundary = t_start + k * problem.period
                impacts = events = 0
                while True:
                    if not model.stuck and y[1] >= 0.0 and y[3] > 0.0:
                        # at the stop and moving into it (a start there, or an impact exactly on a period boundary):
                        # integrators do not report a root at their initial time, so the contact is applied here
                        stop = Stop.CONTACT
                    elif boundary - t <= 4.0 * math.ulp(boundary):
                        stop, t = Stop.BOUNDARY, boundary  # nothing left of this period to integrate
                    else:
                        stop, t, y = self._advance(model, t, y, boundary)
                    if stop is Stop.BOUNDARY:
                        if not model.stuck and y[1] >= 0.0 and y[3] > 0.0:
                            continue  # an impact exactly at the boundary is applied before the strobe
                        break
                    events += 1
                    if events > 10 * law.max_impacts:
                        raise RuntimeError(f"no progress at t = {t!r} s: {events} events in one period")
                    if stop is Stop.RELEASE:
                        rec.stats["releases"] += 1
                        model.stuck = False
                    else:
                        impacts += 1
                        y = y.copy()
                        y[1] = 0.0
                        impact = law.collide(rec, t, max(y[3], 0.0), impacts, lambda: self._pushed(model, t, y))
                        model.stuck = impact.sticks
                        y[3] = impact.after
                    rec.segment(t, MODE_STUCK if model.stuck else MODE_FREE, physical(y))
                if moments:
                    q = y[4:] - quadratures
                    quadratures = y[4:].copy()
                    rec.add_moments(moment_row(q))
                rec.strobe(t, physical(y))
        finally:
            self._end()
        return rec.build(self._counters() | {"rhs_calls": model.rhs_calls + self._compiled_rhs_calls()})

    def _pushed(self, model: Model, t: float, y: NDArray[np.float64]) -> bool:
        """The stop must push to hold the absorber: holding force > 0, or = 0 and rising."""
        p = model.problem
        force = p.holding_force(y[0], y[2])
        scale = 1e-12 * (p.system.k2 * (p.clearance + abs(y[0])) + p.system.b2 * abs(y[2])) + 1e-300
        if abs(force) > scale:
            return bool(force > 0.0)
        was = model.stuck
        model.stuck = True
        rate = model.derivative(t, y)
        # an undamped absorber (B2 = 0) at rest on the stop has H' = K2 X1' = 0 as well: H'' = B2 X1''' + K2 X1''
        # decides (X1''' by a forward difference along the stuck motion); returned as "not pushed", a start at rest
        # on the stop went through it, since the integrators see no crossing of a gap that is 0 at their start
        step = 1e-6 * p.period
        ahead = model.derivative(t + step, y + step * rate)
        model.stuck = was
        first = p.system.b2 * rate[2] + p.system.k2 * rate[0]
        if abs(first) > scale * p.omega:
            return bool(first > 0.0)
        return bool(p.system.b2 * (ahead[2] - rate[2]) / step + p.system.k2 * rate[2] > 0.0)
