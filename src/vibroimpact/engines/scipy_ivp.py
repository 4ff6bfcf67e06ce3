"""Comparison engines: ``scipy.integrate.solve_ivp`` (DOP853, LSODA, Radau, ...) with terminal events and restarts.

The loop a user would write: integrate to the next contact (or release) with a terminal event, apply the map,
restart (any structure and stops: one contact event per stop, see :mod:`.event_loop`). There is no grazing guard, on purpose: these are the baselines the ``momentary`` engine is measured against.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.event_loop import EventLoopEngine, Model, Stop

__all__ = ["SolveIvpEngine", "SOLVE_IVP_METHODS"]

SOLVE_IVP_METHODS = ("RK45", "DOP853", "LSODA", "Radau", "BDF")


class SolveIvpEngine(EventLoopEngine):
    """``solve_ivp`` with a terminal contact event (free flight) or release event (stuck).

    Parameters
    ----------
    settings : EngineSettings
        rtol, atol and max_step are used; ``method`` of the settings is ignored.
    method : str
        One of :data:`SOLVE_IVP_METHODS`.
    """

    def __init__(self, settings: EngineSettings = EngineSettings(), method: str = "DOP853") -> None:
        if method not in SOLVE_IVP_METHODS:
            raise ValueError(f"method = {method!r} is not allowed: use one of {', '.join(SOLVE_IVP_METHODS)}")
        super().__init__(settings)
        self.method = method
        self.name = f"solve_ivp_{method}"

    def _begin(self, model: Model) -> None:
        def contact(stop: int) -> Any:
            def event(t: float, y: NDArray[np.float64]) -> float:
                gap = model.layout.penetration(y, stop)  # n . x - Delta
                # At the restart time, and wherever it is exactly 0, the gap counts as short of the stop. Every
                # restart on the stop (after an impact, a touch or a release) has a gap of 0, and SciPy takes g = 0 at
                # a step's start with g >= 0 at its end for a crossing at that start (brentq returns the end where
                # g = 0): a fast return to the stop (chatter) was applied at the start itself, to the rebound's
                # velocity, over and over, and at rest on the stop with no force (g = 0 throughout) every step
                # reported one. Negative there, the root is the first crossing after the start. (By time as well as
                # by value: brentq re-evaluates the start on the dense output, whose gap there may differ from 0 by
                # round-off.)
                return -1.0 if gap == 0.0 or (t == self._restart and gap > 0.0) else gap

            event.terminal, event.direction = True, 1.0  # type: ignore[attr-defined]
            return event

        def release(t: float, y: NDArray[np.float64]) -> float:
            return model.holding(t, y)

        release.terminal, release.direction = True, -1.0  # type: ignore[attr-defined]
        self._contacts = [contact(k) for k in range(model.layout.stop_count)]
        self._release = release

        def rhs(t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
            return model.derivative(t, y)

        self._rhs = rhs
        self._steps = self._events_found = self._nfev = 0
        self._restart = math.nan

    def _counters(self) -> dict[str, int]:
        return {"steps": self._steps, "events": self._events_found, "solver_rhs_calls": self._nfev}

    def _advance(self, model: Model, t: float, y: NDArray[np.float64], t_stop: float) -> tuple[Stop, float, NDArray[np.float64], int]:
        options: dict[str, Any] = {"method": self.method, "rtol": self.settings.rtol, "atol": self.settings.atol}
        if self.settings.max_step > 0.0:
            options["max_step"] = self.settings.max_step
        # the contacts of every stop not held, then the release of the one held
        watched = [k for k in range(model.layout.stop_count) if k != model.stuck_on]
        events = [self._contacts[k] for k in watched] + ([self._release] if model.stuck else [])
        self._restart = t
        result = solve_ivp(self._rhs, (t, t_stop), y, events=events, **options)
        if result.status < 0:
            raise RuntimeError(f"solve_ivp ({self.method}) failed at t = {result.t[-1]!r} s: {result.message}")
        self._steps += result.t.size - 1
        self._nfev += result.nfev
        if result.status == 1:
            self._events_found += 1
            for index, times in enumerate(result.t_events):
                if times.size:
                    state = np.array(result.y_events[index][0])
                    if index < len(watched):
                        return Stop.CONTACT, float(times[0]), state, watched[index]
                    return Stop.RELEASE, float(times[0]), state, model.stuck_on
        return Stop.BOUNDARY, float(result.t[-1]), np.array(result.y[:, -1]), -1
