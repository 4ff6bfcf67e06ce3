"""Time histories: x(t) and x'(t) of a run of any engine at chosen times, with the contacts inside their span.

Every registered engine samples its own run (``engine.sample(problem, state, t_start, periods, times)``): ``exact``
evaluates the closed-form flow of each segment of its trajectory (compiled), the integrators record their own
interpolation at the requested times while they run, the events handled as in their ``integrate``. At an event's
time a sample is the state just after it (after the impact, or the strobe state at a period boundary)::

    from vibroimpact import make_engine, time_history
    history = time_history("exact", problem, state, 0.0, np.linspace(0.0, 10 * problem.period, 2001))
    history.displacement[:, 1], history.contact_times

A linear steady state that stays clear of its stops has its history in closed form (:func:`linear_history`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.base import Engine
from vibroimpact.engines.registry import make_engine
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.simulation.harmonics import linear_state

__all__ = ["TimeHistory", "time_history", "linear_history", "engine_of"]


@suggest_keywords
@dataclass(frozen=True, eq=False)
class TimeHistory:
    """A motion sampled at given times, and the contacts inside the sampled span.

    Attributes
    ----------
    time : ndarray, shape (S,)
        Sample times, increasing [s].
    displacement : ndarray, shape (S, N)
        x_1 ... x_N at each sample [m], in the order of ``coordinates`` ((X1, X2) on the paper's system).
    velocity : ndarray, shape (S, N)
        x_1' ... x_N' at each sample [m s-1]; at a contact's time, the velocity just after it.
    contact_times : ndarray, shape (C,)
        Impacts (rigid stops) or contact onsets (bumpers, completed contacts only) in [time[0], time[-1]] [s].
    contact_stops : ndarray of int, shape (C,)
        Index (into the problem's stops) of the stop of each contact.
    contact_velocities : ndarray, shape (C,)
        Approach speed n_k . x' just before each contact, > 0 [m s-1] (the rebound is -R times it on a rigid stop).
    coordinates : tuple of str
        Names of the coordinates, the columns of ``displacement`` and ``velocity``.
    engine : str
        Name of the engine that ran the motion (``"linear"``: the closed-form linear steady state).
    """

    time: NDArray[np.float64]
    displacement: NDArray[np.float64]
    velocity: NDArray[np.float64]
    contact_times: NDArray[np.float64]
    contact_stops: NDArray[np.int64]
    contact_velocities: NDArray[np.float64]
    coordinates: tuple[str, ...]
    engine: str

    def __post_init__(self) -> None:
        samples, size, contacts = np.shape(self.time), len(self.coordinates), np.shape(self.contact_times)
        expected = {
            "displacement": (self.displacement, (*samples, size)),
            "velocity": (self.velocity, (*samples, size)),
            "contact_stops": (self.contact_stops, contacts),
            "contact_velocities": (self.contact_velocities, contacts),
        }
        if len(samples) != 1 or len(contacts) != 1:
            raise ValueError(f"time and contact_times: expected 1-D arrays, got shapes {samples} and {contacts}")
        for name, (value, shape) in expected.items():
            if np.shape(value) != shape:
                raise ValueError(f"{name}: expected shape {shape} ({samples[0]} samples, {size} coordinates, {contacts[0]} contacts), got {np.shape(value)}")
        if np.any(np.diff(self.time) < 0.0):
            raise ValueError("time: expected increasing sample times")
        for name in ("time", "displacement", "velocity", "contact_times", "contact_stops", "contact_velocities"):
            getattr(self, name).setflags(write=False)

    @property
    def states(self) -> NDArray[np.float64]:
        """(x, x') at each sample, shape (S, 2 N) [m, m s-1] (the layout of a trajectory's strobe states)."""
        return np.hstack([self.displacement, self.velocity])

    def coordinate(self, name: str) -> NDArray[np.float64]:
        """The displacement of one coordinate by name [m] (``ValueError`` naming the coordinates if it has none)."""
        if name not in self.coordinates:
            raise ValueError(f"coordinate = {name!r} is not a coordinate of the structure: allowed {', '.join(self.coordinates)}")
        return self.displacement[:, self.coordinates.index(name)]


def engine_of(engine: Engine | str) -> Any:
    """``engine`` itself, or the registered engine of that name with default settings (``ValueError`` naming the
    registered engines for an unknown name)."""
    if isinstance(engine, str):
        return make_engine(engine)
    if not hasattr(engine, "integrate"):
        raise TypeError(f"engine = {engine!r} is neither an engine nor the name of a registered one")
    return engine


def _periods(problem: ImpactProblem, t_start: float, t_last: float) -> int:
    """Whole periods (at least one) from t_start that reach t_last, on the engines' own boundaries t_start + k T."""
    periods = max(1, math.ceil((t_last - t_start) / problem.period * (1.0 - 1e-12)))
    while t_start + periods * problem.period < t_last:
        periods += 1
    return periods


@suggest_keywords
def time_history(engine: Engine | str, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, times: NDArray[np.float64]) -> TimeHistory:
    """The motion from ``state`` at ``t_start``, sampled at ``times``.

    Parameters
    ----------
    engine : Engine or str
        An engine, or the name of a registered one (built with default settings).
    problem : ImpactProblem
        Structure, stops and harmonic excitation.
    state : ndarray, shape (2 N,)
        (x_1 ... x_N, x_1' ... x_N') at ``t_start`` [m, m s-1].
    t_start : float
        Start of the run [s].
    times : array_like, shape (S,)
        Increasing sample times >= ``t_start`` [s]; the run covers the whole periods that reach the last.

    Returns
    -------
    TimeHistory
        The samples (at an event's time, the state just after it) and the contacts in [times[0], times[-1]].
    """
    engine = engine_of(engine)
    times = np.array(times, dtype=float).reshape(-1)
    t_start = float(t_start)
    if times.size == 0:
        raise ValueError("times: expected at least one sample time")
    if np.any(np.diff(times) < 0.0) or times[0] < t_start:
        raise ValueError(f"times: expected increasing times from t_start = {t_start!r} s on, got [{times.min()!r}, {times.max()!r}] s")
    if not hasattr(engine, "sample"):
        raise TypeError(f"engine {getattr(engine, 'name', engine)!r} cannot sample its runs (it has no sample method)")
    trajectory, states = engine.sample(problem, np.asarray(state, dtype=float), t_start, _periods(problem, t_start, float(times[-1])), times)
    inside = (trajectory.impact_times >= times[0]) & (trajectory.impact_times <= times[-1])
    n = problem.size
    return TimeHistory(
        time=times,
        displacement=np.array(states[:, :n]),
        velocity=np.array(states[:, n : 2 * n]),
        contact_times=trajectory.impact_times[inside].copy(),
        contact_stops=trajectory.impact_stops[inside].copy(),
        contact_velocities=trajectory.impact_velocities[inside].copy(),
        coordinates=tuple(problem.structure.coordinates),
        engine=str(getattr(engine, "name", type(engine).__name__)),
    )


def linear_history(problem: ImpactProblem, times: NDArray[np.float64]) -> TimeHistory:
    """The linear steady state without stops, x(t) = x0 + Re(X e^{j w t}), at ``times`` [s] (closed form, no
    contacts): the history of a steady state answered without integrating (it stays clear of every stop)."""
    times = np.array(times, dtype=float).reshape(-1)
    linear = linear_state(problem)
    phasor = np.exp(1j * problem.omega * times)[:, None] * linear.amplitudes[None, :]
    empty = np.zeros(0)
    return TimeHistory(
        time=times,
        displacement=linear.offset[None, :] + phasor.real,
        velocity=(1j * problem.omega * phasor).real,
        contact_times=empty,
        contact_stops=np.zeros(0, dtype=np.int64),
        contact_velocities=empty.copy(),
        coordinates=tuple(problem.structure.coordinates),
        engine="linear",
    )
