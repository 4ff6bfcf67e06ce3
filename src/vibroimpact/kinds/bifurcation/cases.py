"""The work of a bifurcation study as runner cases (:mod:`vibroimpact.runs.runner`): brute-force sweeps, the branches
of one restitution, and the two-parameter chart's curves.

* :class:`SweepCase`: a stepped sweep over frequencies (up or down) of the engine with exact Jacobians for the
  problem's contact law (the compiled exact engine for rigid stops, the bumper's closed-form engine for Kelvin-Voigt
  bumpers), the end state carried to the next frequency; at each frequency a transient is dropped, then the strobes of the first coordinate (X1 on the
  paper's layout), its per-period fundamental and the impact velocities are kept and the motion is classified (:data:`MOTION_CLASSES`): linear, one impact per period,
  another periodic motion, or, where the strobes do not repeat, quasi-periodic, chaotic or irregular from the exact
  Jacobians (:func:`vibroimpact.orbits.motion.classify_motion`; from the strobes alone where a Jacobian is undefined,
  :func:`~vibroimpact.orbits.motion.classify_strobes`). A strictly negative Lyapunov exponent means a periodic
  orbit approached slowly: the motion is classified by the period that repeats best.
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
import math
from collections.abc import Callable, Sequence
from typing import Any
from dataclasses import dataclass, asdict

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.engines.registry import RIGID, engine_for, make_engine
from vibroimpact.kinds.bifurcation.logs import FAILURE_FIELDS, failure_arrays
from vibroimpact.kinds.bifurcation.branches import OrbitSet, map_bounds, problem_at, stop_values, MAX_ORBIT_IMPACTS, find_branches
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.units import length_unit
from vibroimpact.orbits.branch import lower_period_maps, SPECIAL_POINT_KINDS, Iterated
from vibroimpact.orbits.continuation import continue_special_point, ContinuationSettings, continue_branch
from vibroimpact.orbits.grazing_curve import trace_grazing
from vibroimpact.orbits.maps import ImpactMap, orbit_measures, resection
from vibroimpact.orbits.motion import classify_motion, classify_strobes
from vibroimpact.orbits.shooting import ShootingError, shoot
from vibroimpact.runs.runner import CaseResult, ProgressReport
from vibroimpact.runs.store import case_key
from vibroimpact.simulation.harmonics import linear_state, resting_state

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
    found.notes.append(f"brute-force seeds: {len(seeds)}, {added} new branches, {skipped} on known branches, {unstable} unstable (no attractor), {failed} not converged")
    return added


def _seed_failure(seed: Seed, error: Exception) -> str:
    """The raw message of a seed that failed (one line)."""
    return f"brute-force seed at {seed.frequency:.3f} Hz (period {seed.period}) failed: {type(error).__name__}: {str(error)[:160]}"


#: What the motion at a brute-force point is (CF flags of ``brute_regime`` and ``chart_regime``, values 0...).
MOTION_CLASSES = ("linear", "one_impact", "other_periodic", "quasi_periodic", "chaotic", "irregular")
#: Impact velocities kept per brute-force point (NaN-padded).
MAX_KEPT_IMPACTS = 64
#: Longest period looked for in the strobes [periods] (the strobes kept must cover it twice).
MAX_PERIOD = 32
#: Strobes repeat when they differ by less than this, relative to the motion's length (Delta + q |H12| on the paper's
#: layout, :meth:`ImpactProblem.velocity_scale` / w in general; velocities: times w) [-].
REPEAT_TOLERANCE = 1e-6


@dataclass(frozen=True, eq=False)
class SweepCase:
    """A stepped brute-force sweep of ``problem`` (its restitution and clearance; rigid stops or Kelvin-Voigt
    bumpers) in one direction over ``frequencies`` [Hz] with ``engine`` (a registry name with exact Jacobians for the
    problem's contact law); ``strobe`` and ``amplitude`` are the first coordinate's."""

    problem: ImpactProblem
    direction: str
    frequencies: tuple[float, ...]
    transient: int
    strobes: int
    engine: str = engine_for(RIGID, "exact_jacobians")  # the registry's, by capability: exact Jacobians for the problem's contact law
    fields: tuple[str, ...] = ("strobe", "amplitude", "velocity", "impacts", "regime", "period", "lyapunov", "state", "error")
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
        engine = make_engine(self.engine)
        f = np.array(self.frequencies)
        order = np.argsort(f) if self.direction == "up" else np.argsort(f)[::-1]
        n, s, width = f.size, self.strobes, 2 * self.problem.size
        out = {
            "strobe": np.full((n, s), np.nan), "amplitude": np.full((n, s), np.nan), "velocity": np.full((n, MAX_KEPT_IMPACTS), np.nan),
            "impacts": np.zeros(n), "regime": np.full(n, -1, dtype=np.int8), "period": np.zeros(n, dtype=np.int16), "lyapunov": np.full(n, np.nan),
            "state": np.full((n, width), np.nan),
        }  # fmt: skip
        state = None
        errors = [""] * n
        for done, k in enumerate(order):
            problem = problem_at(self.problem, float(f[k]))
            state = _linear_start(problem) if state is None else state
            try:
                state = _measure(engine, problem, state, self.transient, s, out, k)
            except RuntimeError as error:  # the engine made no progress (endless chattering): start the next point at rest
                state = resting_state(problem)
                errors[k] = f"{type(error).__name__}: {str(error)[:160]}"
            if report is not None:
                report(done + 1)
        return out | {"error": np.array(errors, dtype=str)}


def _linear_start(problem: ImpactProblem) -> NDArray[np.float64]:
    """The linear steady state at t = 0 if it fits inside every stop, else rest on the stops."""
    linear = linear_state(problem)
    return linear.state(problem.omega) if linear.fits(problem) else resting_state(problem)


def _measure(engine: Any, problem: ImpactProblem, state: NDArray[np.float64], transient: int, strobes: int, out: dict, k: int) -> NDArray[np.float64]:
    """Drop the transient, keep ``strobes`` periods at row ``k`` of ``out``; return the end state."""
    if transient:
        state = engine.integrate(problem, state, 0.0, transient).final_state
    run = engine.integrate(problem, state, 0.0, strobes, moments=True, jacobians=True)
    s = run.strobe_states
    out["state"][k] = run.final_state
    out["strobe"][k] = s[1:, 0]
    out["amplitude"][k] = np.abs(run.moments[:, 0]) * 2.0 / problem.period
    velocities = run.impact_velocities
    out["velocity"][k, : min(velocities.size, MAX_KEPT_IMPACTS)] = velocities[-MAX_KEPT_IMPACTS:]
    out["impacts"][k] = velocities.size / strobes
    length = problem.length_scale()
    scale = np.repeat([length, problem.omega * length], problem.size)
    mismatch = [float(np.max(np.abs(s[p:] - s[:-p]) / scale)) if s.shape[0] > 2 * p else math.inf for p in range(1, MAX_PERIOD + 1)]
    period = next((p for p, m in enumerate(mismatch, start=1) if m < REPEAT_TOLERANCE), 0)
    if velocities.size == 0:
        out["regime"][k], out["period"][k] = 0, 1
        return run.final_state
    if not period:
        jacobians = run.strobe_jacobians
        if np.all(np.isfinite(jacobians)):
            evidence = classify_motion(jacobians, s[1:])
        else:  # a degenerate event (e.g. a chatter sequence ending as a release begins) left a Jacobian undefined
            evidence = classify_strobes(s[1:])  # the strobes alone decide the clear cases; no exponent
        out["lyapunov"][k] = evidence.lyapunov_exponent
        if evidence.lyapunov_exponent < -0.005:  # contracting: a periodic orbit approached slowly
            period = int(np.argmin(mismatch)) + 1
        else:
            out["regime"][k] = MOTION_CLASSES.index(evidence.kind)
            return run.final_state
    out["period"][k] = period
    tail = (strobes // period) * period
    impacts = np.count_nonzero(run.impact_times >= run.strobe_times[strobes - tail])
    out["regime"][k] = 1 if period == 1 and impacts == tail else 2
    return run.final_state


#: Fields of :func:`branch_arrays`.
BRANCH_FIELDS = (
    "branch", "origin", "frequency", "amplitudes", "impulse", "floquet_modulus", "stable", "impacts", "period",
    "multipliers_real", "multipliers_imag", "velocities",
    "sp_branch", "sp_kind", "sp_frequency", "sp_amplitudes", "sp_impulse", "sp_floquet_modulus", "sp_impacts", "sp_period",
    "sp_multipliers_real", "sp_multipliers_imag", "sp_note", "sp_found_on", "notes", "absent", *FAILURE_FIELDS,
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
            seed_branches(found, self.problem, self.low, self.high, self.seeds, settings)
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
    d = np.max(np.abs(linear.stops) + linear.stop_static, axis=-1)
    inside = (d >= low_c) & (d <= high_c)
    runs = np.split(np.flatnonzero(inside), np.flatnonzero(np.diff(np.flatnonzero(inside)) > 1) + 1)
    return [(f[r], d[r]) for r in runs if r.size > 1]
