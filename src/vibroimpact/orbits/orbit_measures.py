"""What a periodic orbit of an :class:`~vibroimpact.orbits.maps.ImpactMap` means physically: its impacts, impulses
and the fundamental harmonics of its coordinates (:func:`orbit_measures`), point by point along a branch
(:func:`branch_measures`), from one exact integration over the orbit's period."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.linear import base_force
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.orbits.branch import Branch, PeriodicOrbit
from vibroimpact.orbits.maps import ImpactMap

__all__ = ["OrbitMeasures", "orbit_measures", "BranchMeasures", "branch_measures"]


@suggest_keywords
@dataclass(frozen=True)
class OrbitMeasures:
    """What a periodic orbit of an :class:`ImpactMap` means physically.

    Attributes
    ----------
    impact_velocities : ndarray
        Approach speed of each impact over the orbit's period [m s-1].
    impulses : ndarray
        Impulse of each impact [N s].
    amplitudes : ndarray, shape (N,)
        |fundamental harmonic| of each coordinate at the excitation frequency, averaged over the orbit's period [m].
    impact_stops : ndarray of int
        The stop of each impact.
    base_force : float
        |fundamental harmonic| of the force transmitted to the base [N]: the springs and dashpots to the ground and the
        stops against it (:func:`vibroimpact.analysis.linear.base_force` of the coordinates' and contact forces'
        fundamentals over the orbit's period); NaN where not measured.
    """

    impact_velocities: NDArray[np.float64]
    impulses: NDArray[np.float64]
    amplitudes: NDArray[np.float64]
    impact_stops: NDArray[np.int_] = dataclasses.field(default_factory=lambda: np.zeros(0, dtype=int))
    base_force: float = math.nan

    @property
    def x1_amplitude(self) -> float:
        """|X1|: the first coordinate's amplitude [m] (the paper's primary mass)."""
        return float(self.amplitudes[0])

    @property
    def x2_amplitude(self) -> float:
        """|X2|: the second coordinate's amplitude [m] (the paper's absorber); NaN for a single coordinate."""
        return float(self.amplitudes[1]) if self.amplitudes.size > 1 else math.nan


@suggest_keywords
def orbit_measures(system: ImpactMap, orbit: PeriodicOrbit) -> OrbitMeasures:
    """Impulses and harmonic amplitudes of ``orbit``, from one exact integration over its period.

    Parameters
    ----------
    system : ImpactMap
        The stroboscopic map the orbit was found on (:func:`~vibroimpact.orbits.shooting.shoot`,
        :func:`~vibroimpact.orbits.continuation.continue_branch`).
    orbit : PeriodicOrbit
        The orbit (its strobe state and parameters).

    Returns
    -------
    OrbitMeasures
        Each impact's velocity [m s-1] and impulse [N s], and each coordinate's fundamental amplitude [m].
    """
    problem = system.problem_at(orbit.parameters)
    periods = orbit.period * system.periods
    trajectory = system.engine.integrate(problem, orbit.state, 0.0, periods, moments=True)
    moments = trajectory.moments.sum(axis=0)
    scale = 2.0 / (periods * problem.period)
    stops = getattr(trajectory, "impact_stops", None)
    stops = np.asarray(stops, dtype=int).copy() if stops is not None else np.zeros(trajectory.impulses.size, dtype=int)
    amplitudes = np.abs(np.asarray(moments[: problem.size])) * scale
    n, k = problem.size, len(problem.stops)
    force = float(np.abs(base_force(problem.structure, problem.omega, moments[:n], problem.normals().sum(axis=1), moments[n : n + k]))) * scale
    return OrbitMeasures(trajectory.impact_velocities.copy(), trajectory.impulses.copy(), amplitudes, stops, force)


@suggest_keywords
@dataclass(frozen=True, eq=False)
class BranchMeasures:
    """What a branch's orbits mean physically, point by point (:func:`branch_measures`).

    Attributes
    ----------
    parameter : str
        The continued parameter.
    values : ndarray, shape (points,)
        Its value at each point [its unit: ``PARAMETERS``].
    amplitudes : ndarray, shape (points, N)
        |fundamental harmonic| of each coordinate [m].
    impacts : ndarray of int, shape (points,)
        Impacts (contact onsets) per orbit period.
    peak_impulse : ndarray, shape (points,)
        The largest |impulse| of a contact over the orbit's period [N s] (0 without contact).
    stable : ndarray of bool, shape (points,)
        Every Floquet multiplier inside the unit circle.
    base_force : ndarray, shape (points,)
        |fundamental harmonic| of the force transmitted to the base [N] (:class:`OrbitMeasures`).
    """

    parameter: str
    values: NDArray[np.float64]
    amplitudes: NDArray[np.float64]
    impacts: NDArray[np.int_]
    peak_impulse: NDArray[np.float64]
    stable: NDArray[np.bool_]
    base_force: NDArray[np.float64] | None = None

    def amplitude(self, coordinate: int) -> NDArray[np.float64]:
        """|X| of one coordinate along the branch [m] (0: the paper's primary mass, 1: its absorber)."""
        return self.amplitudes[:, coordinate]


@suggest_keywords
def branch_measures(system: ImpactMap, branch: Branch) -> BranchMeasures:
    """:func:`orbit_measures` of every orbit of ``branch`` (continued on ``system``), as arrays along it: one exact
    integration per point, each at the orbit's own strobe.

    Parameters
    ----------
    system : ImpactMap
        The map the branch was continued on.
    branch : Branch
        The branch (:func:`~vibroimpact.orbits.continuation.continue_branch`).

    Returns
    -------
    BranchMeasures
        Per point: the continued parameter's value, each coordinate's fundamental amplitude [m]
        (``amplitude(coordinate)``), the impacts per period, the largest impulse [N s] and the stability.
    """
    measures = [orbit_measures(system, orbit) for orbit in branch.orbits]
    return BranchMeasures(
        branch.parameter,
        branch.values,
        np.array([m.amplitudes for m in measures]),
        branch.impacts,
        np.array([float(np.max(np.abs(m.impulses))) if m.impulses.size else 0.0 for m in measures]),
        branch.stable,
        np.array([m.base_force for m in measures]),
    )
