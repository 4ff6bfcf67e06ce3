"""The largest response along a continued branch, located exactly: the worst case a design is judged on (issue 32).

A branch's largest |X| over its stable stretches is at one of three kinds of place: a special point where the stretch
ends (a fold, period doubling, Neimark-Sacker or grazing point, located by the continuation to its tolerance), an end
of the branch (a bound of the band), or an interior maximum of |X| along the stretch. The last is refined by a
bounded search in the continued parameter between the points either side of the largest sampled one, each trial
orbit shot from the sampled orbit's state: the maximum to the shooting's tolerance, not to a step of the continuation.
:func:`branch_maximum` returns the largest of them and says which it is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.measures import Measure, as_measure
from vibroimpact.orbits.branch import Branch, PeriodicOrbit
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.bumper_screen import bumper_screen_refusal, rigid_twin
from vibroimpact.orbits.maps import ImpactMap, closed_form_state
from vibroimpact.orbits.orbit_measures import branch_measures, orbit_measures
from vibroimpact.orbits.shooting import ShootingError, shoot

__all__ = ["BranchMaximum", "branch_maximum", "WorstCase", "worst_response", "STABLE_BOUNDARY"]

#: A special point's orbit with every |multiplier| below 1 + this borders a stable stretch (its critical multiplier
#: is on the unit circle) [-].
STABLE_BOUNDARY = 1e-6


@dataclass(frozen=True, eq=False)
class BranchMaximum:
    """The largest |X| of one coordinate along a branch (:func:`branch_maximum`).

    Attributes
    ----------
    amplitude : float
        |X| [m] (the fundamental harmonic's amplitude).
    value : float
        The continued parameter there [its unit].
    where : str
        ``interior`` (a maximum along a stable stretch), ``end`` (a point where the branch ends), or the kind of the
        special point (``fold``, ``period_doubling``, ``neimark_sacker``, ``grazing``).
    orbit : PeriodicOrbit
        The orbit there.
    """

    amplitude: float
    value: float
    where: str
    orbit: PeriodicOrbit


def branch_maximum(system: Any, branch: Branch, measure: int | Measure = 0, stable_only: bool = True, tolerance: float = 1e-10) -> BranchMaximum | None:
    """The largest ``measure`` over ``branch`` (its stable stretches only, by default).

    Parameters
    ----------
    system : ImpactMap
        The map the branch was continued on.
    branch : Branch
        From :func:`~vibroimpact.orbits.continuation.continue_branch`.
    measure : int or Measure
        A row of :mod:`vibroimpact.analysis.measures`, or a coordinate index for its |X| (0: the paper's primary mass).
    stable_only : bool
        Only stable orbits (the motions that can be observed), and the special points that bound them.
    tolerance : float
        Of the bounded search for an interior maximum, relative to the parameter [-].

    Returns
    -------
    BranchMaximum or None
        None where no orbit of the branch is stable (``stable_only``).
    """
    measure = as_measure(measure, system.problem)
    amplitude = measure.of_shot(branch_measures(system, branch))
    stable = np.asarray(branch.stable, dtype=bool) if stable_only else np.ones(amplitude.size, dtype=bool)
    candidates: list[BranchMaximum] = []
    for point in branch.special_points:
        if stable_only and float(np.max(np.abs(point.orbit.multipliers))) > 1.0 + STABLE_BOUNDARY:
            continue
        value = float(measure.of_shot(orbit_measures(system, point.orbit)))
        candidates.append(BranchMaximum(value, point.value, point.kind, point.orbit))
    for end in (0, amplitude.size - 1):
        if amplitude.size and stable[end]:
            candidates.append(BranchMaximum(float(amplitude[end]), float(branch.values[end]), "end", branch.orbits[end]))
    for i in range(1, amplitude.size - 1):
        if stable[i - 1 : i + 2].all() and amplitude[i] >= amplitude[i - 1] and amplitude[i] >= amplitude[i + 1]:
            refined = _interior(system, branch, i, measure, tolerance)
            candidates.append(refined if refined is not None else BranchMaximum(float(amplitude[i]), float(branch.values[i]), "interior", branch.orbits[i]))
    return max(candidates, key=lambda c: c.amplitude) if candidates else None


def _interior(system: Any, branch: Branch, i: int, measure: Measure, tolerance: float) -> BranchMaximum | None:
    """The maximum of ``measure`` between points i - 1 and i + 1 of ``branch``, by a bounded search in its parameter with
    each orbit shot from point i's state (None where the parameter is not monotone there or a shot fails)."""
    values = branch.values
    low, high = sorted((float(values[i - 1]), float(values[i + 1])))
    if not low < float(values[i]) < high:
        return None  # a turning point between: the fold is a candidate of its own
    index = list(branch.orbits[i].parameter_names).index(branch.parameter)
    base = branch.orbits[i]
    found: dict[float, PeriodicOrbit] = {}

    def negative(p: float) -> float:
        q = np.array(base.parameters, dtype=float)
        q[index] = p
        try:
            orbit = shoot(system, base.state, q)
        except ShootingError:
            return math.nan
        found[p] = orbit
        return -float(measure.of_shot(orbit_measures(system, orbit)))

    result = minimize_scalar(negative, bounds=(low, high), method="bounded", options={"xatol": tolerance * max(abs(low), abs(high), 1e-300)})
    if not math.isfinite(float(result.fun)) or float(result.x) not in found:
        return None
    return BranchMaximum(-float(result.fun), float(result.x), "interior", found[float(result.x)])


@dataclass(frozen=True, eq=False)
class WorstCase:
    """The largest stable |X| of a problem over a band (:func:`worst_response`).

    Attributes
    ----------
    amplitude : float
        |X| [m].
    frequency : float
        Where [Hz].
    motion : str
        Which motion sets it ("the contact-free orbit", "one impact per period", ...) and where on its branch.
    branches : tuple of (Branch, BranchMaximum or None)
        Every branch continued for it, with its own maximum.
    """

    amplitude: float
    frequency: float
    motion: str
    branches: tuple[tuple[Branch, BranchMaximum | None], ...]


def worst_response(problem: Any, band: tuple[float, float], measure: int | Measure = 0, scan: int = 301) -> WorstCase:
    """The largest stable ``measure`` (a coordinate index: its |X|) over ``band`` [Hz], over the contact-free orbit (in closed form, where
    it clears the stops) and every branch continued from a closed-form one-impact orbit (each root of eq. 16, the
    middle of each run of ``scan`` frequencies where it exists and is admissible), each located exactly
    (:func:`branch_maximum`). Kelvin-Voigt bumpers start from their rigid twin's closed-form orbit
    (:func:`~vibroimpact.orbits.bumper_screen.rigid_twin`: the same stops, rigid), shot on the bumpers' own map.
    Period-doubled branches and non-periodic attractors are not searched here.

    Raises
    ------
    ValueError
        A problem the closed form does not apply to (several stops that are not a symmetric pair, a free mass), nor
        its rigid twin where its stops are bumpers.
    """
    low, high = (float(f) for f in band)
    f = np.linspace(low, high, scan)
    base = ImpactMap(problem)
    measure = as_measure(measure, problem)
    index = base.parameter_names.index("frequency")

    def at_frequency(frequency: float) -> np.ndarray:
        p = base.parameters.copy()
        p[index] = frequency
        return p

    def linear(frequency: float) -> float:
        found = base.contact_free_orbit(at_frequency(frequency))
        if found is None or found.clearance < 0.0:
            return math.nan
        return float(measure.of_harmonics(base.problem_at(at_frequency(frequency)), 2.0 * math.pi * frequency, found.amplitudes.amplitudes))

    best = (-math.inf, math.nan, "")
    values = np.array([linear(x) for x in f])
    for i in np.flatnonzero(np.isfinite(values)):
        left = values[i - 1] if i > 0 else -math.inf
        right = values[i + 1] if i + 1 < values.size else -math.inf
        if values[i] >= np.nan_to_num(left, nan=-math.inf) and values[i] >= np.nan_to_num(right, nan=-math.inf):
            a, b = f[max(i - 1, 0)], f[min(i + 1, f.size - 1)]
            found = minimize_scalar(lambda x: -np.nan_to_num(linear(x), nan=0.0), bounds=(a, b), method="bounded", options={"xatol": 1e-12 * b})
            value, where = (-float(found.fun), float(found.x)) if -float(found.fun) >= values[i] else (float(values[i]), float(f[i]))
            if value > best[0]:
                best = (value, where, "the contact-free orbit")
    branches: list[tuple[Branch, BranchMaximum | None]] = []
    traced: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    bumpers = bumper_screen_refusal(problem) is None  # bumpers whose rigid twin has the closed forms
    for root in ("+", "-"):
        orbit = solve_impact_orbit(rigid_twin(problem) if bumpers else problem, frequency=f, root=root)
        ok = np.asarray(orbit.admissible(), dtype=bool).reshape(-1)
        runs = np.split(np.arange(f.size), np.flatnonzero(np.diff(ok.astype(int))) + 1)
        for run in runs:
            if not ok[run[0]]:
                continue
            start = float(f[run[len(run) // 2]])
            there = base.problem_at(at_frequency(start))
            system = ImpactMap(there)
            closed = rigid_twin(there) if bumpers else there
            single = solve_impact_orbit(closed, root=root)
            if not bumpers:
                x_start = float(measure.of_orbit(single).reshape(-1)[0])
                if any(_passes(known, start, x_start) for known in traced):
                    continue  # a branch already traced passes through this start
            try:
                shot = shoot(system, closed_form_state(closed, single), system.parameters)
            except ShootingError:
                continue
            if bumpers:  # the bumper's own orbit: is it on a branch already traced?
                if shot.impacts < 1 or any(_passes(known, start, float(measure.of_shot(orbit_measures(system, shot)))) for known in traced):
                    continue
            branch = continue_branch(system, shot, "frequency", ContinuationSettings(lower=low, upper=high))
            measured = branch_measures(system, branch)
            traced.append((branch.values, measure.of_shot(measured), branch.impacts))
            top = branch_maximum(system, branch, measure)
            branches.append((branch, top))
            if top is not None and top.amplitude > best[0]:
                best = (top.amplitude, top.value, f"{_motion(top)} ({top.where} of its branch)")
    return WorstCase(best[0], best[1], best[2], tuple(branches))


def _passes(known: tuple[np.ndarray, np.ndarray, np.ndarray], frequency: float, amplitude: float) -> bool:
    """Does a traced branch (values [Hz], |X| [m], impacts) pass through the one-impact orbit at ``frequency`` with
    |X| = ``amplitude``: a segment of one-impact points bracketing the frequency whose interpolated |X| is within
    1e-3 of it (relative)?"""
    values, amplitudes, impacts = known
    for i in range(values.size - 1):
        a, b = float(values[i]), float(values[i + 1])
        if impacts[i] == impacts[i + 1] == 1 and min(a, b) <= frequency <= max(a, b) and a != b:
            x = amplitudes[i] + (amplitudes[i + 1] - amplitudes[i]) * (frequency - a) / (b - a)
            if abs(x - amplitude) <= 1e-3 * amplitude:
                return True
    return False


def _motion(top: BranchMaximum) -> str:
    impacts = top.orbit.hybrid.impacts if top.orbit.hybrid is not None else 0
    period = top.orbit.period
    if impacts == 0:
        return "the contact-free orbit"
    return f"{impacts} impact{'s' if impacts != 1 else ''} per {period} period{'s' if period != 1 else ''}" if period != 1 else f"{impacts} impact{'s' if impacts != 1 else ''} per period"
