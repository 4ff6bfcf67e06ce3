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
    """Right-hand side and event functions of one problem, with a mutable mode flag (free or stuck)."""

    problem: ImpactProblem
    with_moments: bool
    stuck: bool = False
    apex_event: bool = True
    rhs_calls: int = 0
    size: int = field(init=False)

    def __post_init__(self) -> None:
        s, p = self.problem.system, self.problem
        self.size = 4 + (QUADRATURES if self.with_moments else 0)
        self._coefficients = (s.m1, s.m2, s.k1, s.k2, s.b1, s.b2, p.amplitude, p.omega, p.phase, p.clearance)

    def rhs(self, t: float, y: NDArray[np.float64], yp: NDArray[np.float64]) -> None:
        """Write y' into ``yp`` (scikit-sundae convention)."""
        self.rhs_calls += 1
        m1, m2, k1, k2, b1, b2, q, w, phase, delta = self._coefficients
        x1, gap, v1, v2 = y[0], y[1], y[2], y[3]
        x2 = gap + delta
        force = q * math.cos(w * t + phase)
        yp[0] = v1
        if self.stuck:
            yp[1] = 0.0
            yp[2] = (force - k1 * x1 - b1 * v1 - k2 * (x1 - delta) - b2 * v1) / m1
            yp[3] = 0.0
        else:
            yp[1] = v2
            yp[2] = (force - k1 * x1 - b1 * v1 - k2 * (x1 - x2) - b2 * (v1 - v2)) / m1
            yp[3] = (k2 * (x1 - x2) + b2 * (v1 - v2)) / m2
        if self.with_moments:
            holding = b2 * v1 + k2 * (x1 - delta) if self.stuck else 0.0
            write_quadratures(yp, 4, t, w, x1, x2, holding)

    def derivative(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """y' as a new array."""
        yp = np.empty(self.size)
        self.rhs(t, y, yp)
        return yp

    #: Number of event functions and their crossing directions: gap rising, holding force falling, apex (X2' falling).
    NUM_EVENTS = 3
    DIRECTIONS = (1, -1, -1)

    def events(self, t: float, y: NDArray[np.float64], out: NDArray[np.float64]) -> None:
        """Event functions: gap X2 - Delta and apex X2' (free flight only), holding force (stuck only).

        Inactive events return a constant, so they never cross zero.
        """
        if self.stuck:
            out[0] = -1.0
            out[1] = self.problem.holding_force(y[0], y[2])
            out[2] = 1.0
        else:
            out[0] = y[1]
            out[1] = 1.0
            out[2] = y[3] if self.apex_event else 1.0


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
        return rec.build(self._counters() | {"rhs_calls": model.rhs_calls})

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
