"""Closed-form starts for shooting and continuation: the impact orbit's state at the strobe, another root, a strobe
phase clear of the impacts.

Where a closed form applies (:mod:`vibroimpact.analysis.layout`: one rigid stop, or a symmetric two-sided stop, on a
structure without rigid-body modes) the orbit's state at t = 0 of the problem's time is a shooting guess that is
exact up to the engine's round-off. The paper's layout keeps its own closed form (:func:`solve_one_impact` with the
named system, bit for bit as before); any other layout uses :func:`vibroimpact.analysis.impact_orbit.solve_impact_orbit`.
Where none applies, start from a simulated state (:func:`vibroimpact.orbits.maps.resection` puts its strobe clear of
its impacts) and shoot.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.analysis.impact_orbit import ROOTS, ImpactOrbit, solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.analysis.pgf import OneImpactSolution, solve_one_impact
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import TwoDofSystem

__all__ = ["one_impact_state", "closed_form_state", "with_impulse", "section_phase", "paper_form"]


def paper_form(problem: ImpactProblem) -> bool:
    """Does ``problem`` use the paper's named closed form (named system, its single stop, force on the primary)?"""
    return isinstance(problem.system, TwoDofSystem) and not isinstance(problem.contact, tuple) and problem.paper_layout


def one_impact_state(problem: ImpactProblem, solution: OneImpactSolution | ImpactOrbit | None = None) -> NDArray[np.float64]:
    """The closed-form impact orbit's state (x, x') at t = 0 (mod T) of ``problem``'s time; NaN where none exists.

    On the paper's layout: the one-impact orbit of eqs. 15-16 (the closed form measures time from the impact, with the
    linear response q |H12| cos(w t + phi); in the problem's time the force is q cos(w t' + phase), so t' = t + (phi -
    arg H12 - phase) / w). Any other layout with a closed form: :func:`closed_form_state` (one stop: one impact per
    period; a symmetric two-sided stop: the two-impacts orbit). ``ValueError`` naming the reason where none applies.

    Parameters
    ----------
    problem : ImpactProblem
        Rigid stop(s) and harmonic force.
    solution : OneImpactSolution or ImpactOrbit, optional
        A scalar solution for this problem (solved when omitted), e.g. with another root of the impulse equation.
    """
    if isinstance(solution, ImpactOrbit) or (solution is None and not paper_form(problem)):
        return closed_form_state(problem, solution)
    if solution is None:
        solution = solve_one_impact(problem.system, problem.omega, problem.clearance, problem.restitution, problem.amplitude)
    w, period = float(solution.omega), float(solution.period)
    impact_at = (float(solution.phase) - float(np.angle(solution.receptances.h12)) - problem.phase) / w
    t = np.array([[(-impact_at) % period]])
    return np.array([solution.x1(t)[0, 0], solution.x2(t)[0, 0], solution.x1(t, 1)[0, 0], solution.x2(t, 1)[0, 0]])


def closed_form_state(problem: ImpactProblem, orbit: ImpactOrbit | None = None, root: str = "+") -> NDArray[np.float64]:
    """The state (x, x') at t = 0 of ``problem``'s time on its closed-form impact orbit (any structure), shape (2N,).

    Parameters
    ----------
    problem : ImpactProblem
        One rigid stop, or a symmetric two-sided pair, on a structure without rigid-body modes, harmonic force.
    orbit : ImpactOrbit, optional
        A scalar orbit of this problem (solved with ``root`` when omitted).
    root : {'+', '-'}
        Which root of the impulse equation, when solving.

    Returns
    -------
    ndarray
        NaN where the orbit does not exist (no real root with J >= 0).
    """
    if orbit is None:
        orbit = solve_impact_orbit(problem, root=root)
    if not bool(np.all(orbit.exists)):
        return np.full(2 * problem.size, np.nan)
    return np.asarray(orbit.state_at(np.zeros(np.shape(orbit.omega) + (1,))), dtype=float).reshape(-1)


def with_impulse(solution: OneImpactSolution | ImpactOrbit, impulse: float) -> OneImpactSolution | ImpactOrbit:
    """A scalar closed-form solution with another root J of the impulse equation (its phase follows from eq. 15)."""
    if isinstance(solution, ImpactOrbit):
        c = (1.0 / (solution.layout.effective_mass * (1.0 + solution.restitution)) + solution.chi_rate_before) / solution.omega
        a = solution.linear_amplitude
        delta = solution.clearance - solution.static_offset
        phase = np.arctan2(-impulse * c / a, (delta + impulse * solution.chi0) / a)
        return dataclasses.replace(solution, impulse=np.asarray(impulse, dtype=float), phase=np.asarray(phase, dtype=float), exists=np.asarray(impulse >= 0.0))
    c = (1.0 / (solution.system.m2 * (1.0 + solution.restitution)) + solution.chi_rate_before) / solution.omega
    a = solution.amplitude * np.abs(solution.receptances.h12)
    phase = np.arctan2(-impulse * c / a, (solution.clearance + impulse * solution.chi0) / a)
    return dataclasses.replace(solution, impulse=np.asarray(impulse, dtype=float), phase=np.asarray(phase, dtype=float))


def _paper_fractions(problem: ImpactProblem, f: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    system, delta, r, q = problem.system, problem.clearance, problem.restitution, problem.amplitude
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
    return fractions


def section_phase(problem: ImpactProblem, frequencies: ArrayLike, clearances: ArrayLike | None = None, amplitudes: ArrayLike | None = None) -> float:
    """A force phase [rad] that keeps the strobe (t = 0 mod T) away from the closed-form orbits' impacts.

    Where an impact crosses the strobe time the fixed point of the stroboscopic map jumps between the states just
    before and just after it, and a continuation cannot follow. The impact instants of both roots of the impulse
    equation (both stops' impacts, T/2 apart, for a two-sided stop), as fractions of the period, are found over
    ``frequencies`` [Hz] from the closed form; the phase puts the strobe in the middle of the widest gap between them.
    Use it as the problem's force phase (``dataclasses.replace(problem.harmonic, phase=...)``). ``clearances`` and
    ``amplitudes`` (broadcast against ``frequencies``; the problem's when omitted) cover a continuation in those
    parameters (any layout but the paper's named form, which varies the frequency only). 0 where no closed form applies (start
    from a simulated state and :func:`vibroimpact.orbits.maps.resection` instead) or no orbit exists.
    """
    f = np.asarray(frequencies, dtype=float)
    if paper_form(problem):
        fractions = _paper_fractions(problem, f)
    else:
        if closed_form_refusal(problem) is not None:
            return 0.0
        fractions = []
        for root in ROOTS:
            orbit = solve_impact_orbit(problem, 2.0 * np.pi * f, clearances, None, amplitudes, root=root)
            # the impact time includes the problem's phase: measure it against a force of phase 0
            base = ((orbit.impact_time + problem.phase / orbit.omega) / orbit.period) % 1.0
            fractions.append(base[orbit.exists])
            if orbit.two_sided:
                fractions.append((base[orbit.exists] + 0.5) % 1.0)
    points = np.sort(np.concatenate(fractions))
    if points.size == 0:
        return 0.0
    gaps = np.diff(np.concatenate([points, [points[0] + 1.0]]))
    k = int(np.argmax(gaps))
    return float(2.0 * np.pi * ((points[k] + 0.5 * gaps[k]) % 1.0))
