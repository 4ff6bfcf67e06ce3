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

from vibroimpact.orbits.branch import Branch, PeriodicOrbit
from vibroimpact.orbits.maps import branch_measures, orbit_measures
from vibroimpact.orbits.shooting import ShootingError, shoot

__all__ = ["BranchMaximum", "branch_maximum", "STABLE_BOUNDARY"]

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


def branch_maximum(system: Any, branch: Branch, coordinate: int = 0, stable_only: bool = True, tolerance: float = 1e-10) -> BranchMaximum | None:
    """The largest |X| of ``coordinate`` over ``branch`` (its stable stretches only, by default).

    Parameters
    ----------
    system : ImpactMap
        The map the branch was continued on.
    branch : Branch
        From :func:`~vibroimpact.orbits.continuation.continue_branch`.
    coordinate : int
        0: the paper's primary mass.
    stable_only : bool
        Only stable orbits (the motions that can be observed), and the special points that bound them.
    tolerance : float
        Of the bounded search for an interior maximum, relative to the parameter [-].

    Returns
    -------
    BranchMaximum or None
        None where no orbit of the branch is stable (``stable_only``).
    """
    measures = branch_measures(system, branch)
    amplitude = measures.amplitude(coordinate)
    stable = np.asarray(branch.stable, dtype=bool) if stable_only else np.ones(amplitude.size, dtype=bool)
    candidates: list[BranchMaximum] = []
    for point in branch.special_points:
        if stable_only and float(np.max(np.abs(point.orbit.multipliers))) > 1.0 + STABLE_BOUNDARY:
            continue
        value = float(orbit_measures(system, point.orbit).amplitudes[coordinate])
        candidates.append(BranchMaximum(value, point.value, point.kind, point.orbit))
    for end in (0, amplitude.size - 1):
        if amplitude.size and stable[end]:
            candidates.append(BranchMaximum(float(amplitude[end]), float(branch.values[end]), "end", branch.orbits[end]))
    for i in range(1, amplitude.size - 1):
        if stable[i - 1 : i + 2].all() and amplitude[i] >= amplitude[i - 1] and amplitude[i] >= amplitude[i + 1]:
            refined = _interior(system, branch, i, coordinate, tolerance)
            candidates.append(refined if refined is not None else BranchMaximum(float(amplitude[i]), float(branch.values[i]), "interior", branch.orbits[i]))
    return max(candidates, key=lambda c: c.amplitude) if candidates else None


def _interior(system: Any, branch: Branch, i: int, coordinate: int, tolerance: float) -> BranchMaximum | None:
    """The maximum of |X| between points i - 1 and i + 1 of ``branch``, by a bounded search in its parameter with
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
        return -float(orbit_measures(system, orbit).amplitudes[coordinate])

    result = minimize_scalar(negative, bounds=(low, high), method="bounded", options={"xatol": tolerance * max(abs(low), abs(high), 1e-300)})
    if not math.isfinite(float(result.fun)) or float(result.x) not in found:
        return None
    return BranchMaximum(-float(result.fun), float(result.x), "interior", found[float(result.x)])
