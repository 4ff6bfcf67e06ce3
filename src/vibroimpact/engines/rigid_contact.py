"""The rigid stop's law as the momentary-impact engines apply it: one place for ``exact`` and the event loop.

The law itself (impact map, chattering test, sticking, impulse, holding force) is :class:`vibroimpact.model.contact.
RigidStop`'s; this module adds what an engine brings to it: thresholds scaled to the problem's motion, the check of
the starting state, and the record of each impact. Whether the stop pushes the absorber stays with each engine (a
root search on the exact flow, or derivatives of the integrated motion) and is passed in.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.base import TrajectoryBuilder, check_run
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import Impact, RigidStop
from vibroimpact.model.problem import ImpactProblem

__all__ = ["RigidContact"]


class RigidContact:
    """The rigid stops of one problem with an engine's settings.

    Parameters
    ----------
    engine : str
        Name of the engine (for messages).
    problem : ImpactProblem
        Every stop must have a :class:`RigidStop` law, and the excitation must be harmonic (``TypeError`` otherwise).
    settings : EngineSettings
        Sticking velocity (a fraction of the problem's velocity scale) and impacts per period before sticking.
    periods : int
        Periods the run integrates (>= 0).

    Attributes
    ----------
    laws : tuple of RigidStop
        The law of each stop (``stop``: the first one's, for single-stop callers).
    normals : ndarray, shape (K, N)
        n_k: stop k's gap is clearances[k] - n_k . x.
    clearances : ndarray, shape (K,)
        Delta_k [m].
    masses : ndarray, shape (K,)
        Effective mass m_eff = 1 / (n^T M^-1 n) of each stop [kg] (``mass``: the first one's; M2 on the paper's layout).
    kicks : ndarray, shape (K, N)
        M^-1 n_k [kg-1]: an impulse P on stop k changes the velocities by -P M^-1 n_k.
    velocity_scale : float
        The problem's velocity scale (w (Delta + q |H12|) on the paper's layout) [m s-1].
    length_scale : float
        max |Delta| + velocity_scale / w [m]: the size of the motion, for round-off thresholds.
    sticking_velocity : float
        Impacts at most this fast [m s-1] are chattering.
    """

    def __init__(self, engine: str, problem: ImpactProblem, settings: EngineSettings, periods: int) -> None:
        check_run(engine, problem, RigidStop, periods)
        problem.harmonic  # a frequency is needed for the scales (TypeError naming the excitation otherwise)
        mass_matrix = problem.structure.mass_matrix
        self.size = problem.size
        self.names = problem.structure.coordinates
        self.stops = problem.stops
        self.laws: tuple[RigidStop, ...] = tuple(stop.law for stop in self.stops)  # type: ignore[misc]
        self.normals = problem.normals()
        self.clearances = problem.clearances()
        self.kicks = np.linalg.solve(mass_matrix, self.normals.T).T.reshape(-1, self.size)
        self.masses = 1.0 / np.einsum("ki,ki->k", self.normals, self.kicks)
        self.stop, self.mass = self.laws[0], float(self.masses[0])
        self.velocity_scale = problem.velocity_scale()
        self.length_scale = float(np.max(np.abs(self.clearances))) + self.velocity_scale / problem.omega
        self.sticking_velocity = settings.sticking_velocity * self.velocity_scale
        self.max_impacts = settings.max_impacts_per_period

    def gaps(self, state: NDArray[np.float64]) -> NDArray[np.float64]:
        """Delta_k - n_k . x of every stop [m] (negative: penetrating)."""
        return self.clearances - self.normals @ np.asarray(state[: self.size], dtype=float)

    def approach(self, state: NDArray[np.float64]) -> NDArray[np.float64]:
        """n_k . x' of every stop [m s-1]: positive while the gap closes."""
        return self.normals @ np.asarray(state[self.size : 2 * self.size], dtype=float)

    def check_start(self, state: NDArray[np.float64]) -> None:
        """A start beyond any stop (by more than round-off of the length scale) is an error naming the stop."""
        gaps = self.gaps(state)
        for k, gap in enumerate(gaps):
            if gap < -1e-12 * self.length_scale:
                where = self.stops[k].describe(self.names)
                raise ValueError(f"the initial state penetrates stop {k} ({where}) by {float(-gap):.6g} m: start on the allowed side of every stop")

    def collide(self, rec: TrajectoryBuilder, t: float, velocity: float, impacts: int, pushed: Callable[[], bool], stop: int = 0) -> Impact:
        """Apply stop ``stop``'s law to an impact at time t [s] at approach ``velocity`` = n . x' >= 0 [m s-1], the
        ``impacts``-th of its period, and record it (an impact at zero speed is a touch: only a stick is counted)."""
        law = self.laws[stop]
        outcome = law.impact(float(self.masses[stop]), velocity, law.chatters(velocity, impacts, self.sticking_velocity, self.max_impacts), pushed)
        if velocity > 0.0:
            rec.impact(t, velocity, outcome.impulse, stop=stop)  # m_eff (1 + R) v, or m_eff v when it sticks
        rec.stats["sticks"] += int(outcome.sticks)
        return outcome

    def kick(self, state: NDArray[np.float64], stop: int, impulse: float) -> NDArray[np.float64]:
        """The state after an impulse ``impulse`` [N s] of stop ``stop``: x' -> x' - impulse M^-1 n (x unchanged).

        With impulse m_eff (1 + R) v this restitutes the gap velocity, n . x'(t+) = -R n . x'(t-), and on a relative
        stop it conserves the momentum of the two bodies."""
        out = np.array(state, dtype=float)
        out[self.size : 2 * self.size] -= impulse * self.kicks[stop]
        return out
