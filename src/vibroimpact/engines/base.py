"""What every engine shares: the problem it solves, its settings, and the immutable trajectory it returns."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.system import TwoDofSystem
from vibroimpact.model.validation import require_in_range, require_non_negative, require_positive

__all__ = ["ImpactProblem", "Trajectory", "Engine", "MODE_FREE", "MODE_STUCK"]

#: Segment modes of a trajectory.
MODE_FREE, MODE_STUCK = 0, 1


@dataclass(frozen=True)
class ImpactProblem:
    """The system of eq. 1 with a rigid stop: force q cos(w t + phase) on the primary mass, stop at X2 = Delta.

    Parameters
    ----------
    system : TwoDofSystem
        Masses, springs and dashpots.
    clearance : float
        Delta [m], >= 0.
    restitution : float
        R [-], 0 <= R <= 1: the absorber's velocity after an impact is -R times the velocity before.
    amplitude : float
        q [N], >= 0.
    frequency : float
        Excitation frequency [Hz], > 0.
    phase : float
        Phase of the force at t = 0 [rad].
    """

    system: TwoDofSystem
    clearance: float = field(metadata={"units": "m"})
    restitution: float = field(metadata={"units": "1"})
    amplitude: float = field(metadata={"units": "N"})
    frequency: float = field(metadata={"units": "Hz"})
    phase: float = field(default=0.0, metadata={"units": "rad"})

    def __post_init__(self) -> None:
        require_non_negative("clearance", self.clearance)
        require_in_range("restitution", self.restitution, 0.0, 1.0)
        require_non_negative("amplitude", self.amplitude)
        require_positive("frequency", self.frequency)

    @property
    def omega(self) -> float:
        """Angular frequency w [rad s-1]."""
        return 2.0 * math.pi * self.frequency

    @property
    def period(self) -> float:
        """T = 1 / f [s]."""
        return 1.0 / self.frequency

    def force(self, t: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
        """External force on the primary mass [N]."""
        return self.amplitude * np.cos(self.omega * t + self.phase)

    def holding_force(self, x1: float | NDArray[np.float64], v1: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
        """Force the stop must exert to hold the absorber at rest at X2 = Delta, B2 X1' + K2 (X1 - Delta) [N].

        Positive: the absorber is pushed into the stop (it sticks); it leaves when this turns negative.
        """
        return self.system.b2 * v1 + self.system.k2 * (x1 - self.clearance)

    def velocity_scale(self) -> float:
        """A velocity typical of the motion, w (Delta + q |H12|) [m s-1], for relative thresholds."""
        linear = self.amplitude * float(np.abs(self.system.receptances(self.omega).h12))
        return self.omega * (self.clearance + linear) + 1e-300


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

    def __post_init__(self) -> None:
        for name in ("strobe_times", "strobe_states", "impact_times", "impact_velocities", "impulses", "segments", "segment_states", "moments", "contact_peaks"):
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


class Engine(Protocol):
    """A time-domain solver of an :class:`ImpactProblem`."""

    name: str

    def integrate(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` at ``t_start``."""
        ...
