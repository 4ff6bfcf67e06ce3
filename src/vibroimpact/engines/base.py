"""What every engine shares: the records it returns (trajectory, swept-sine record), the protocols of the stepping
and the sweeping engines, and the checks every run starts with."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import Contact, ImpactProblem

__all__ = ["Trajectory", "TrajectoryBuilder", "SweepRecord", "Engine", "SweepingEngine", "check_run", "MODE_FREE", "MODE_STUCK"]

#: Segment modes of a trajectory.
MODE_FREE, MODE_STUCK = 0, 1


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Immutable record of an integration over whole periods from ``t_start``.

    Attributes
    ----------
    problem : ImpactProblem
        What was integrated.
    strobe_times : ndarray, shape (n + 1,)
        t_start + k T [s], k = 0 ... n.
    strobe_states : ndarray, shape (n + 1, 4)
        (X1, X2, X1', X2') at the strobe times [m, m, m s-1, m s-1] (after any impact at that instant).
    impact_times : ndarray
        Times of the impacts [s].
    impact_velocities : ndarray
        Absorber velocity just before each impact, > 0 [m s-1].
    impulses : ndarray
        M2 (X2'(t-) - X2'(t+)) of each impact [N s]: M2 (1 + R) X2'(t-), or M2 X2'(t-) for the impact that ends a
        chattering sequence in sticking.
    segments : ndarray, shape (s, 3)
        Rows (start [s], end [s], mode): ``MODE_FREE`` flight or ``MODE_STUCK`` (absorber held at the stop).
    segment_states : ndarray, shape (s, 4)
        State at the start of each segment (after the event that began it).
    moments : ndarray of complex, shape (n, 5) or (0, 5)
        Per period, when requested: integrals of X1 e^{-jwt}, X2 e^{-jwt} [m s], of the contact force e^{-jwt}
        (impulses plus holding force while stuck) [N s], and of X1^2, X2^2 [m2 s] (real).
    contact_peaks : ndarray, shape (c, 2)
        Compliant contacts only: largest contact force [N] and largest absorber deceleration [m s-2] of each contact.
    stats : dict
        Engine counters (steps, rhs calls, events, grazing checks ...).
    strobe_jacobians : ndarray, shape (n, 4, 4) or (0, 4, 4)
        ``exact`` engine on request: entry k is the exact Jacobian of period k's stroboscopic map, d y_{k+1} / d y_k.
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

    def __post_init__(self) -> None:
        for name in (
            "strobe_times", "strobe_states", "impact_times", "impact_velocities", "impulses", "segments", "segment_states", "moments",
            "contact_peaks", "strobe_jacobians",
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

    Engines report physical states (X1, X2, X1', X2'), segment starts, impacts, moments of the running period and
    strobes; segment ends are the next segment's start (or the last strobe), so zero-length segments vanish.
    """

    def __init__(self, problem: ImpactProblem, moments: bool) -> None:
        self.problem, self.moments = problem, moments
        self._strobe_times: list[float] = []
        self._strobe_states: list[NDArray[np.float64]] = []
        self._impacts: list[tuple[float, float, float]] = []
        self._segments: list[tuple[float, int]] = []
        self._segment_states: list[NDArray[np.float64]] = []
        self._period_moments: list[NDArray[np.complex128]] = []
        self._peaks: list[tuple[float, float]] = []
        self._current = np.zeros(5, dtype=complex)
        self.stats: dict[str, int] = {"impacts": 0, "sticks": 0, "releases": 0}

    def impact(self, t: float, velocity: float, impulse: float, in_moments: bool = True) -> None:
        """An impact at time t [s] with pre-impact velocity [m s-1] and impulse [N s].

        A momentary impulse's Fourier term is added to the contact-force moment; a compliant contact's force is
        integrated continuously instead (``in_moments=False``).
        """
        self._impacts.append((t, velocity, impulse))
        self.stats["impacts"] += 1
        if self.moments and in_moments:
            self._current[2] += impulse * complex(math.cos(self.problem.omega * t), -math.sin(self.problem.omega * t))

    def contact_peaks(self, force: float, acceleration: float) -> None:
        """Largest contact force [N] and absorber deceleration [m s-2] of the last compliant contact."""
        self._peaks.append((force, acceleration))

    def segment(self, t: float, mode: int, state: NDArray[np.float64]) -> None:
        """A new segment (``MODE_FREE`` or ``MODE_STUCK``) starts at time t [s] in ``state``."""
        self._segments.append((t, mode))
        self._segment_states.append(np.array(state[:4], dtype=float))

    def add_moments(self, values: NDArray[np.complex128]) -> None:
        """Add integrals (X1, X2, holding force times e^{-jwt}; X1^2, X2^2) to the running period."""
        self._current += values

    def strobe(self, t: float, state: NDArray[np.float64]) -> None:
        """A period boundary at time t [s]: record the state and close the running period's moments."""
        if self._strobe_times and self.moments:
            self._period_moments.append(self._current)
            self._current = np.zeros(5, dtype=complex)
        self._strobe_times.append(t)
        self._strobe_states.append(np.array(state[:4], dtype=float))

    def build(self, stats: dict[str, int] | None = None) -> Trajectory:
        """The immutable trajectory, with ``stats`` merged into the builder's counters."""
        starts = np.array([s[0] for s in self._segments])
        ends = np.append(starts[1:], self._strobe_times[-1]) if starts.size else starts
        keep = ends > starts
        impacts = np.array(self._impacts, dtype=float).reshape(-1, 3)
        return Trajectory(
            problem=self.problem,
            strobe_times=np.array(self._strobe_times),
            strobe_states=np.array(self._strobe_states).reshape(-1, 4),
            impact_times=impacts[:, 0].copy(),
            impact_velocities=impacts[:, 1].copy(),
            impulses=impacts[:, 2].copy(),
            segments=np.column_stack([starts, ends, [s[1] for s in self._segments]]).reshape(-1, 3)[keep],
            segment_states=np.array(self._segment_states).reshape(-1, 4)[keep],
            moments=np.array(self._period_moments, dtype=complex).reshape(-1, 5),
            contact_peaks=np.array(self._peaks, dtype=float).reshape(-1, 2),
            stats=self.stats | (stats or {}),
        )


