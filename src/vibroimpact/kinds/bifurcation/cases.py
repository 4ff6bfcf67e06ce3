"""The work of a bifurcation study as runner cases (:mod:`vibroimpact.runs.runner`): brute-force sweeps, the branches
of one restitution, and the two-parameter chart's curves.

* :class:`SweepCase`: a stepped sweep over frequencies (up or down) of the engine with exact Jacobians for the
  problem's contact law, the end state carried to the next frequency, each point's motion measured and classified
  (:data:`MOTION_CLASSES`): :func:`vibroimpact.simulation.attractors.stepped_sweep`, as a runner case.
* :class:`BranchCase`: :func:`vibroimpact.kinds.bifurcation.branches.find_branches` of one restitution.
* :class:`ChartCase`: the special points of the chart's restitution followed in (frequency, clearance), from the
  branches of its own continuation (their labels and frequency ranges are returned too): folds, period
  doublings and Neimark-Sacker points continued (:func:`vibroimpact.orbits.continuation.continue_special_point`), the
  points where a free flight of an orbit touches the stop traced by repeated location
  (:func:`vibroimpact.orbits.grazing_curve.trace_grazing`), and the closed-form orbit's vanishing impact velocity
  (where the linear motion reaches a stop, max_k |n_k H F| + n_k K^-1 F0 = Delta: q |H12| = Delta on the paper's
  layout) from the linear response.

Every case holds the general problem (:class:`~vibroimpact.model.problem.ImpactProblem`: structure, a tuple of rigid
stops sharing one clearance and restitution, harmonic load) and moves it in frequency (and clearance) with
:func:`~vibroimpact.kinds.bifurcation.branches.problem_at`.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any
from dataclasses import dataclass, asdict

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.engines.registry import RIGID, engine_for, make_engine
from vibroimpact.kinds.bifurcation.logs import FAILURE_FIELDS, failure_arrays
from vibroimpact.kinds.bifurcation.slow_seeds import SLOW_SEED_FIELDS, SeedOutcome, continue_seed_orbit, settle_seed, slow_seed_arrays
from vibroimpact.kinds.bifurcation.born import grow_at_grazing
from vibroimpact.kinds.bifurcation.branches import OrbitSet, map_bounds, problem_at, stop_values, MAX_ORBIT_IMPACTS, find_branches
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.units import length_unit
from vibroimpact.orbits.branch import lower_period_maps, SPECIAL_POINT_KINDS, Iterated
from vibroimpact.orbits.continuation import continue_special_point, ContinuationSettings, continue_branch
from vibroimpact.orbits.grazing_curve import trace_grazing
from vibroimpact.orbits.maps import ImpactMap, resection
from vibroimpact.orbits.orbit_measures import orbit_measures
from vibroimpact.orbits.shooting import ShootingError, shoot
from vibroimpact.runs.runner import CaseResult, ProgressReport
from vibroimpact.runs.fingerprints import case_key
from vibroimpact.simulation.settling import SettledMotion
from vibroimpact.simulation.attractors import MAX_KEPT_IMPACTS, MOTION_CLASSES, SWEEP_FIELDS, stepped_sweep

__all__ = ["Seed", "MAX_SEEDED_BRANCHES", "SEEDED_MAX_STEPS", "sweep_seeds", "seed_branches", "MOTION_CLASSES", "MAX_KEPT_IMPACTS", "SweepCase", "BranchCase", "ChartCase", "branch_arrays"]


# --------------------------------------------------------------------------------------------------------------------
# Branches seeded from the brute force: attractors that no branch from the closed form, a period doubling or a grazing
# point reaches (e.g. R = 0.8, a two-impact orbit with X1 up to ~9 mm over 20.6-25.9 Hz; R = 0.2, period 3-8 orbits
# with 2-4 impacts over 34-39 Hz).
# --------------------------------------------------------------------------------------------------------------------

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
        Structure, stops (rigid or bumpers: the sweep's restitution and clearance) and harmonic load, as the sweep ran it.
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
    engine = make_engine(engine_for(problem.contact_law, "exact_jacobians"))  # the sweep's: rigid stops or bumpers
    restitution = stop_values(problem)[1]
    bounds = map_bounds(low, high)
    settings = dataclasses.replace(settings, max_steps=min(settings.max_steps, SEEDED_MAX_STEPS))
    added, skipped, failed, unstable = 0, 0, 0, 0
    slow: list[tuple[Seed, ShootingError]] = []
    for seed in seeds:
        if added >= max_branches:
            found.notes.append(f"brute-force seeds: stopped after {max_branches} new branches ({len(seeds)} seeds)")
            break
        at = problem_at(problem, seed.frequency)
        sweep_map = ImpactMap(at, seed.period, engine, bounds)
        period = seed.period
        found.attempted("seed")
        try:
            orbit = shoot(sweep_map, np.array(seed.state), sweep_map.parameters)
            for d, lower in reversed(lower_period_maps(sweep_map)):  # a slowly settled point may repeat after a multiple
                if np.max(np.abs(lower.evaluate(orbit.state, orbit.parameters).image - orbit.state) / sweep_map.state_scale) < 1e-7:
                    period, sweep_map = d, ImpactMap(at, d, engine, bounds)
                    orbit = shoot(sweep_map, orbit.state, sweep_map.parameters)
                    break
        except ShootingError as error:
            if np.all(np.isfinite(seed.state)):
                slow.append((seed, error))  # a motion still settling: run on, after the other seeds (slow_seeds)
            else:
                found.failed("seed", _seed_failure(seed, error))
                failed += 1
            continue
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
            found.failed("seed", _seed_failure(seed, error))
            failed += 1
            continue
        label = found.add_branch(mapping, branch, "brute_force")
        found.maps.append((mapping, branch))
        added += 1
        found.notes[-1] += f"; seeded at {seed.frequency:.3f} Hz, period {period}, {measures.impulses.size} impacts, max |mu| = {orbit.floquet_modulus:.4g} there"
        if progress is not None:
            progress(f"R = {restitution:g}: branch {label} from the brute force at {seed.frequency:.3f} Hz (period {period}): {len(branch.orbits)} points")
    count = found.count
    settled = _settle_slow_seeds(found, problem, slow, bounds, settings, engine, max_branches - added)
    failed += sum(outcome.outcome == "failed" for outcome in settled)
    added += found.count - count
    kinds = Counter(outcome.outcome for outcome in settled if outcome.outcome != "failed")
    what = ", ".join(f"{count} {SETTLED_WORDS[kind]}" for kind, count in kinds.items())
    found.notes.append(f"brute-force seeds: {len(seeds)}, {added} new branches, {skipped} on known branches, {unstable} unstable (no attractor), "
                       f"{len(slow)} settling slowly{' (' + what + ')' if what else ''}, {failed} failed")  # fmt: skip
    return added


#: How the seeds' summary note counts each outcome of a slowly settling seed.
SETTLED_WORDS = {"periodic": "periodic", "quasi_periodic": "on a torus", "chaotic": "chaotic", "undecided": "undecided"}


def _settle_slow_seeds(
    found: OrbitSet, problem: ImpactProblem, slow: Sequence[tuple[Seed, ShootingError]], bounds: dict[str, tuple[float, float]], settings: ContinuationSettings, engine: Any,
    room: int,
) -> list[SeedOutcome]:  # fmt: skip
    """Run on the motion of every seed shooting did not converge from, say what it reached in ``found.notes`` and
    ``found.settled`` (an engine's failure as a failure), and continue the periodic orbits found, at most ``room``
    new branches (:mod:`~vibroimpact.kinds.bifurcation.slow_seeds`)."""
    outcomes = []
    for seed, error in slow:
        at = problem_at(problem, seed.frequency)
        history = getattr(error, "residual_history", ())
        residual = (f"residual {history[0]:.3g} at the start" if np.isfinite(history[0]) else "the map has no value at its strobe") if history else str(error)[:120]

        def orbit_of(motion: SettledMotion, at: ImpactProblem = at) -> tuple[int, str]:
            return continue_seed_orbit(found, at, motion, bounds, settings, engine, room > 0)

        before = found.count
        outcome = settle_seed(found, at, seed.frequency, seed.period, np.array(seed.state), residual, orbit_of, engine)
        room -= found.count - before
        if outcome.outcome == "failed":
            found.failed("seed", outcome.text)
        else:
            found.notes.append(outcome.text)
        found.settled.append(outcome)
        outcomes.append(outcome)
    return outcomes


def _seed_failure(seed: Seed, error: Exception) -> str:
    """The raw message of a seed that failed (one line)."""
    return f"brute-force seed at {seed.frequency:.3f} Hz (period {seed.period}) failed: {type(error).__name__}: {str(error)[:160]}"


@dataclass(frozen=True, eq=False)
class SweepCase:
    """A stepped brute-force sweep of ``problem`` (its restitution and clearance; rigid stops or Kelvin-Voigt
    bumpers) in one direction over ``frequencies`` [Hz] with ``engine`` (a registry name with exact Jacobians for the
    problem's contact law); ``strobe`` and ``amplitude`` are the first coordinate's
    (:func:`vibroimpact.simulation.attractors.stepped_sweep`)."""

    problem: ImpactProblem
    direction: str
    frequencies: tuple[float, ...]
    transient: int
    strobes: int
    engine: str = engine_for(RIGID, "exact_jacobians")  # the registry's, by capability: exact Jacobians for the problem's contact law
    fields: tuple[str, ...] = SWEEP_FIELDS
    progress_unit: str = "frequency points"

    @property
    def progress_total(self) -> float:
        """Frequency points."""
        return float(len(self.frequencies))

    def key(self) -> str:
        """Hash of everything that determines the result."""
        return case_key({"kind": "bifurcation_sweep", **asdict(self)})

    def run(self, report: ProgressReport | None = None) -> CaseResult:
        """Arrays over the frequencies in increasing order (whatever the direction); ``error``: the raw message where
        the engine failed (``regime`` -1), else empty."""
        return stepped_sweep(self.problem, self.direction, self.frequencies, self.transient, self.strobes, make_engine(self.engine), report)


#: Fields of :func:`branch_arrays`.
BRANCH_FIELDS = (
    "branch", "origin", "frequency", "amplitudes", "impulse", "floquet_modulus", "stable", "impacts", "period",
    "multipliers_real", "multipliers_imag", "velocities",
    "sp_branch", "sp_kind", "sp_frequency", "sp_amplitudes", "sp_impulse", "sp_floquet_modulus", "sp_impacts", "sp_period",
    "sp_multipliers_real", "sp_multipliers_imag", "sp_note", "sp_found_on", "notes", "absent", *FAILURE_FIELDS, *SLOW_SEED_FIELDS,
)  # fmt: skip


@dataclass(frozen=True, eq=False)
class BranchCase:
    """Every branch of ``problem``'s restitution (:func:`find_branches`); arrays from :func:`branch_arrays`."""

    problem: ImpactProblem
    low: float
    high: float
    options: tuple[tuple[str, object], ...]
    seeds: tuple[Seed, ...] = ()
    engine: str = "exact"
    fields: tuple[str, ...] = BRANCH_FIELDS
    progress_unit: str = "branch sets"

    @property
    def restitution(self) -> float:
        """R [-] of the problem's stops."""
        return stop_values(self.problem)[1]

    @property
    def progress_total(self) -> float:
        """One unit per branch set."""
        return 1.0

    def key(self) -> str:
        """Hash of everything that determines the result."""
        return case_key({"kind": "bifurcation_branches", "problem": asdict(self.problem), "band": [self.low, self.high], "options": dict(self.options),
                         "seeds": [asdict(seed) for seed in self.seeds]})  # fmt: skip

    def run(self, report: ProgressReport | None = None) -> CaseResult:
        """The branches' and special points' arrays."""
        options = dict(self.options)
        brute_force = bool(options.pop("brute_force", True))
        found = find_branches(self.problem, self.low, self.high, **options)
        if brute_force and self.seeds:
            settings = ContinuationSettings(lower=self.low, upper=self.high, max_steps=int(options.get("max_steps", 2000)), max_step=float(options.get("max_step", 0.1)), stop_at_grazing=True)
            first = len(found.maps)
            seed_branches(found, self.problem, self.low, self.high, self.seeds, settings)
            if bool(options.get("grazing", True)):  # the seeded branches' grazing points, as the others' (branches.find_branches)
                grow_at_grazing(found, found.maps, settings, first)
        return branch_arrays(found, self.problem.size)


def branch_arrays(found: OrbitSet, size: int) -> CaseResult:
    """Flat arrays of an :class:`OrbitSet` of a structure of ``size`` coordinates (one row per branch point, one per
    special point; amplitudes (rows, N), multipliers (rows, 2N); ``sp_found_on``: the labels of every branch a special
    point was found on, space-separated; ``absent``: the closed-form starts a bumper has no orbit for, a line each)."""

    def column(rows: list[dict], name: str, dtype: type = float) -> np.ndarray:
        return np.array([row[name] for row in rows], dtype=dtype)

    def velocities(rows: list[dict]) -> np.ndarray:
        out = np.full((len(rows), MAX_ORBIT_IMPACTS), np.nan)
        for i, row in enumerate(rows):
            out[i, : row["velocities"].size] = row["velocities"]
        return out

    def table(rows: list[dict], name: str, width: int, dtype: type = float) -> np.ndarray:
        return np.array([row[name] for row in rows], dtype=dtype).reshape(-1, width)

    points, specials = found.points, found.specials
    pm, sm = table(points, "multipliers", 2 * size, complex), table(specials, "multipliers", 2 * size, complex)
    return {
        "branch": column(points, "branch", int), "origin": column(points, "origin", int), "frequency": column(points, "frequency"),
        "amplitudes": table(points, "amplitudes", size), "impulse": column(points, "impulse"),
        "floquet_modulus": column(points, "floquet_modulus"), "stable": column(points, "stable", int), "impacts": column(points, "impacts", int),
        "period": column(points, "period", int), "multipliers_real": pm.real, "multipliers_imag": pm.imag, "velocities": velocities(points),
        "sp_branch": column(specials, "branch", int), "sp_kind": column(specials, "kind", int), "sp_frequency": column(specials, "frequency"),
        "sp_amplitudes": table(specials, "amplitudes", size), "sp_impulse": column(specials, "impulse"),
        "sp_floquet_modulus": column(specials, "floquet_modulus"), "sp_impacts": column(specials, "impacts", int),
        "sp_period": column(specials, "period", int), "sp_multipliers_real": sm.real, "sp_multipliers_imag": sm.imag,
        "sp_induced_by": np.array([row.get("induced_by", np.nan) for row in specials], dtype=float),  # (NaN: a smooth point)
        "sp_note": np.array([row["note"] for row in specials], dtype=str), "sp_found_on": np.array([" ".join(map(str, row["found_on"])) for row in specials], dtype=str),
        "notes": np.array(found.notes, dtype=str), "absent": np.array(found.absent, dtype=str), **failure_arrays(found.attempts, found.failures),
        **slow_seed_arrays(found.settled),
    }  # fmt: skip



@dataclass(frozen=True, eq=False)
class ChartCase:
    """Curves of special points in (frequency, clearance) at ``problem``'s restitution, from the branches at its
    clearance."""

    problem: ImpactProblem
    low: float
    high: float
    clearance_range: tuple[float, float]
    kinds: tuple[str, ...]
    max_steps: int
    engine: str = "exact"
    fields: tuple[str, ...] = ("curve", "kind", "frequency", "clearance", "notes", "branch_label", "branch_origin", "branch_low", "branch_high", *FAILURE_FIELDS)
    progress_unit: str = "charts"

    @property
    def progress_total(self) -> float:
        """One unit."""
        return 1.0

    def key(self) -> str:
        """Hash of everything that determines the result."""
        return case_key({"kind": "bifurcation_chart", **asdict(self)})

    def run(self, report: ProgressReport | None = None) -> CaseResult:
        """The curves as flat arrays (one row per curve point)."""
        found = find_branches(self.problem, self.low, self.high, grazing=False, linear=False)
        clearance = stop_values(self.problem)[0]
        low_c, high_c = self.clearance_range
        bounds = {"clearance": (low_c, high_c), "frequency": (self.low, self.high)}
        settings = ContinuationSettings(max_steps=self.max_steps, max_step=0.2, stop_at_grazing=True)
        rows: list[tuple[int, int, float, float]] = []
        notes = list(found.notes)
        attempts = {f"chart_{kind}": count for kind, count in found.attempts.items()}  # the chart's own branches
        failures = [(f"chart_{kind}", detail) for kind, detail in found.failures]
        curve = 0
        if "grazing" in self.kinds:
            for f, d in _grazing_curves(self.problem, self.low, self.high, low_c, high_c):
                rows += [(curve, SPECIAL_POINT_KINDS.index("grazing"), fi, di) for fi, di in zip(f, d)]
                curve += 1
        for mapping, branch in found.maps:
            system = Iterated(mapping, branch.orbits[0].period) if branch.orbits[0].period > 1 else mapping
            for point in branch.special_points:
                kind = SPECIAL_POINT_KINDS.index(point.kind)
                if point.kind not in self.kinds or (point.kind == "grazing" and "velocity" in point.note):
                    continue  # the closed-form orbit's vanishing impact: the linear-response curve above
                if point.induced_by is not None:
                    continue  # induced by a contact onset (multipliers jump there): no smooth extended system
                if any(k == kind and abs(f - point.value) < 1e-3 and abs(d - clearance) < 1e-6 for _c, k, f, d in rows):
                    continue  # on a curve already followed
                attempts["curve"] = attempts.get("curve", 0) + 1
                try:
                    if point.kind == "grazing":  # not differentiable there: located again at each clearance
                        special = trace_grazing(system, point, "clearance", bounds)
                        how = f"traced by location ({special.measure})"
                    else:
                        special = continue_special_point(system, point, "clearance", settings, bounds=bounds)
                        how = "continued"
                except Exception as error:  # noqa: BLE001 - a curve that cannot be followed is recorded, not fatal
                    failures.append(("curve", f"{point.kind} curve from {point.value:.4f} Hz failed: {type(error).__name__}: {str(error)[:160]}"))
                    notes.append(failures[-1][1])
                    continue
                f, d = special.values("frequency"), special.values("clearance")
                notes.append(f"{point.kind} curve {curve} from {point.value:.4f} Hz {how}: {f.size} points, {_span(d, clearance)}, ends: {special.end}")
                rows += [(curve, kind, fi, di) for fi, di in zip(f, d)]
                curve += 1
        table = np.array(rows, dtype=float).reshape(-1, 4)
        return {"curve": table[:, 0].astype(int), "kind": table[:, 1].astype(int), "frequency": table[:, 2], "clearance": table[:, 3], "notes": np.array(notes, dtype=str), **_branch_ranges(found),
                **failure_arrays(attempts, failures)}  # fmt: skip


def _span(clearances: np.ndarray, magnitude: float) -> str:
    """The clearances of a curve [m] as "0.500-6.000 mm", in the unit of ``magnitude`` [m]."""
    unit, factor = length_unit(magnitude)
    return f"{clearances.min() * factor:.3f}-{clearances.max() * factor:.3f} {unit}"


def _branch_ranges(found: OrbitSet) -> CaseResult:
    """Label, origin flag and frequency range [Hz] of each branch of ``found`` (``branch_label``, ``branch_origin``,
    ``branch_low``, ``branch_high``)."""
    labels = sorted({int(point["branch"]) for point in found.points})
    frequency = {label: [point["frequency"] for point in found.points if point["branch"] == label] for label in labels}
    origin = {int(point["branch"]): int(point["origin"]) for point in found.points}
    return {
        "branch_label": np.array(labels, dtype=int), "branch_origin": np.array([origin[k] for k in labels], dtype=int),
        "branch_low": np.array([min(frequency[k]) for k in labels]), "branch_high": np.array([max(frequency[k]) for k in labels]),
    }  # fmt: skip


def _grazing_curves(problem: ImpactProblem, low: float, high: float, low_c: float, high_c: float, step: float = 0.01) -> list[tuple[np.ndarray, np.ndarray]]:
    """Delta = max_k (|n_k H F(f)| + n_k K^-1 F0) over the band (q |H12(f)| on the paper's layout), split where it
    leaves [low_c, high_c]: where the closed-form orbit's impact velocity vanishes and the linear orbit touches a stop
    (every stop sharing the clearance Delta)."""
    f = np.arange(low, high + 0.5 * step, step)
    linear = linear_amplitudes(problem, omega=2.0 * np.pi * f)
    d = np.max(np.abs(linear.stop_amplitudes) + linear.stop_static, axis=-1)
    inside = (d >= low_c) & (d <= high_c)
    runs = np.split(np.flatnonzero(inside), np.flatnonzero(np.diff(np.flatnonzero(inside)) > 1) + 1)
    return [(f[r], d[r]) for r in runs if r.size > 1]
