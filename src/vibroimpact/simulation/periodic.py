"""Steady states found by shooting, and what a motion is when no periodic orbit is reached.

``start: shooting`` looks for the periodic orbit directly: a zero of P(y) - y of the stroboscopic map of the
compiled ``exact`` engine, solved by damped Newton with the exact Jacobian (:func:`vibroimpact.orbits.shooting.shoot`)
from the closed-form one-impact orbit (or any guess). The map's section is half a period after the guess's impact,
so that no impact sits on the strobe (the fixed point of a map whose section cuts an impact jumps). A stable orbit is
then the steady state: the ``exact`` engine measures it at once; an integrator starts on it and only confirms that
its own stroboscopic state repeats.

Where marching does not converge, :func:`motion_evidence` says what the motion is (``quasi_periodic``, ``chaotic``
or ``irregular``): from the exact per-period Jacobians for ``exact``, and for any other engine from its own strobes
and two of its own nearby trajectories (:mod:`vibroimpact.orbits.motion`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.base import Engine, Trajectory
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.simulation.harmonics import gaps
from vibroimpact.orbits.branch import HybridInfo, MapEvaluation
from vibroimpact.orbits.lyapunov import lyapunov_along_run, state_scales
from vibroimpact.orbits.motion import MotionEvidence, classify_motion, classify_strobes
from vibroimpact.orbits.shooting import ShootingError, ShootingSettings, shoot

__all__ = ["SectionMap", "ShotOrbit", "shoot_orbit", "motion_evidence"]


class SectionMap:
    """The stroboscopic map of one problem through the section t = ``section`` (mod T), for shooting.

    Parameters
    ----------
    problem : ImpactProblem
        Rigid stop and harmonic force.
    section : float
        Time of the section [s].
    engine : ExactEngine
        The compiled engine that computes the map and its Jacobian.

    Attributes
    ----------
    evaluations : int
        Map evaluations so far (each one excitation period).
    """

    parameter_names = ("frequency",)

    def __init__(self, problem: ImpactProblem, section: float, engine: ExactEngine) -> None:
        self.problem, self.section, self.engine = problem, float(section), engine
        self.dimension = 2 * problem.size
        self.state_scale = state_scales(problem)
        self.parameter_scale = np.array([1.0])
        self.evaluations = 0

    def evaluate(self, y: NDArray[np.float64], p: NDArray[np.float64]) -> MapEvaluation:
        """The state one period after ``y`` at the section, with its exact Jacobian (NaN for a start inside a stop)."""
        n = self.dimension
        if not np.all(gaps(self.problem, y) >= 0.0):
            return MapEvaluation(np.full(n, np.nan), np.full((n, n), np.nan), None, None)
        self.evaluations += 1
        image = self.engine.strobe_map(self.problem, np.asarray(y, dtype=float), self.section, 1)
        v = image.impact_velocities
        hybrid = HybridInfo(int(v.size), float(v.min()) if v.size else np.inf, image.closest_approach, image.sticks)
        return MapEvaluation(image.state, image.jacobian, None, hybrid)


@dataclass(frozen=True)
class ShotOrbit:
    """A period-one orbit found by shooting.

    Attributes
    ----------
    time : float
        Time of its section [s].
    state : ndarray, shape (2 N,)
        Its state there (x, x'); for the paper (X1, X2, X1', X2').
    floquet_modulus : float
        Largest |Floquet multiplier| [-].
    periods : int
        Map evaluations (excitation periods integrated) the search cost.
    """

    time: float
    state: NDArray[np.float64]
    floquet_modulus: float
    periods: int

    @property
    def stable(self) -> bool:
        """All Floquet multipliers inside the unit circle."""
        return self.floquet_modulus < 1.0


def shoot_orbit(problem: ImpactProblem, time: float, guess: NDArray[np.float64], settings: ShootingSettings = ShootingSettings(tolerance=1e-12, max_iterations=12)) -> ShotOrbit | None:
    """The period-one orbit through the section at ``time`` [s] nearest ``guess``; None where Newton fails.

    Shooting needs the exact Jacobian: it always uses the compiled ``exact`` engine (the problem must have a rigid
    stop). The search costs one excitation period per map evaluation.
    """
    section = SectionMap(problem, time, ExactEngine())
    try:
        orbit = shoot(section, np.asarray(guess, dtype=float), np.array([problem.frequency]), 1, settings)
    except ShootingError:
        return None
    return ShotOrbit(float(time), orbit.state, orbit.floquet_modulus, section.evaluations)


def motion_evidence(engine: Engine, problem: ImpactProblem, run: Trajectory, every: int | None = None) -> MotionEvidence:
    """What a motion that did not become periodic is, from a run on its attractor.

    Parameters
    ----------
    engine : Engine
        The engine that made ``run``.
    problem : ImpactProblem
        The problem.
    run : Trajectory
        A run on the attractor. With ``strobe_jacobians`` (``exact``) the exact exponent and the strobes decide;
        otherwise the strobes and an exponent of the engine's own (:func:`vibroimpact.orbits.lyapunov.lyapunov_along_run`:
        a copy perturbed by 1e-6 of the motion's scale restarts from the run's strobes; one more run of the same
        length; following only the run's second half left 61 of the restitution study's 1505 points undecided
        instead of 32).
    every : int, optional
        Periods between renormalisations of the separation (>= 1); by default a 32nd of the run, at most 32. Each is
        a new engine call; over 32 periods a separation of 1e-6 grows to at most ~1e-3 on the paper's chaotic
        attractors (exponents <= 0.2), still small.
    """
    if run.strobe_jacobians.shape[0]:
        return classify_motion(run.strobe_jacobians, run.strobe_states)
    every = min(32, max(1, run.periods // 32)) if every is None else every
    if run.periods // every < 10:
        return classify_strobes(run.strobe_states)
    return classify_strobes(run.strobe_states, lyapunov_along_run(engine, problem, run, every))

