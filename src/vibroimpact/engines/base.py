"""What every engine shares: the records it returns (trajectory, swept-sine record), the protocols of the stepping
and the sweeping engines, and the checks every run starts with."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.registry import Capabilities
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.problem import Contact, ImpactProblem

__all__ = ["Trajectory", "TrajectoryBuilder", "SweepRecord", "Engine", "SweepingEngine", "check_run", "start_state", "MODE_FREE", "MODE_STUCK"]

#: Segment modes of a trajectory.
MODE_FREE, MODE_STUCK = 0, 1


@suggest_keywords
@dataclass(frozen=True, eq=False)
class Trajectory:
    """Immutable record of an integration over whole periods from ``t_start``.

    Attributes
    ----------
    problem : ImpactProblem
        What was integrated.
    strobe_times : ndarray, shape (n + 1,)
        t_start + k T [s], k = 0 ... n.
    strobe_states : ndarray, shape (n + 1, 2 N)
        (x_1 ... x_N, x_1' ... x_N') at the strobe times [m, m s-1] (after any impact at that instant); for the paper's
        system (X1, X2, X1', X2').
    impact_times : ndarray
        Times of the impacts [s].
    impact_velocities : ndarray
        Approach speed of the stop's coordinate just before each impact, n . x'(t-) > 0 [m s-1] (the absorber's
        velocity for the paper's stop).
    impulses : ndarray
        Impulse of each impact [N s]: m_eff (1 + R) v, or m_eff v for the impact that ends a chattering sequence in
        sticking (m_eff = M2 for the paper's stop, see :class:`~vibroimpact.model.contact.Stop`).
    segments : ndarray, shape (s, 3)
        Rows (start [s], end [s], mode): ``MODE_FREE`` flight or ``MODE_STUCK`` (a stop held closed).
    segment_states : ndarray, shape (s, 2 N)
        State at the start of each segment (after the event that began it).
    moments : ndarray of complex, shape (n, 2 N + K) or (0, 2 N + K)
        Per period, when requested: integrals of x_i e^{-jwt} for each coordinate [m s], of each stop's contact force
        e^{-jwt} (impulses plus holding force while stuck) [N s], and of x_i^2 [m2 s] (real); for the paper's system
        (X1, X2, F, X1^2, X2^2).
    contact_peaks : ndarray, shape (c, 2)
        Compliant contacts only: largest contact force [N] and largest absorber deceleration [m s-2] of each contact.
    stats : dict
        Engine counters (steps, rhs calls, events, grazing checks ...).
    strobe_jacobians : ndarray, shape (n, 2 N, 2 N) or (0, 2 N, 2 N)
        ``exact`` engine on request: entry k is the exact Jacobian of period k's stroboscopic map, d y_{k+1} / d y_k.
    impact_stops : ndarray of int
        Index (into ``problem.stops``) of the stop of each impact.
    segment_stops : ndarray of int, shape (s,)
        Index of the stop held closed in each ``MODE_STUCK`` segment (or in contact, for a compliant engine), -1 in
        free flight.
    contact_peak_stops : ndarray of int, shape (c,)
        Index of the stop of each row of ``contact_peaks``.
    """

    problem: ImpactProblem
    strobe_times: NDArray[np.float64]
    strobe_states: NDArray[np.float64]
    impact_times: NDArray[np.float64]
    impact_velocities: NDArray[np.float64]
    impulses: NDArray[np.float64]
    segments: NDArray[np.float64]
    segment_states: NDArray[np.float64]
    moments: NDArray[np.complex128]
    contact_peaks: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 2)))
    stats: dict[str, int] = field(default_factory=dict)
    strobe_jacobians: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 4, 4)))
    impact_stops: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    segment_stops: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    contact_peak_stops: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def __post_init__(self) -> None:
        # engines that know one stop only leave the stop indices empty: every impact, stuck segment and peak is stop 0
        if self.impact_stops.size != self.impact_times.size:
            object.__setattr__(self, "impact_stops", np.zeros(self.impact_times.size, dtype=np.int64))
        if self.segment_stops.size != self.segments.shape[0]:
            stuck = self.segments[:, 2] == MODE_STUCK if self.segments.size else np.zeros(0, dtype=bool)
            object.__setattr__(self, "segment_stops", np.where(stuck, 0, -1).astype(np.int64))
        if self.contact_peak_stops.size != self.contact_peaks.shape[0]:
            object.__setattr__(self, "contact_peak_stops", np.zeros(self.contact_peaks.shape[0], dtype=np.int64))
        for name in (
            "strobe_times", "strobe_states", "impact_times", "impact_velocities", "impulses", "segments", "segment_states", "moments",
            "contact_peaks", "strobe_jacobians", "impact_stops", "segment_stops", "contact_peak_stops",
        ):  # fmt: skip
            getattr(self, name).setflags(write=False)

    @property
    def periods(self) -> int:
        """Number of whole periods integrated."""
        return self.strobe_times.size - 1

    @property
    def final_state(self) -> NDArray[np.float64]:
        """State at the last strobe time."""
        return self.strobe_states[-1]

    @property
    def stuck_time(self) -> float:
        """Total time spent stuck at the stop [s]."""
        stuck = self.segments[:, 2] == MODE_STUCK
        return float(np.sum(self.segments[stuck, 1] - self.segments[stuck, 0]))


class TrajectoryBuilder:
    """Accumulates what an engine finds while it integrates; :meth:`build` freezes it into a :class:`Trajectory`.

    Engines report physical states (x, x'), segment starts, impacts, moments of the running period and strobes;
    segment ends are the next segment's start (or the last strobe), so zero-length segments vanish.
    """

    def __init__(self, problem: ImpactProblem, moments: bool) -> None:
        self.problem, self.moments = problem, moments
        self.size, self.stop_count = problem.size, len(problem.stops)
        #: columns of a period's moments: coordinates, contact forces per stop, squares of the coordinates
        self.width = 2 * self.size + self.stop_count
        self._strobe_times: list[float] = []
        self._strobe_states: list[NDArray[np.float64]] = []
        self._impacts: list[tuple[float, float, float]] = []
        self._impact_stops: list[int] = []
        self._segments: list[tuple[float, int]] = []
        self._segment_stops: list[int] = []
        self._segment_states: list[NDArray[np.float64]] = []
        self._period_moments: list[NDArray[np.complex128]] = []
        self._peaks: list[tuple[float, float]] = []
        self._peak_stops: list[int] = []
        self._current = np.zeros(self.width, dtype=complex)
        self.stats: dict[str, int] = {"impacts": 0, "sticks": 0, "releases": 0}

    def impact(self, t: float, velocity: float, impulse: float, in_moments: bool = True, stop: int = 0) -> None:
        """An impact on stop ``stop`` at time t [s] with approach velocity [m s-1] and impulse [N s].

        A momentary impulse's Fourier term is added to the stop's contact-force moment; a compliant contact's force
        is integrated continuously instead (``in_moments=False``).
        """
        self._impacts.append((t, velocity, impulse))
        self._impact_stops.append(stop)
        self.stats["impacts"] += 1
        if self.moments and in_moments:
            self._current[self.size + stop] += impulse * complex(math.cos(self.problem.omega * t), -math.sin(self.problem.omega * t))

    def contact_peaks(self, force: float, acceleration: float, stop: int = 0) -> None:
        """Largest contact force [N] and deceleration of the stopped coordinate [m s-2] of the last compliant contact."""
        self._peaks.append((force, acceleration))
        self._peak_stops.append(stop)

    def segment(self, t: float, mode: int, state: NDArray[np.float64], stop: int = -1) -> None:
        """A new segment (``MODE_FREE``, or ``MODE_STUCK`` on stop ``stop``) starts at time t [s] in ``state``."""
        self._segments.append((t, mode))
        self._segment_stops.append(stop if mode == MODE_STUCK and stop >= 0 else (0 if mode == MODE_STUCK else -1))
        self._segment_states.append(np.array(state[: 2 * self.size], dtype=float))

    def add_moments(self, values: NDArray[np.complex128]) -> None:
        """Add integrals (coordinates and contact forces times e^{-jwt}; squares of the coordinates) to the running
        period, shape (2 N + K,)."""
        self._current += values

    def strobe(self, t: float, state: NDArray[np.float64]) -> None:
        """A period boundary at time t [s]: record the state and close the running period's moments."""
        if self._strobe_times and self.moments:
            self._period_moments.append(self._current)
            self._current = np.zeros(self.width, dtype=complex)
        self._strobe_times.append(t)
        self._strobe_states.append(np.array(state[: 2 * self.size], dtype=float))

    def build(self, stats: dict[str, int] | None = None) -> Trajectory:
        """The immutable trajectory, with ``stats`` merged into the builder's counters."""
        starts = np.array([s[0] for s in self._segments])
        ends = np.append(starts[1:], self._strobe_times[-1]) if starts.size else starts
        keep = ends > starts
        impacts = np.array(self._impacts, dtype=float).reshape(-1, 3)
        states = 2 * self.size
        return Trajectory(
            problem=self.problem,
            strobe_times=np.array(self._strobe_times),
            strobe_states=np.array(self._strobe_states).reshape(-1, states),
            impact_times=impacts[:, 0].copy(),
            impact_velocities=impacts[:, 1].copy(),
            impulses=impacts[:, 2].copy(),
            segments=np.column_stack([starts, ends, [s[1] for s in self._segments]]).reshape(-1, 3)[keep],
            segment_states=np.array(self._segment_states).reshape(-1, states)[keep],
            moments=np.array(self._period_moments, dtype=complex).reshape(-1, self.width),
            contact_peaks=np.array(self._peaks, dtype=float).reshape(-1, 2),
            stats=self.stats | (stats or {}),
            impact_stops=np.array(self._impact_stops, dtype=np.int64),
            segment_stops=np.array(self._segment_stops, dtype=np.int64)[keep] if keep.size else np.zeros(0, dtype=np.int64),
            contact_peak_stops=np.array(self._peak_stops, dtype=np.int64),
        )


@dataclass(frozen=True, eq=False)
class SweepRecord:
    """A swept-sine run, sampled uniformly in time: every coordinate of any structure and each stop's contact force.

    Attributes
    ----------
    sweep : SweptSine
        The excitation.
    time : ndarray, shape (S,)
        Sample times [s].
    displacements : ndarray, shape (S, N)
        x_1 ... x_N at each sample [m], in the order of the structure's coordinates (``trajectory.problem``;
        (X1, X2) for the paper's system); :meth:`displacement` picks one by name.
    base_force : ndarray, shape (S,)
        Force on the base [N]: through the springs and dashpots, 1^T (K x + C x'), plus each absolute stop's
        (1^T n_k) lambda_k (the paper's K1 X1 + B1 X1' + F).
    contact_forces : ndarray, shape (S, K)
        Bumper force lambda_k of each stop [N] (0 outside its contact).
    trajectory : Trajectory
        Contacts: ``impact_times`` (onsets) [s], ``impact_velocities`` [m s-1], ``impulses`` [N s] and
        ``contact_peaks`` (c, 2) = [peak force N, peak deceleration m s-2], one row per completed contact with its
        stop in ``impact_stops`` and ``contact_peak_stops`` (a contact still open at the end is counted in
        ``stats["contacts"]`` only); ``segments`` (free and contact); ``stats``: ``steps`` (step attempts),
        ``rhs_calls`` (residual or right-hand-side evaluations), ``contacts``, ``events`` (roots handled),
        ``solver_calls``, ``grazing`` (contacts caught at an apex).
    contact_fourier : ndarray of complex, shape (S, K)
        Running integral of lambda_k exp(-j theta) theta' dt from t = 0 to each sample, per stop [N], integrated with
        the motion: its increase over a window of whole cycles, divided by pi times the cycles, is the bumper force's
        fundamental.
    """

    sweep: SweptSine
    time: NDArray[np.float64]
    displacements: NDArray[np.float64]
    base_force: NDArray[np.float64]
    contact_forces: NDArray[np.float64]
    trajectory: Trajectory
    contact_fourier: NDArray[np.complex128]

    def __post_init__(self) -> None:
        samples = np.shape(self.time)
        problem = self.trajectory.problem
        expected = {
            "time": ((samples[0],) if len(samples) == 1 else None, self.time),
            "displacements": ((*samples, problem.size), self.displacements),
            "base_force": (samples, self.base_force),
            "contact_forces": ((*samples, len(problem.stops)), self.contact_forces),
            "contact_fourier": ((*samples, len(problem.stops)), self.contact_fourier),
        }
        for name, (shape, value) in expected.items():
            if shape is None or np.shape(value) != shape:
                raise ValueError(f"{name}: expected shape {shape or '(S,)'} (S samples, N = {problem.size} coordinates, K = {len(problem.stops)} stops), got {np.shape(value)}")

    @property
    def coordinates(self) -> tuple[str, ...]:
        """Names of the coordinates, in the order of the columns of :attr:`displacements`."""
        return tuple(self.trajectory.problem.structure.coordinates)

    def displacement(self, coordinate: str) -> NDArray[np.float64]:
        """The samples of one coordinate by name [m] (``ValueError`` naming the coordinates if it has none)."""
        names = self.coordinates
        if coordinate not in names:
            raise ValueError(f"coordinate = {coordinate!r} is not a coordinate of the structure: allowed {', '.join(names)}")
        return self.displacements[:, names.index(coordinate)]


class Engine(Protocol):
    """A time-domain solver of an :class:`ImpactProblem` with a harmonic force, period by period."""

    name: str
    #: what it can do (its registry row's; code asks these, never the name)
    capabilities: Capabilities

    def integrate(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` at ``t_start``."""
        ...

    def sample(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, times: NDArray[np.float64]) -> tuple[Trajectory, NDArray[np.float64]]:
        """Integrate as :meth:`integrate` and give the states (x, x') at ``times`` [s] (increasing, inside the run),
        shape (len(times), 2 N) [m, m s-1]: exact where the flow is closed form, else the integrator's own
        interpolation; at an event's time the state just after it (:func:`vibroimpact.simulation.history.time_history`)."""
        ...


class SweepingEngine(Protocol):
    """A time-domain solver of an :class:`ImpactProblem` with a :class:`SweptSine` excitation, start to end."""

    name: str
    capabilities: Capabilities

    def sweep(
        self, problem: ImpactProblem, sample_rate: float, state: NDArray[np.float64] | None = None, progress: Callable[[float], None] | None = None
    ) -> SweepRecord:
        """Run the whole sweep from ``state`` (rest by default) at t = 0, sampled at ``sample_rate`` [Hz];
        ``progress`` receives the simulated time reached [s]."""
        ...


def check_run(engine: str, problem: ImpactProblem, contact: type[Contact], periods: int = 0) -> None:
    """What every run checks first: a whole number of periods >= 0, and a contact law the engine solves.

    Parameters
    ----------
    engine : str
        Name of the engine, for the message.
    problem : ImpactProblem
        The problem to run.
    contact : type
        :class:`RigidStop` or :class:`KelvinVoigtBumper`: the contact law of the engine.
    periods : int
        Periods to integrate.
    """
    if periods < 0:
        raise ValueError(f"periods = {periods} is out of range: allowed [0, inf)")
    for k, stop in enumerate(problem.stops):
        if not isinstance(stop.law, contact):
            raise TypeError(f"engine {engine!r} solves a {contact.__name__}, not stop {k}'s contact = {stop.law!r}")


def start_state(problem: ImpactProblem, state: NDArray[np.float64], t_start: float) -> NDArray[np.float64]:
    """``state`` (x, x') as a writable C-ordered copy, after checking it and ``t_start`` [s] as every run does first: 2 N
    finite values and a finite time (a NaN or an infinity would make an event loop search for ever).

    Raises
    ------
    ValueError
        Naming ``state`` or ``t_start`` and what is wrong with it.
    """
    values = np.array(state, dtype=float, order="C")  # a writable copy: one compiled overload (a read-only array would compile another)
    if values.shape != (2 * problem.size,):
        raise ValueError(f"state: expected {2 * problem.size} values (x and x' of {problem.size} coordinates), got shape {values.shape}")
    if not np.all(np.isfinite(values)):
        bad = int(np.flatnonzero(~np.isfinite(values))[0])
        raise ValueError(f"state: expected finite values [m, m s-1], got {values[bad]!r} at index {bad}")
    if not math.isfinite(float(t_start)):
        raise ValueError(f"t_start = {float(t_start)!r} s: expected a finite time")
    return values