@dataclass(frozen=True, eq=False)
class SweepRecord:
    """A swept-sine run, sampled uniformly in time.

    Attributes
    ----------
    sweep : SweptSine
        The excitation.
    time : ndarray
        Sample times [s].
    x1, x2 : ndarray
        Displacements [m].
    base_force : ndarray
        Force on the base: suspension K1 X1 + B1 X1' plus bumper [N].
    contact_force : ndarray
        Bumper force [N] (0 outside contact).
    trajectory : Trajectory
        Contacts: ``impact_times`` (onsets) [s], ``impact_velocities`` [m s-1], ``impulses`` [N s] and
        ``contact_peaks`` (c, 2) = [peak force N, peak deceleration m s-2], one row per completed contact (a contact
        still open at the end is counted in ``stats["contacts"]`` only); ``segments`` (free and contact); ``stats``:
        ``steps`` (step attempts), ``rhs_calls`` (residual or right-hand-side evaluations), ``contacts``, ``events``
        (roots handled), ``solver_calls``, ``grazing`` (contacts caught at an apex).
    contact_fourier : ndarray of complex
        Running integral of F exp(-j theta) theta' dt from t = 0 to each sample [N], integrated with the motion:
        its increase over a window of whole cycles, divided by pi times the cycles, is the bumper force's fundamental.
    """

    sweep: SweptSine
    time: NDArray[np.float64]
    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    base_force: NDArray[np.float64]
    contact_force: NDArray[np.float64]
    trajectory: Trajectory
    contact_fourier: NDArray[np.complex128]


class Engine(Protocol):
    """A time-domain solver of an :class:`ImpactProblem` with a harmonic force, period by period."""

    name: str

    def integrate(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` at ``t_start``."""
        ...


class SweepingEngine(Protocol):
    """A time-domain solver of an :class:`ImpactProblem` with a :class:`SweptSine` excitation, start to end."""

    name: str

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
    if not isinstance(problem.contact, contact):
        raise TypeError(f"engine {engine!r} solves a {contact.__name__}, not problem.contact = {problem.contact!r}")
