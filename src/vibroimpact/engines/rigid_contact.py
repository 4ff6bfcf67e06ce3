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
    """The rigid stop of one problem with an engine's settings.

    Parameters
    ----------
    engine : str
        Name of the engine (for messages).
    problem : ImpactProblem
        Must have a :class:`RigidStop` and a harmonic force (``TypeError`` otherwise).
    settings : EngineSettings
        Sticking velocity (a fraction of the problem's velocity scale) and impacts per period before sticking.
    periods : int
        Periods the run integrates (>= 0).

    Attributes
    ----------
    velocity_scale : float
        The problem's velocity scale w (Delta + q |H12|) [m s-1].
    length_scale : float
        Delta + velocity_scale / w [m]: the size of the motion, for round-off thresholds.
    sticking_velocity : float
        Impacts at most this fast [m s-1] are chattering.
    """

    def __init__(self, engine: str, problem: ImpactProblem, settings: EngineSettings, periods: int) -> None:
        check_run(engine, problem, RigidStop, periods)
        self.stop, self.mass = problem.rigid_stop, problem.system.m2
        self.velocity_scale = problem.velocity_scale()
        self.length_scale = problem.clearance + self.velocity_scale / problem.omega
        self.sticking_velocity = settings.sticking_velocity * self.velocity_scale
        self.max_impacts = settings.max_impacts_per_period

    def check_start(self, state: NDArray[np.float64]) -> None:
        """A start beyond the stop (by more than round-off of the length scale) is an error."""
        if state[1] > self.stop.clearance + 1e-12 * self.length_scale:
            raise ValueError(f"initial X2 = {state[1]!r} m penetrates the stop (clearance {self.stop.clearance!r} m)")

    def collide(self, rec: TrajectoryBuilder, t: float, velocity: float, impacts: int, pushed: Callable[[], bool]) -> Impact:
        """Apply the law to an impact at time t [s] at approach ``velocity`` >= 0 [m s-1], the ``impacts``-th of its
        period, and record it (an impact at zero speed is a touch: only a stick is counted)."""
        outcome = self.stop.impact(self.mass, velocity, self.stop.chatters(velocity, impacts, self.sticking_velocity, self.max_impacts), pushed)
        if velocity > 0.0:
            rec.impact(t, velocity, outcome.impulse)  # M2 (1 + R) v, or M2 v when the absorber sticks
        rec.stats["sticks"] += int(outcome.sticks)
        return outcome
