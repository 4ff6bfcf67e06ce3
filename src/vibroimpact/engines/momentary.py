"""Engine ``momentary``: SUNDIALS CVODE (through scikit-sundae) with exact contact events and a grazing guard.

CVODE finds roots only as sign changes between steps, so a nearly tangent contact (the gap's maximum slightly above
zero inside one step) would be missed. The guard: a third event function, the absorber velocity X2' falling through
zero, stops the integrator at every local maximum of X2 in free flight. CVODE locates that root and evaluates all
event functions there, so a gap that is positive at the maximum reveals its own sign change and is returned as the
contact. If the gap at a maximum is negative, integration simply goes on. If a maximum is ever returned with a
non-negative gap but no contact, a contact was stepped over: the integration is replayed from the last restart point
(at most one period back) one step at a time; after each step whose X2' turns from positive to non-positive the
gap's maximum is estimated by cubic Hermite interpolation and, when it comes near the stop, the integrator is driven
exactly to it (with Newton corrections on X2' = 0), where the contact shows up as an ordinary root.

scikit-sundae 1.2.0 facts this relies on (see ``../shared/NOTES.md``): event records accumulate on the event
function and are cleared here after each event; ``direction`` is read at the first ``init_step`` only, so the event
directions are fixed and inactive events return a constant; errors do not raise but return a negative ``status``,
turned into ``RuntimeError`` here. Normal-mode stepping returns to Python only at events and period boundaries.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from sksundae.cvode import CVODE

from .base import EngineSettings
from .event_loop import EventLoopEngine, Model, Stop

__all__ = ["MomentaryEngine"]

_STATUS_TSTOP, _STATUS_ROOT = 1, 2


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
    """

    name = "momentary"

    def __init__(self, settings: EngineSettings = EngineSettings(), grazing_guard: bool = True) -> None:
        super().__init__(settings)
        self.grazing_guard = grazing_guard

    def _begin(self, model: Model) -> None:
        model.apex_event = self.grazing_guard

        def events(t: float, y: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            model.events(t, y, out)

        events.terminal = [True] * Model.NUM_EVENTS  # type: ignore[attr-defined]
        events.direction = list(Model.DIRECTIONS)  # type: ignore[attr-defined]
        options: dict[str, Any] = {
            "method": "Adams" if self.settings.method == "adams" else "BDF",
            "rtol": self.settings.rtol,
            "atol": self.settings.atol,
            "max_num_steps": 1_000_000,
            "eventsfn": events,
            "num_events": Model.NUM_EVENTS,
        }
        if self.settings.max_step > 0.0:
            options["max_step"] = self.settings.max_step
        self._events = events
        self._solver = CVODE(model.rhs, **options)
        self._at = _Position(np.nan, None)
        self._origin = _Position(np.nan, None)
        self._apexes = self._replays = self._grazing_checks = self._rewinds = self._events_found = 0

    def _counters(self) -> dict[str, int]:
        return {
            "events": self._events_found,
            "apex_checks": self._apexes,
            "grazing_replays": self._replays,
            "grazing_checks": self._grazing_checks,
            "grazing_rewinds": self._rewinds,
        }

    def _restart(self, t: float, y: NDArray[np.float64]) -> None:
        _clear_event_records(self._events)
        result = self._solver.init_step(t, y)
        if result.status < 0:
            raise RuntimeError(f"CVODE could not start at t = {t!r} s: {result.message}")

    def _advance(self, model: Model, t: float, y: NDArray[np.float64], t_stop: float) -> tuple[Stop, float, NDArray[np.float64]]:
        if not (self._at.t == t and self._at.y is y):
            self._restart(t, y)
        self._origin = _Position(t, y)
        while True:
            result = self._solver.step(t_stop, tstop=t_stop)
            if result.status < 0:
                raise RuntimeError(f"CVODE failed at t = {result.t!r} s: {result.message}")
            if result.status == _STATUS_TSTOP:
                now = np.array(result.y)
                self._at = _Position(float(result.t), now)
                return Stop.BOUNDARY, float(result.t), now
            fired = np.asarray(result.i_events[-1])
            _clear_event_records(self._events)
            if fired[0] != 0 or fired[1] != 0:
                return self._event(fired, result)
            self._apexes += 1
            if result.y[1] < 0.0 or not self.grazing_guard:
                continue  # an ordinary maximum of X2, short of the stop
            self._replays += 1
            return self._replay(model, t_stop)

    def _event(self, fired: NDArray, result: Any) -> tuple[Stop, float, NDArray[np.float64]]:
        self._events_found += 1
        self._at = _Position(np.nan, None)
        return (Stop.CONTACT if fired[0] != 0 else Stop.RELEASE), float(result.t), np.array(result.y)

    def _replay(self, model: Model, t_stop: float) -> tuple[Stop, float, NDArray[np.float64]]:
        """Integrate again from the last restart point one step at a time, checking the gap inside every step."""
        t, y = self._origin.t, self._origin.y
        assert y is not None
        self._restart(t, y)
        previous_t, previous_y = t, y
        while True:
            result = self._solver.step(t_stop, method="onestep", tstop=t_stop)
            if result.status < 0:
                raise RuntimeError(f"CVODE failed at t = {result.t!r} s: {result.message}")
            now_t, now_y = float(result.t), np.array(result.y)
            if result.status == _STATUS_ROOT:
                fired = np.asarray(result.i_events[-1])
                _clear_event_records(self._events)
                if fired[0] != 0 or fired[1] != 0:
                    return self._event(fired, result)
                if now_y[1] >= 0.0:  # a tangent touch at the apex: contact at zero speed
                    return self._event(np.array([1, 0, 0]), result)
            elif previous_y[3] > 0.0 >= now_y[3]:
                found = self._graze(model, previous_t, previous_y, now_t, now_y)
                if found is not None:
                    if isinstance(found[0], Stop):
                        return found  # type: ignore[return-value]
                    now_t, now_y = found[1], found[2]
                    continue_from_graze = True
                else:
                    continue_from_graze = False
                if not continue_from_graze and result.status == _STATUS_TSTOP:
                    self._at = _Position(now_t, now_y)
                    return Stop.BOUNDARY, now_t, now_y
                previous_t, previous_y = now_t, now_y
                continue
            if result.status == _STATUS_TSTOP:
                self._at = _Position(now_t, now_y)
                return Stop.BOUNDARY, now_t, now_y
            previous_t, previous_y = now_t, now_y

    def _graze(self, model: Model, t0: float, y0: NDArray[np.float64], t1: float, y1: NDArray[np.float64]) -> tuple[Any, float, NDArray[np.float64]] | None:
        """Look for a contact at the gap's maximum inside [t0, t1]; None if there is clearly none.

        Returns a stop triple if a contact was found, else ``(None, t, y)``: the integrator now sits at (t, y).
        """
        self._grazing_checks += 1
        h = t1 - t0
        s = np.linspace(0.0, 1.0, 65)
        hermite = (2 * s**3 - 3 * s**2 + 1) * y0[1] + (s**3 - 2 * s**2 + s) * h * y0[3] + (-2 * s**3 + 3 * s**2) * y1[1] + (s**3 - s**2) * h * y1[3]
        k = int(np.argmax(hermite))
        curvature = abs(model.derivative(t1, y1)[3])
        if hermite[k] < -0.01 * h * h * curvature:  # y[1] is the gap X2 - Delta
            return None
        self._rewinds += 1
        target = t0 + s[k] * h
        t, y = t0, y0
        for _ in range(4):
            if target <= t:  # the maximum lies behind: start again from the step's beginning
                t, y = t0, y0
            self._restart(t, y)
            while True:
                result = self._solver.step(target, method="onestep", tstop=target)
                if result.status < 0:
                    raise RuntimeError(f"CVODE failed at t = {result.t!r} s: {result.message}")
                if result.status == _STATUS_ROOT:
                    fired = np.asarray(result.i_events[-1])
                    _clear_event_records(self._events)
                    if fired[0] != 0 or fired[1] != 0 or result.y[1] >= 0.0:
                        return self._event(np.array([1, 0, 0]) if fired[1] == 0 else fired, result)
                    continue
                if result.status == _STATUS_TSTOP:
                    break
            t, y = float(result.t), np.array(result.y)
            acceleration = model.derivative(t, y)[3]
            if acceleration >= 0.0:
                break
            correction = -y[3] / acceleration
            if abs(correction) <= 1e-12 * h:
                break
            target = t + correction
        self._at = _Position(t, y)
        return None, t, y


def _clear_event_records(events: Any) -> None:
    """Forget the roots recorded on a scikit-sundae event function (they accumulate and slow every step)."""
    for name in ("_i", "_t", "_y"):
        records = getattr(events, name, None)
        if records is not None:
            records.clear()
    counts = getattr(events, "_i_cnt", None)
    if counts is not None:
        counts[:] = 0
