"""Branches seeded from the brute force: attractors that no branch from the closed form, a period doubling or a grazing
point reaches (e.g. R = 0.8, a two-impact orbit with X1 up to ~9 mm over 20.6-25.9 Hz; R = 0.2, period 3-8 orbits
with 2-4 impacts over 34-39 Hz).

Where a brute-force sweep's strobes repeat with a period k (:data:`~vibroimpact.study.bifurcation_cases.MAX_PERIOD`)
the end state is a seed (:class:`Seed`). Each seed is shot as a fixed point of ``ImpactMap(problem, periods=k)`` in
the sweep's own section (force phase 0, strobes at t = 0 mod T, as the sweep), measured, and skipped when a known
branch passes through the same orbit (same period and impacts per orbit period, impulse within
:data:`~vibroimpact.study.bifurcation_branches.SAME_ORBIT` at that frequency). A new orbit is moved to a strobe away
from its impacts (:func:`vibroimpact.orbits.maps.resection`), shot again there and continued in frequency both ways
with its special points. A seed whose orbit is unstable is no attractor (the sweep's strobes only nearly repeated) and
is skipped. The middle of each run of like seeds (same sweep, period and impact count over consecutive frequencies)
is tried first, the longest runs first, then the other seeds; at most ``max_branches`` branches are added per
restitution.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.branch import lower_period_maps
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap, orbit_measures, resection
from vibroimpact.orbits.shooting import ShootingError, shoot
from vibroimpact.study.bifurcation_branches import OrbitSet, map_bounds, problem_at, stop_values

__all__ = ["Seed", "MAX_SEEDED_BRANCHES", "SEEDED_MAX_STEPS", "sweep_seeds", "seed_branches"]

#: Most branches seeded from the brute force per restitution.
MAX_SEEDED_BRANCHES = 16
#: Most continuation steps per direction of a seeded branch (a many-impact orbit may creep towards a degenerate end,
#: e.g. multipliers growing without bound at fixed frequency, in ever smaller steps).
SEEDED_MAX_STEPS = 600


@dataclass(frozen=True)
class Seed:
    """A brute-force point whose strobes repeat: frequency [Hz], period k [excitation periods], the state (x, x') at
    the strobe (t = 0 mod T, the problem's force phase) [m, m s-1], 2N entries, and the run of like points it belongs
    to (sweep, first and last frequency index)."""

    frequency: float
    period: int
    state: tuple[float, ...]
    run: tuple[int, int, int] = (0, 0, 0)


def sweep_seeds(frequency: NDArray[np.float64], period: NDArray[np.int_], impacts: NDArray[np.float64], state: NDArray[np.float64], sweep: int = 0) -> list[Seed]:
    """The seeds of one sweep (points with a period >= 1 and some impact), the middle of each run of like points first.

    Parameters
    ----------
    frequency : ndarray, shape (n,)
        The sweep's frequencies [Hz].
    period : ndarray of int, shape (n,)
        The period its strobes repeat with (0: they do not).
    impacts : ndarray, shape (n,)
        Impacts per excitation period.
    state : ndarray, shape (n, 2N)
        The end state at each frequency (a strobe).
    sweep : int
        A label of the sweep (kept in each seed's ``run``).
    """
    n = frequency.size
    kind = [(int(period[i]), int(round(float(impacts[i]) * int(period[i])))) for i in range(n)]
    usable = [kind[i][0] >= 1 and kind[i][1] >= 1 and bool(np.all(np.isfinite(state[i]))) for i in range(n)]
    runs, i = [], 0
    while i < n:
        j = i
        while j + 1 < n and usable[i] and usable[j + 1] and kind[j + 1] == kind[i]:
            j += 1
        if usable[i]:
            runs.append((i, j))
        i = j + 1
    first, rest = [], []
    for a, b in runs:
        middle = (a + b) // 2
        for k in range(a, b + 1):
            seed = Seed(float(frequency[k]), kind[k][0], tuple(float(x) for x in state[k]), (sweep, a, b))
            (first if k == middle else rest).append(seed)
    first.sort(key=lambda s: s.run[1] - s.run[2])  # the longest runs (the most robust attractors) first
    rest.sort(key=lambda s: abs(s.frequency - 0.5 * (frequency[s.run[1]] + frequency[s.run[2]])))
    return first + rest


def seed_branches(
    found: OrbitSet, problem: ImpactProblem, low: float, high: float,
    seeds: Sequence[Seed], settings: ContinuationSettings, max_branches: int = MAX_SEEDED_BRANCHES, progress: Callable[[str], None] | None = None,
) -> int:  # fmt: skip
    """Continue a branch from every seed no known branch passes through (module docstring); return how many.

    Parameters
    ----------
    found : OrbitSet
        The branches known so far; the new ones are added.
    problem : ImpactProblem
        Structure, rigid stops (the sweep's restitution and clearance) and harmonic load, as the sweep ran it.
    low, high : float
        The band [Hz].
    seeds : sequence of Seed
        From :func:`sweep_seeds`, in the order to try.
    settings : ContinuationSettings
        Of the continuation (its steps capped at :data:`SEEDED_MAX_STEPS`).
    max_branches : int
        Most branches added.
    progress : callable, optional
        Gets a line per branch.
    """
    engine = ExactEngine()
    restitution = stop_values(problem)[1]
    bounds = map_bounds(low, high)
    settings = dataclasses.replace(settings, max_steps=min(settings.max_steps, SEEDED_MAX_STEPS))
    added, skipped, failed, unstable = 0, 0, 0, 0
    for seed in seeds:
        if added >= max_branches:
            found.notes.append(f"brute-force seeds: stopped after {max_branches} new branches ({len(seeds)} seeds)")
            break
        at = problem_at(problem, seed.frequency)
        sweep_map = ImpactMap(at, seed.period, engine, bounds)
        try:
            orbit = shoot(sweep_map, np.array(seed.state), sweep_map.parameters)
        except ShootingError:
            failed += 1
            continue
        period = seed.period
        for d, lower in reversed(lower_period_maps(sweep_map)):  # a slowly settled point may repeat after a multiple
            if np.max(np.abs(lower.evaluate(orbit.state, orbit.parameters).image - orbit.state) / sweep_map.state_scale) < 1e-7:
                period, sweep_map = d, ImpactMap(at, d, engine, bounds)
                orbit = shoot(sweep_map, orbit.state, sweep_map.parameters)
                break
        if not orbit.stable:  # not the attractor the sweep settled on (its strobes only nearly repeated)
            unstable += 1
            continue
        measures = orbit_measures(sweep_map, orbit)
        impulse = float(measures.impulses.sum()) / period
        if found.known(seed.frequency, period, int(measures.impulses.size), impulse):
            skipped += 1
            continue
        try:
            moved, state = resection(at, orbit.state, period, engine)
            mapping = ImpactMap(moved, period, engine, bounds)
            start = shoot(mapping, state, mapping.parameters)
            branch = continue_branch(mapping, start, "frequency", settings)
        except (ShootingError, RuntimeError, ValueError) as error:
            found.notes.append(f"brute-force seed at {seed.frequency:.3f} Hz (period {seed.period}) failed: {type(error).__name__}: {str(error)[:160]}")
            failed += 1
            continue
        label = found.add_branch(mapping, branch, "brute_force")
        found.maps.append((mapping, branch))
        added += 1
        found.notes[-1] += f"; seeded at {seed.frequency:.3f} Hz, period {period}, {measures.impulses.size} impacts, max |mu| = {orbit.floquet_modulus:.4g} there"
        if progress is not None:
            progress(f"R = {restitution:g}: branch {label} from the brute force at {seed.frequency:.3f} Hz (period {period}): {len(branch.orbits)} points")
    found.notes.append(f"brute-force seeds: {len(seeds)}, {added} new branches, {skipped} on known branches, {unstable} unstable (no attractor), {failed} not converged")
    return added
