"""Engine ``momentary``: SUNDIALS CVODE (the one scikit-sundae ships) with exact contact events and a grazing guard.

CVODE finds roots only as sign changes between steps, so a nearly tangent contact (the gap's maximum slightly above
zero inside one step) would be missed. The guard: a third event function, the absorber velocity X2' falling through
zero, stops the integrator at every local maximum of X2 in free flight. CVODE locates that root and evaluates all
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
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import carray, cfunc, types
from numpy.typing import NDArray
from sksundae.cvode import CVODE

from vibroimpact.engines.event_loop import EventLoopEngine, Model, Stop
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.sundae import ROOT_RETURN, CompiledCvode, as_doubles, clear_event_records, compiled_cvode_problem, content_data

__all__ = ["MomentaryEngine", "compiled_parameters", "COMPILED_RHS", "COMPILED_JACOBIAN", "COMPILED_EVENTS"]

_STATUS_TSTOP = 1
# layout of the compiled callbacks' user data: mode flags, state size, then Model.coefficients()
_STUCK, _APEX, _SIZE, _FIRST = 0, 1, 2, 3
_A20, _A21, _A22, _A23, _A30, _A31, _A32, _A33, _C2, _C3, _F2, _W, _PHASE, _DELTA, _K2, _B2 = range(_FIRST, _FIRST + 16)
_PARAMETERS = _FIRST + 16


def compiled_parameters(model: Model) -> NDArray[np.float64]:
    """The user data of the compiled callbacks for ``model`` (its mode flags must be copied in before each use)."""
    return np.array([float(model.stuck), float(model.apex_event), float(model.size), *model.coefficients()])


@cfunc(types.intc(types.float64, types.voidptr, types.voidptr, types.voidptr), cache=True)
def _rhs(t: float, y_vector: Any, yp_vector: Any, data: Any) -> int:  # pragma: no cover - compiled
    p = carray(as_doubles(data), (_PARAMETERS,))
    size = int(p[_SIZE])
    y, yp = carray(content_data(y_vector), (size,)), carray(content_data(yp_vector), (size,))
    x1, u, v1, v2 = y[0], y[1], y[2], y[3]
    forcing = p[_C2] + p[_F2] * math.cos(p[_W] * t + p[_PHASE])
    stuck = p[_STUCK] != 0.0
    yp[0] = v1
    if stuck:
        yp[1] = 0.0
        yp[2] = p[_A20] * x1 + p[_A22] * v1 + forcing
        yp[3] = 0.0
    else:
        yp[1] = v2
        yp[2] = p[_A20] * x1 + p[_A21] * u + p[_A22] * v1 + p[_A23] * v2 + forcing
        yp[3] = p[_A30] * x1 + p[_A31] * u + p[_A32] * v1 + p[_A33] * v2 + p[_C3]
    if size > 4:  # the eight moment quadratures (see event_loop.write_quadratures)
        x2 = u + p[_DELTA]
        holding = p[_B2] * v1 + p[_K2] * (x1 - p[_DELTA]) if stuck else 0.0
        c, s = math.cos(p[_W] * t), math.sin(p[_W] * t)
        yp[4], yp[5], yp[6], yp[7] = x1 * c, x1 * s, x2 * c, x2 * s
        yp[8], yp[9], yp[10], yp[11] = holding * c, holding * s, x1 * x1, x2 * x2
    return 0


@cfunc(types.intc(types.float64, types.voidptr, types.voidptr, types.voidptr, types.voidptr, types.voidptr, types.voidptr, types.voidptr), cache=True)
def _jacobian(t: float, y_vector: Any, f_vector: Any, matrix: Any, data: Any, tmp1: Any, tmp2: Any, tmp3: Any) -> int:  # pragma: no cover
    p = carray(as_doubles(data), (_PARAMETERS,))
    size = int(p[_SIZE])
    jac = carray(content_data(matrix), (size, size))  # column-major: jac[j, i] = d y'_i / d y_j
    jac[:, :] = 0.0
    stuck = p[_STUCK] != 0.0
    jac[2, 0] = 1.0
    jac[0, 2], jac[2, 2] = p[_A20], p[_A22]
    if not stuck:
        jac[3, 1] = 1.0
        jac[1, 2], jac[3, 2] = p[_A21], p[_A23]
        jac[0, 3], jac[1, 3], jac[2, 3], jac[3, 3] = p[_A30], p[_A31], p[_A32], p[_A33]
    if size > 4:
        y = carray(content_data(y_vector), (size,))
        c, s = math.cos(p[_W] * t), math.sin(p[_W] * t)
        jac[0, 4], jac[0, 5], jac[1, 6], jac[1, 7] = c, s, c, s
        if stuck:
            jac[0, 8], jac[2, 8], jac[0, 9], jac[2, 9] = p[_K2] * c, p[_B2] * c, p[_K2] * s, p[_B2] * s
        jac[0, 10], jac[1, 11] = 2.0 * y[0], 2.0 * (y[1] + p[_DELTA])
    return 0


@cfunc(types.intc(types.float64, types.voidptr, types.CPointer(types.float64), types.voidptr), cache=True)
def _events(t: float, y_vector: Any, out: Any, data: Any) -> int:  # pragma: no cover - compiled
    p = carray(as_doubles(data), (_PARAMETERS,))
    y = carray(content_data(y_vector), (4,))
    if p[_STUCK] != 0.0:
        out[0], out[1], out[2] = -1.0, p[_B2] * y[2] + p[_K2] * (y[0] - p[_DELTA]), 1.0
    else:
        out[0], out[1], out[2] = y[1], 1.0, (y[3] if p[_APEX] != 0.0 else 1.0)
    return 0


#: The compiled callbacks (numba ``cfunc``; ``.address`` for CVODE, ``.ctypes`` to call them from Python).
COMPILED_RHS, COMPILED_JACOBIAN, COMPILED_EVENTS = _rhs, _jacobian, _events


@dataclass(frozen=True)
class _Position:
    t: float
    y: NDArray[np.float64] | None


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
        self._at = _Position(np.nan, None)
        self._apexes = self._touches = self._events_found = self._solver_rhs = 0
        if self.compiled:
            self._parameters = compiled_parameters(model)
            self._cvode: CompiledCvode | None = CompiledCvode(
                model.size, self.settings.method, self.settings.rtol, self.settings.atol, _rhs.address, _jacobian.address,
                _events.address, Model.DIRECTIONS, self._parameters, self.settings.max_step)
            return
        self._cvode = None
        events = model.events

        def fresh_events(t: float, y: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            events(t, y, out)

        # a function object of its own: scikit-sundae stores the event records on it
        fresh_events.terminal = [True] * Model.NUM_EVENTS  # type: ignore[attr-defined]
        fresh_events.direction = list(Model.DIRECTIONS)  # type: ignore[attr-defined]
        options: dict[str, Any] = {
            "method": "Adams" if self.settings.method == "adams" else "BDF",
            "rtol": self.settings.rtol,
            "atol": self.settings.atol,
            "max_num_steps": 1_000_000,
            "eventsfn": fresh_events,
            "num_events": Model.NUM_EVENTS,
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
        self._at = _Position(np.nan, None)

    def _counters(self) -> dict[str, int]:
        return {"events": self._events_found, "apex_checks": self._apexes, "tangent_touches": self._touches}

    def _compiled_rhs_calls(self) -> int:
        return self._solver_rhs

    def _advance(self, model: Model, t: float, y: NDArray[np.float64], t_stop: float) -> tuple[Stop, float, NDArray[np.float64]]:
        if self._cvode is None:
            return self._advance_python(t, y, t_stop)
        cvode = self._cvode
        self._parameters[_STUCK] = 1.0 if model.stuck else 0.0
        if not (self._at.t == t and self._at.y is y):
            cvode.restart(t, y)
        while True:
            flag, now = cvode.advance(t_stop)
            if flag != ROOT_RETURN:  # at t_stop (CV_TSTOP_RETURN, or CV_SUCCESS with t_stop = tout)
                state = cvode.state.copy()
                self._at = _Position(now, state)
                return Stop.BOUNDARY, now, state
            fired = cvode.roots()
            if fired[0] != 0 or fired[1] != 0:
                return self._event(fired, now, cvode.state.copy())
            self._apexes += 1
            if cvode.state[1] < 0.0:
                continue  # an ordinary maximum of X2, short of the stop
            # CVODE evaluates every event function at the located apex, so a gap that crossed zero before it would
            # have been returned as the contact; a non-negative gap here is a tangent touch: a contact at zero speed
            self._touches += 1
            return self._event((1, 0, 0), now, cvode.state.copy())

    def _advance_python(self, t: float, y: NDArray[np.float64], t_stop: float) -> tuple[Stop, float, NDArray[np.float64]]:
        if not (self._at.t == t and self._at.y is y):
            clear_event_records(self._events)
            started = self._solver.init_step(t, y)
            if started.status < 0:
                raise RuntimeError(f"CVODE could not start at t = {t!r} s: {started.message}")
        while True:
            result = self._solver.step(t_stop, tstop=t_stop)
            if result.status < 0:
                raise RuntimeError(f"CVODE failed at t = {result.t!r} s: {result.message}")
            if result.status == _STATUS_TSTOP:
                now = np.array(result.y)
                self._at = _Position(float(result.t), now)
                return Stop.BOUNDARY, float(result.t), now
            fired = tuple(int(i) for i in result.i_events[-1])
            clear_event_records(self._events)
            if fired[0] != 0 or fired[1] != 0:
                return self._event(fired, float(result.t), np.array(result.y))
            self._apexes += 1
            if result.y[1] < 0.0:
                continue
            self._touches += 1
            return self._event((1, 0, 0), float(result.t), np.array(result.y))

    def _event(self, fired: tuple[int, ...], t: float, state: NDArray[np.float64]) -> tuple[Stop, float, NDArray[np.float64]]:
        self._events_found += 1
        self._at = _Position(np.nan, None)
        return (Stop.CONTACT if fired[0] != 0 else Stop.RELEASE), t, state
