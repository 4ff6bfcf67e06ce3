"""Engine ``momentary``: SUNDIALS CVODE (the one scikit-sundae ships) with exact contact events and a grazing guard.

Any N-dof structure with any rigid stops (:mod:`~vibroimpact.engines.event_loop`, :mod:`~vibroimpact.engines.flow_layout`). CVODE finds roots only as sign
changes between steps, so a nearly tangent contact (a gap's minimum slightly below zero inside one step) would be
missed. The guard: an event function per stop, its approach velocity n_k . x' falling through zero, stops the
integrator at every local maximum of n_k . x in free flight. CVODE locates that root and evaluates all
event functions there, so a gap that is positive at the maximum reveals its own sign change and is returned as the
contact. A maximum with a negative gap is passed over; one with a gap of exactly zero is a tangent touch, handled
as a contact at zero speed.

The flow between impacts is linear, so CVODE gets its exact, constant Jacobian (one matrix per mode) instead of
difference quotients. The right-hand side, the Jacobian and the event functions are numba ``cfunc`` callbacks
(compiled once, cached on disk) given to CVODE through :class:`~vibroimpact.engines.sundae.CompiledCvode`: Python runs
only between events and at period boundaries. Where that binding cannot load, the engine runs the same equations
through scikit-sundae's Python callbacks (~20x slower; ``compiled=False`` forces it). scikit-sundae 1.2.0 facts the
fallback relies on (see ``../shared/NOTES.md``): event records accumulate on the event function and are cleared
here after each event; ``direction`` is read at the first ``init_step`` only, so the event directions are fixed
and inactive events return a constant; errors do not raise but return a negative ``status``, turned into
``RuntimeError`` here.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp
from sksundae.cvode import CVODE

from vibroimpact.engines.event_loop import EventLoopEngine, Model, Outputs, Stop
from vibroimpact.engines.rigid_kernels import COMPILED_EVENTS as _events, COMPILED_JACOBIAN as _jacobian, COMPILED_RHS as _rhs
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.sundae import ROOT_RETURN, CompiledCvode, clear_event_records, compiled_cvode_problem

__all__ = ["MomentaryEngine", "compiled_parameters", "COMPILED_RHS", "COMPILED_JACOBIAN", "COMPILED_EVENTS", "SolveIvpEngine", "SOLVE_IVP_METHODS"]

_STATUS_TSTOP, _STATUS_ROOT = 1, 2


def compiled_parameters(model: Model) -> NDArray[np.float64]:
    """A copy of the user data of the compiled callbacks for ``model`` (its mode flags as they are now)."""
    return model.parameters.copy()


#: The compiled callbacks (numba ``cfunc``; ``.address`` for CVODE, ``.ctypes`` to call them from Python).
COMPILED_RHS, COMPILED_JACOBIAN, COMPILED_EVENTS = _rhs, _jacobian, _events


class MomentaryEngine(EventLoopEngine):
    """CVODE (Adams or BDF) with terminal contact/release events and a grazing guard.

    Parameters
    ----------
    settings : EngineSettings
        Tolerances, method, max_step and sticking thresholds.
    grazing_guard : bool
        Check the gap's maximum inside every step (default). Switching it off is for demonstrating what it prevents.
    compiled : bool or None
        Compiled callbacks (True), scikit-sundae's Python callbacks (False), or the compiled ones where they load
        (None, the default).
    """

    name = "momentary"

    def __init__(self, settings: EngineSettings = EngineSettings(), grazing_guard: bool = True, compiled: bool | None = None) -> None:
        super().__init__(settings)
        self.grazing_guard = grazing_guard
        if compiled and compiled_cvode_problem() is not None:
            raise RuntimeError(f"the compiled CVODE binding cannot run here: {compiled_cvode_problem()}")
        self.compiled = compiled_cvode_problem() is None if compiled is None else compiled

    def _begin(self, model: Model) -> None:
        model.apex_event = self.grazing_guard
        # where the integrator stands (its state array) after a boundary return: the next call goes on from there
        self._at_t: float = np.nan
        self._at_y: NDArray[np.float64] | None = None
        self._apexes = self._touches = self._events_found = self._solver_rhs = 0
        if self.compiled:
            # the model's own parameter array: the mode it writes there is what the callbacks read
            self._cvode: CompiledCvode | None = CompiledCvode(
                model.size, self.settings.method, self.settings.rtol, self.settings.atol, _rhs.address, _jacobian.address,
                _events.address, model.directions, model.parameters, self.settings.max_step)
            return
        self._cvode = None
        events = model.events

        def fresh_events(t: float, y: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            events(t, y, out)

        # a function object of its own: scikit-sundae stores the event records on it
        fresh_events.terminal = [True] * model.num_events  # type: ignore[attr-defined]
        fresh_events.direction = list(model.directions)  # type: ignore[attr-defined]
        options: dict[str, Any] = {
            "method": "Adams" if self.settings.method == "adams" else "BDF",
            "rtol": self.settings.rtol,
            "atol": self.settings.atol,
            "max_num_steps": 1_000_000,
            "eventsfn": fresh_events,
            "num_events": model.num_events,
            "jacfn": model.jacobian,
        }
        if self.settings.max_step > 0.0:
            options["max_step"] = self.settings.max_step
        self._events = fresh_events
        self._solver = CVODE(model.rhs, **options)

    def _end(self) -> None:
        if self._cvode is not None:
            self._solver_rhs = self._cvode.total_rhs_evaluations()
            self._cvode.close()
            self._cvode = None
        self._at_t, self._at_y = np.nan, None

    def _counters(self) -> dict[str, int]:
        return {"events": self._events_found, "apex_checks": self._apexes, "tangent_touches": self._touches}

    def _compiled_rhs_calls(self) -> int:
        return self._solver_rhs

    def _advance(self, model: Model, t: float, y: NDArray[np.float64], t_stop: float, outputs: Outputs | None = None) -> tuple[Stop, float, NDArray[np.float64], int]:
        if self._cvode is None:
            return self._advance_python(model, t, y, t_stop, outputs)
        cvode = self._cvode
        if not (self._at_t == t and self._at_y is y):
            cvode.restart(t, y)
        advance, roots, decide = cvode.advance, cvode.roots, self._decide
        while True:
            t_out = outputs.next_time() if outputs is not None else math.inf
            if t_out < t_stop:  # an output time before the boundary: CVODE's interpolation there, or a root before it
                flag, now = advance(t_stop, t_out)
                if flag != ROOT_RETURN:
                    outputs.record(model.layout.physical(cvode.state))  # type: ignore[union-attr]
                    continue
            else:
                flag, now = advance(t_stop)
            if flag != ROOT_RETURN:  # at t_stop (CV_TSTOP_RETURN, or CV_SUCCESS with t_stop = tout)
                state = cvode.state.copy()
                self._at_t, self._at_y = now, state
                return Stop.BOUNDARY, now, state, -1
            found = decide(model, roots(), now, cvode.state)
            if found is not None:
                return found

    def _advance_python(self, model: Model, t: float, y: NDArray[np.float64], t_stop: float, outputs: Outputs | None) -> tuple[Stop, float, NDArray[np.float64], int]:
        if not (self._at_t == t and self._at_y is y):
            clear_event_records(self._events)
            started = self._solver.init_step(t, y)
            if started.status < 0:
                raise RuntimeError(f"CVODE could not start at t = {t!r} s: {started.message}")
        while True:
            t_out = outputs.next_time() if outputs is not None else math.inf
            result = self._solver.step(min(t_out, t_stop), tstop=t_stop)
            if result.status < 0:
                raise RuntimeError(f"CVODE failed at t = {result.t!r} s: {result.message}")
            if t_out < t_stop and result.status != _STATUS_ROOT:  # interpolated at the output time
                outputs.record(model.layout.physical(np.array(result.y)))  # type: ignore[union-attr]
                continue
            if result.status == _STATUS_TSTOP:
                now = np.array(result.y)
                self._at_t, self._at_y = float(result.t), now
                return Stop.BOUNDARY, float(result.t), now, -1
            fired = tuple(int(i) for i in result.i_events[-1])
            clear_event_records(self._events)
            found = self._decide(model, fired, float(result.t), np.array(result.y))
            if found is not None:
                return found

    def _decide(self, model: Model, fired: tuple[int, ...], t: float, state: NDArray[np.float64]) -> tuple[Stop, float, NDArray[np.float64], int] | None:
        """What the roots ``fired`` at (t, state) mean: a contact (the first stop whose penetration rose through 0),
        a release, or an apex; None for an ordinary apex, short of its stop (integrate on)."""
        stops = model.layout.stop_count
        for k in range(stops):
            if fired[k] != 0:
                return self._event(Stop.CONTACT, t, state, k)
        if fired[stops] != 0:
            return self._event(Stop.RELEASE, t, state, model.stuck_on)
        self._apexes += 1
        for k in range(stops):
            # CVODE evaluates every event function at the located apex, so a gap that crossed zero before it would
            # have been returned as the contact; a non-negative penetration here is a tangent touch: a contact at
            # zero speed
            if fired[stops + 1 + k] != 0 and model.layout.penetration(state, k) >= 0.0:
                self._touches += 1
                return self._event(Stop.CONTACT, t, state, k)
        return None  # an ordinary maximum, short of the stop

    def _event(self, kind: Stop, t: float, state: NDArray[np.float64], stop: int) -> tuple[Stop, float, NDArray[np.float64], int]:
        self._events_found += 1
        self._at_t, self._at_y = np.nan, None
        return kind, t, state.copy(), stop


# --------------------------------------------------------------------------------------------------------------------
# Comparison engines: ``scipy.integrate.solve_ivp`` (DOP853, LSODA, Radau, ...) with terminal events and restarts.
# --------------------------------------------------------------------------------------------------------------------

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

    def _advance(self, model: Model, t: float, y: NDArray[np.float64], t_stop: float, outputs: Outputs | None = None) -> tuple[Stop, float, NDArray[np.float64], int]:
        options: dict[str, Any] = {"method": self.method, "rtol": self.settings.rtol, "atol": self.settings.atol}
        if outputs is not None:
            options["dense_output"] = True  # the outputs on the way: the method's own interpolant
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
        if outputs is not None:
            due = outputs.due(float(result.t[-1]))
            if due.size:
                for state in result.sol(due).T:
                    outputs.record(model.layout.physical(state))
        if result.status == 1:
            self._events_found += 1
            for index, times in enumerate(result.t_events):
                if times.size:
                    state = np.array(result.y_events[index][0])
                    if index < len(watched):
                        return Stop.CONTACT, float(times[0]), state, watched[index]
                    return Stop.RELEASE, float(times[0]), state, model.stuck_on
        return Stop.BOUNDARY, float(result.t[-1]), np.array(result.y[:, -1]), -1
