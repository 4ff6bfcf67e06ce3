"""Engine ``momentary``: SUNDIALS CVODE (through scikit-sundae) with exact contact events and a grazing guard.

CVODE finds roots only as sign changes between steps, so a nearly tangent contact (the gap's maximum slightly above
zero inside one step) would be missed. The guard: a third event function, the absorber velocity X2' falling through
zero, stops the integrator at every local maximum of X2 in free flight. CVODE locates that root and evaluates all
event functions there, so a gap that is positive at the maximum reveals its own sign change and is returned as the
contact. A maximum with a negative gap is passed over; one with a gap of exactly zero is a tangent touch, handled
as a contact at zero speed.

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

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.sundae import clear_event_records
from vibroimpact.engines.event_loop import EventLoopEngine, Model, Stop

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
        self._apexes = self._touches = self._events_found = 0

    def _counters(self) -> dict[str, int]:
        return {"events": self._events_found, "apex_checks": self._apexes, "tangent_touches": self._touches}

    def _restart(self, t: float, y: NDArray[np.float64]) -> None:
        clear_event_records(self._events)
        result = self._solver.init_step(t, y)
        if result.status < 0:
            raise RuntimeError(f"CVODE could not start at t = {t!r} s: {result.message}")

    def _advance(self, model: Model, t: float, y: NDArray[np.float64], t_stop: float) -> tuple[Stop, float, NDArray[np.float64]]:
        if not (self._at.t == t and self._at.y is y):
            self._restart(t, y)
        while True:
            result = self._solver.step(t_stop, tstop=t_stop)
            if result.status < 0:
                raise RuntimeError(f"CVODE failed at t = {result.t!r} s: {result.message}")
            if result.status == _STATUS_TSTOP:
                now = np.array(result.y)
                self._at = _Position(float(result.t), now)
                return Stop.BOUNDARY, float(result.t), now
            fired = np.asarray(result.i_events[-1])
            clear_event_records(self._events)
            if fired[0] != 0 or fired[1] != 0:
                return self._event(fired, result)
            self._apexes += 1
            if result.y[1] < 0.0:
                continue  # an ordinary maximum of X2, short of the stop
            # CVODE evaluates every event function at the located apex, so a gap that crossed zero before it would
            # have been returned as the contact; a non-negative gap here is a tangent touch: a contact at zero speed
            self._touches += 1
            return self._event(np.array([1, 0, 0]), result)

    def _event(self, fired: NDArray, result: Any) -> tuple[Stop, float, NDArray[np.float64]]:
        self._events_found += 1
        self._at = _Position(np.nan, None)
        return (Stop.CONTACT if fired[0] != 0 else Stop.RELEASE), float(result.t), np.array(result.y)
