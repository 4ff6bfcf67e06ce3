"""The impacting system as a parametrised map: the stroboscopic map of an :class:`ImpactProblem` over k periods.

``ImpactMap(problem, periods=k)`` maps the state (X1, X2, X1', X2') at t = 0 (mod T) to the state k excitation
periods later, with the exact Jacobian of the compiled ``exact`` engine (state-transition matrices times saltation
matrices of impacts, sticking and release). Its parameters are ``frequency`` [Hz], ``restitution`` [-],
``clearance`` [m] and ``amplitude`` [N]; a parameter vector becomes a new problem (the frequency changes the
period, the strobes stay at t = 0 mod T). dP/dp comes from central differences (see
:data:`vibroimpact.orbits.shooting.FD_RELATIVE_STEP`). Each evaluation carries the hybrid information continuation
watches: impacts per orbit period, the slowest impact, the closest approach of a free flight to the stop, sticks.

:func:`one_impact_state` gives the closed-form one-impact orbit's strobe state (a shooting guess), and
:func:`orbit_measures` what an orbit means physically (impulse per impact, harmonic amplitudes).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.pgf import OneImpactSolution, solve_one_impact
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.branch import HybridInfo, MapEvaluation, PeriodicOrbit

__all__ = ["ImpactMap", "OrbitMeasures", "orbit_measures", "one_impact_state", "with_impulse", "section_phase", "resection", "PARAMETERS"]

#: The parameters of an :class:`ImpactMap`, in order, with their units.
PARAMETERS = {"frequency": "Hz", "restitution": "1", "clearance": "m", "amplitude": "N"}


class ImpactMap:
    """Stroboscopic map over ``periods`` excitation periods of a rigid-stop problem under a harmonic force.

    Parameters
    ----------
    problem : ImpactProblem
        The base problem (rigid stop, harmonic force); its values are the default parameter vector.
    periods : int
        k >= 1: excitation periods per map iteration.
    engine : ExactEngine, optional
        The engine that computes the map (default settings when omitted).
    bounds : dict, optional
        Parameter name -> (lower, upper): outside this box the map has no image (NaN, a failed step), e.g. to keep a
        continuation's trials at physical frequencies. Parameters outside their own ranges (a negative clearance or
        frequency, R > 1) never have one.

    Attributes
    ----------
    parameters : ndarray, shape (4,)
        The base problem's (frequency [Hz], restitution [-], clearance [m], amplitude [N]).
    state_scale : ndarray, shape (4,)
        (L, L, V, V) with L = Delta + q |H12(w)| [m] and V = w L [m s-1] of the base problem.
    parameter_scale : ndarray, shape (4,)
        (1 Hz, 0.1, 1 mm, 1 N): what counts as a unit of arclength for each parameter.
    """

    parameter_names = tuple(PARAMETERS)
    dimension = 4

    def __init__(self, problem: ImpactProblem, periods: int = 1, engine: ExactEngine | None = None, bounds: dict[str, tuple[float, float]] | None = None) -> None:
        _checked = (problem.rigid_stop, problem.harmonic)  # TypeError naming the part unless a rigid stop and a harmonic force
        if int(periods) < 1:
            raise ValueError(f"periods = {periods!r} is out of range: allowed [1, inf)")
        self.problem, self.periods = problem, int(periods)
        self.engine = engine if engine is not None else ExactEngine()
        self.parameters = np.array([problem.frequency, problem.restitution, problem.clearance, problem.amplitude])
        length = problem.clearance + problem.amplitude * float(np.abs(problem.system.receptances(problem.omega).h12))
        self.state_scale = np.array([length, length, problem.omega * length, problem.omega * length])
        self.parameter_scale = np.array([1.0, 0.1, 1e-3, 1.0])
        self.bounds = dict(bounds or {})
        unknown = set(self.bounds) - set(PARAMETERS)
        if unknown:
            raise ValueError(f"bounds: unknown parameters {sorted(unknown)}; allowed {list(PARAMETERS)}")
        self._box = [(self.parameter_names.index(name), float(low), float(high)) for name, (low, high) in self.bounds.items()]

    def with_periods(self, periods: int) -> "ImpactMap":
        """The same map over ``periods`` excitation periods (one compiled call per evaluation, unlike ``Iterated``)."""
        return ImpactMap(self.problem, periods, self.engine, self.bounds)

    def problem_at(self, p: NDArray[np.float64]) -> ImpactProblem:
        """The problem with parameter vector ``p``."""
        frequency, restitution, clearance, amplitude = (float(x) for x in p)
        base = self.problem
        return ImpactProblem(base.system, RigidStop(clearance, restitution), HarmonicForce(amplitude, frequency, base.phase))

    def evaluate(self, y: NDArray[np.float64], p: NDArray[np.float64]) -> MapEvaluation:
        """The state k periods after ``y`` at t = 0, its Jacobian and the hybrid information.

        A state inside the stop (X2 > Delta), a non-finite state, invalid parameters (e.g. a Newton iterate at a
        negative frequency or clearance), parameters outside ``bounds`` and a flight on which the engine makes no
        progress (endless chattering) have no image: NaN, which Newton's method and the corrector treat as a failed step.
        """
        problem = None
        if all(low <= p[i] <= high for i, low, high in self._box) and np.all(np.isfinite(y)):
            try:
                problem = self.problem_at(p)
            except ValueError:  # a Newton iterate outside the parameters' ranges (negative clearance, R > 1, ...)
                problem = None
        strobe = None
        if problem is not None and y[1] <= problem.clearance:  # inside the stop, no flight starts
            try:
                strobe = self.engine.strobe_map(problem, np.asarray(y, dtype=float), 0.0, self.periods)
            except RuntimeError:  # the engine made no progress (endless chattering)
                strobe = None
        if strobe is None:
            return MapEvaluation(np.full(4, np.nan), np.full((4, 4), np.nan), None, None)
        velocities = strobe.impact_velocities
        length = self.state_scale[0]
        hybrid = HybridInfo(
            impacts=int(velocities.size),
            min_impact_velocity=float(velocities.min()) if velocities.size else math.inf,
            closest_approach=float(strobe.closest_approach),
            sticks=int(strobe.sticks),
            length_scale=length,
            velocity_scale=problem.omega * length,
        )
        return MapEvaluation(strobe.state, strobe.jacobian, None, hybrid)


@dataclass(frozen=True)
class OrbitMeasures:
    """What a periodic orbit of an :class:`ImpactMap` means physically.

    Attributes
    ----------
    impact_velocities : ndarray
        Approach speed of each impact over the orbit's period [m s-1].
    impulses : ndarray
        Impulse of each impact [N s].
    x1_amplitude, x2_amplitude : float
        |fundamental harmonic| of X1 and X2 at the excitation frequency, averaged over the orbit's period [m].
    """

    impact_velocities: NDArray[np.float64]
    impulses: NDArray[np.float64]
    x1_amplitude: float
    x2_amplitude: float


def orbit_measures(system: ImpactMap, orbit: PeriodicOrbit) -> OrbitMeasures:
    """Impulses and harmonic amplitudes of ``orbit``, from one exact integration over its period."""
    problem = system.problem_at(orbit.parameters)
    periods = orbit.period * system.periods
    trajectory = system.engine.integrate(problem, orbit.state, 0.0, periods, moments=True)
    moments = trajectory.moments.sum(axis=0)
    scale = 2.0 / (periods * problem.period)
    return OrbitMeasures(trajectory.impact_velocities.copy(), trajectory.impulses.copy(), float(abs(moments[0]) * scale), float(abs(moments[1]) * scale))


def one_impact_state(problem: ImpactProblem, solution: OneImpactSolution | None = None) -> NDArray[np.float64]:
    """The closed-form one-impact orbit's state (X1, X2, X1', X2') at t = 0 (mod T) of ``problem``'s time.

    The closed form measures time from the impact, with the linear response q |H12| cos(w t + phi); in the problem's
    time the force is q cos(w t' + phase), so t' = t + (phi - arg H12 - phase) / w. NaN where no solution exists.

    Parameters
    ----------
    problem : ImpactProblem
        Rigid stop and harmonic force.
    solution : OneImpactSolution, optional
        A scalar solution for this problem (solved when omitted), e.g. with another root of eq. 16.
    """
    if solution is None:
        solution = solve_one_impact(problem.system, problem.omega, problem.clearance, problem.restitution, problem.amplitude)
    w, period = float(solution.omega), float(solution.period)
    impact_at = (float(solution.phase) - float(np.angle(solution.receptances.h12)) - problem.phase) / w
    t = np.array([[(-impact_at) % period]])
    return np.array([solution.x1(t)[0, 0], solution.x2(t)[0, 0], solution.x1(t, 1)[0, 0], solution.x2(t, 1)[0, 0]])


def with_impulse(solution: OneImpactSolution, impulse: float) -> OneImpactSolution:
    """A scalar closed-form solution with another root J of eq. 16 (its phase follows from eq. 15)."""
    c = (1.0 / (solution.system.m2 * (1.0 + solution.restitution)) + solution.chi_rate_before) / solution.omega
    a = solution.amplitude * np.abs(solution.receptances.h12)
    phase = np.arctan2(-impulse * c / a, (solution.clearance + impulse * solution.chi0) / a)
    return dataclasses.replace(solution, impulse=np.asarray(impulse, dtype=float), phase=np.asarray(phase, dtype=float))


def section_phase(problem: ImpactProblem, frequencies: NDArray[np.float64]) -> float:
    """A force phase [rad] that keeps the strobe (t = 0 mod T) away from the one-impact orbits' impacts.

    Where an impact crosses the strobe time the fixed point of the stroboscopic map jumps between the states just
    before and just after it, and a continuation cannot follow. The impact instants of both roots of eq. 16, as
    fractions of the period, are found over ``frequencies`` [Hz] from the closed form; the phase puts the strobe in
    the middle of the widest gap between them. Use it as ``HarmonicForce(q, f, phase)``.
    """
    system, delta, r, q = problem.system, problem.clearance, problem.restitution, problem.amplitude
    f = np.asarray(frequencies, dtype=float)
    sol = solve_one_impact(system, 2.0 * np.pi * f, delta, r, q)
    c = (1.0 / (system.m2 * (1.0 + r)) + sol.chi_rate_before) / sol.omega
    a = q * np.abs(sol.receptances.h12)
    quad_a, quad_b = c**2 + sol.chi0**2, delta * sol.chi0
    disc = quad_a * a**2 - (c * delta) ** 2
    fractions = []
    with np.errstate(invalid="ignore"):
        for sign in (1.0, -1.0):
            impulse = (-quad_b + sign * np.sqrt(disc)) / quad_a
            ok = (disc >= 0.0) & (impulse >= 0.0)
            phase = np.arctan2(-impulse * c / a, (delta + impulse * sol.chi0) / a)
            fractions.append((((phase - np.angle(sol.receptances.h12)) / (2.0 * np.pi)) % 1.0)[ok])
    points = np.sort(np.concatenate(fractions))
    if points.size == 0:
        return 0.0
    gaps = np.diff(np.concatenate([points, [points[0] + 1.0]]))
    k = int(np.argmax(gaps))
    return float(2.0 * np.pi * ((points[k] + 0.5 * gaps[k]) % 1.0))


def resection(problem: ImpactProblem, state: NDArray[np.float64], periods: int, engine: ExactEngine | None = None) -> tuple[ImpactProblem, NDArray[np.float64]]:
    """The same motion seen through a strobe away from its impacts.

    ``state`` is the state at t = 0 of ``problem`` on (or near) an orbit of ``periods`` excitation periods, e.g. the
    end of a brute-force run. The motion is integrated over ``periods`` periods; the impact instants modulo T leave
    gaps, and the new strobe goes in the middle of the widest: at tau = g T, i.e. the problem with force phase
    phase + 2 pi g, whose t = 0 is the old t = tau. An :class:`ImpactMap` of that problem has the orbit as a fixed
    point of a map that is smooth near it (no impact crosses its strobe).

    Returns
    -------
    (ImpactProblem, ndarray)
        The problem with the new force phase [rad], and the state (X1, X2, X1', X2') at its t = 0.
    """
    engine = engine if engine is not None else ExactEngine()
    run = engine.integrate(problem, np.asarray(state, dtype=float), 0.0, int(periods))
    fractions = np.sort((run.impact_times / problem.period) % 1.0)
    if fractions.size == 0:
        return problem, np.asarray(state, dtype=float).copy()
    gaps = np.diff(np.concatenate([fractions, [fractions[0] + 1.0]]))
    k = int(np.argmax(gaps))
    g = float((fractions[k] + 0.5 * gaps[k]) % 1.0)
    moved = engine.dense(run, np.array([g * problem.period]))[0]
    phase = float((problem.phase + 2.0 * np.pi * g) % (2.0 * np.pi))
    base = problem
    return ImpactProblem(base.system, base.contact, HarmonicForce(base.amplitude, base.frequency, phase)), np.asarray(moved, dtype=float)
