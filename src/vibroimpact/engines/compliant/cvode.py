"""The compliant-bumper model of :mod:`.model` (engine :mod:`.ida`) through SUNDIALS CVODE instead of IDA.

Same model, events and bookkeeping (contact-mode flag, onset and release, recorded force and deceleration peaks,
grazing apex check); only the integrator differs: the residual y' - f(t, y) of each mode is turned into the
right-hand side f, the event functions get the y' they need from f, and CVODE (Adams or BDF, no Jacobian callback:
Adams needs none, BDF uses difference quotients) advances it. It serves as the independent-integrator reference and
as a point of comparison in the accuracy-and-cost study.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray
from sksundae.cvode import CVODE

from vibroimpact.engines.compliant.ida import CompliantEngine
from vibroimpact.engines.compliant.model import BumperModel, absolute_tolerances
from vibroimpact.engines.settings import EngineSettings

__all__ = ["CompliantCvodeEngine"]


class CompliantCvodeEngine(CompliantEngine):
    """The Kelvin-Voigt bumper through CVODE (``settings.method``: ``adams`` or ``bdf``); see :class:`CompliantEngine`."""

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        super().__init__(settings)
        self.name = f"compliant_cvode_{settings.method}"

    def solve(self, solver: Any, tspan: NDArray[np.float64], y0: NDArray[np.float64], yp0: NDArray[np.float64]) -> Any:
        """One CVODE call over ``tspan`` (an ODE solver needs no y0')."""
        return solver.solve(tspan, y0)

    def _solver(self, model: BumperModel, contact: int, omega_ref: float) -> tuple[Any, Any]:
        residual = model.residual(contact)
        zero = np.zeros(model.size)

        def rhs(t: float, y: NDArray[np.float64], yp: NDArray[np.float64]) -> None:
            residual(t, y, zero, yp)  # yp <- 0 - f(t, y)
            np.negative(yp, out=yp)

        events = model.events(contact)
        derivative = np.empty(model.size)

        def cvode_events(t: float, y: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            rhs(t, y, derivative)
            events(t, y, derivative, out)

        cvode_events.terminal = events.terminal  # type: ignore[attr-defined]
        cvode_events.direction = events.direction  # type: ignore[attr-defined]
        options: dict[str, Any] = {
            "method": "Adams" if self.settings.method == "adams" else "BDF",
            "rtol": self.settings.rtol,
            "atol": absolute_tolerances(self.settings.atol, omega_ref, model.layout.masses, model.quadratures, model.layout.size),
            "max_num_steps": 1_000_000,
            "eventsfn": cvode_events,
            "num_events": model.event_count(contact),
            "first_step": self.first_step(model, contact, omega_ref),  # CVODE's own guess collapsed at contact onsets
        }
        if self.settings.max_step > 0.0:
            options["max_step"] = self.settings.max_step
            options["first_step"] = min(options["first_step"], self.settings.max_step)
        return CVODE(rhs, **options), cvode_events
