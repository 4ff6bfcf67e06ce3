"""Branches of periodic orbits of each absorber concept, continued in frequency: where the orbits the simulations and
the closed forms found are stable, and where they lose stability (folds, period doublings, torus and grazing points).

A concept's branches start from every simulated periodic steady state with impacts that no earlier branch passes
through (same period, impact count and |X1| within :data:`SAME_ORBIT`), and from the middle of each stretch where the
closed-form impact orbit is admissible (its unstable parts too, which no simulation reaches). Each start is moved to a stroboscopic section clear of its impacts (:func:`vibroimpact.orbits.maps.resection`),
shot as a fixed point of the exact map (:func:`vibroimpact.orbits.shooting.shoot`) and continued both ways over the
band (:func:`vibroimpact.orbits.continuation.continue_branch`). A failure is a note, never fatal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, asdict

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.engines.base import Trajectory
from vibroimpact.kinds.concepts.scene import Concept
from vibroimpact.model.contact import RIGID
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.branch import Branch
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap, resection
from vibroimpact.orbits.shooting import shoot
from vibroimpact.runs.runner import CaseResult, ProgressReport
from vibroimpact.runs.fingerprints import case_key
from vibroimpact.simulation.harmonics import HarmonicMeasures, measure
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.simulation.steady import march as march_to_repeat

__all__ = ["SteadyOutcome", "march", "check_stops", "GAP_TOLERANCE", "BranchCase", "BRANCH_FIELDS", "SAME_ORBIT", "MAX_SEEDS", "branch_seeds"]


# --------------------------------------------------------------------------------------------------------------------
# Steady states of an absorber concept at one frequency, for any structure and any stops: march until the
# stroboscopic state repeats, then measure whole periods.
# --------------------------------------------------------------------------------------------------------------------

#: Largest |gap| at an impact, and largest penetration anywhere recorded, as a fraction of the motion's length scale [-].
GAP_TOLERANCE = 1e-6


def check_stops(trajectory: Trajectory) -> None:
    """Rigid stops: ``RuntimeError`` unless every impact of ``trajectory`` happens on its stop's closed gap and no recorded state
    (strobes, segment starts) is inside a stop, to :data:`GAP_TOLERANCE` of the motion's length: an engine that does
    not know a layout (e.g. takes a relative stop for the paper's) is refused instead of trusted."""
    problem = trajectory.problem
    if problem.contact_law != RIGID:
        return  # a bumper is compressed while in contact: penetration is its law, nothing to check
    normals, clearances = problem.normals(), problem.clearances()
    size = problem.size
    tolerance = GAP_TOLERANCE * problem.length_scale()
    states = np.concatenate([trajectory.strobe_states[:, :size], trajectory.segment_states[:, :size]])
    if states.size and np.min(clearances[None, :] - states @ normals.T) < -tolerance:
        raise RuntimeError(f"a recorded state is inside a stop of {[stop.describe(problem.structure.coordinates) for stop in problem.stops]}: the engine does not honour this layout")
    starts = trajectory.segments[:, 0] if trajectory.segments.size else np.zeros(0)
    for time, stop in zip(trajectory.impact_times, trajectory.impact_stops):
        k = int(np.argmin(np.abs(starts - time))) if starts.size else -1
        if k < 0 or abs(starts[k] - time) > 1e-9 * problem.period:
            continue  # no segment starts at this impact (an engine that records none): nothing to check
        gap = clearances[stop] - normals[stop] @ trajectory.segment_states[k, :size]
        if abs(gap) > tolerance:
            raise RuntimeError(f"an impact on stop {stop} ({problem.stops[stop].describe(problem.structure.coordinates)}) at t = {time:.6g} s leaves a gap of {gap:.3g} m: the engine does not honour this layout")


@dataclass(frozen=True)
class SteadyOutcome:
    """A steady state found by :func:`march`.

    Attributes
    ----------
    measures : HarmonicMeasures
        Over the measured periods.
    converged : bool
        The stroboscopic state repeated to the tolerance.
    multiplicity : int
        Its period in excitation periods (0 if not converged).
    periods : int
        Periods integrated in all.
    time : float
        Time of the first measured strobe [s] (on the steady motion when converged).
    state : ndarray, shape (2 N,)
        State at ``time``.
    """

    measures: HarmonicMeasures
    converged: bool
    multiplicity: int
    periods: int
    time: float
    state: NDArray[np.float64]


def march(engine: object, problem: ImpactProblem, t: float, y: NDArray[np.float64], settings: SteadySettings, max_periods: int | None = None) -> SteadyOutcome:
    """Integrate from (t [s], y) until the strobes repeat (the steady states' march,
    :func:`vibroimpact.simulation.steady.march`, at most ``max_periods``, default the settings'), then measure
    ``measure_periods`` (a multiple of the period found) or ``irregular_measure_periods`` with moments."""
    t, y, multiplicity, used = march_to_repeat(engine, problem, t, y, settings, max_periods)  # type: ignore[arg-type]
    measured = multiplicity * math.ceil(settings.measure_periods / multiplicity) if multiplicity else settings.irregular_measure_periods
    final = engine.integrate(problem, y, t, measured, moments=True)  # type: ignore[attr-defined]
    check_stops(final)
    return SteadyOutcome(measure(final), multiplicity > 0, multiplicity, used + measured, t, np.array(y, dtype=float))

#: Largest relative |X1| difference of an orbit from a branch it is taken to lie on [-].
SAME_ORBIT = 0.02
#: Most branches started per concept.
MAX_SEEDS = 8
#: Fields of a branch case's result: one entry per orbit point (``note``: one string).
BRANCH_FIELDS = ("frequency", "x1_amplitude", "base_force_amplitude", "floquet_modulus", "impacts_per_period", "period", "branch", "note")


@dataclass(frozen=True)
class BranchCase:
    """The branches of one concept over [low, high] Hz.

    Attributes
    ----------
    concept : Concept
        System and rigid stops.
    amplitude : float
        q [N].
    low, high : float
        The band [Hz].
    seeds : tuple of (float, int, float, tuple of float)
        Simulated periodic steady states with impacts: (frequency [Hz], period [excitation periods], force phase at
        t = 0 [rad], state at t = 0).
    max_steps : int
        Most points per branch and direction.
    """

    concept: Concept
    amplitude: float
    low: float
    high: float
    seeds: tuple[tuple[float, int, float, tuple[float, ...]], ...]
    max_steps: int

    engine = "continuation"
    fields = BRANCH_FIELDS
    progress_unit = "branches"

    @property
    def progress_total(self) -> float:
        """Seeds to try."""
        return float(max(len(self.seeds), 1))

    def key(self) -> str:
        """A stable hash of everything that determines the result."""
        return case_key({"kind": "concept_branches", "concept": asdict(self.concept), "amplitude": self.amplitude, "band": [self.low, self.high],
                         "seeds": [list(s[:3]) + list(s[3]) for s in self.seeds], "max_steps": self.max_steps})  # fmt: skip

    def run(self, report: ProgressReport | None = None) -> CaseResult:
        """Every branch of the concept, as flat per-point arrays."""
        points: list[tuple[float, float, float, float, float, float, float]] = []
        notes: list[str] = []
        settings = ContinuationSettings(lower=self.low, upper=self.high, max_steps=self.max_steps, max_step=0.1, stop_at_grazing=True)
        bounds = {"frequency": (0.5 * self.low, 2.0 * self.high)}
        count = 0
        for done, (frequency, period, phase, state) in enumerate(self._starts(notes)):
            if count >= MAX_SEEDS:
                notes.append(f"more than {MAX_SEEDS} starts: the rest were not continued")
                break
            try:
                problem = self.concept.problem(self.amplitude, frequency, phase)
                moved, y = resection(problem, np.array(state), period)
                mapping = ImpactMap(moved, periods=period, bounds=bounds)
                if self._known(points, mapping, y, period):
                    continue
                orbit = shoot(mapping, y, mapping.parameters)
                branch = continue_branch(mapping, orbit, "frequency", settings)
            except Exception as error:  # noqa: BLE001 - a failed branch is a note, the others go on
                notes.append(f"branch from {frequency:.2f} Hz failed: {type(error).__name__}: {str(error)[:160]}")
                continue
            points.extend(_measure(mapping, branch, count))
            notes.append(f"branch {count} from {frequency:.2f} Hz: {len(branch.orbits)} points, {branch.values.min():.2f}-{branch.values.max():.2f} Hz, ends: {branch.end}")
            count += 1
            if report is not None:
                report(float(done + 1))
        table = np.array(points, dtype=float).reshape(-1, 7)
        out: dict[str, NDArray] = {name: table[:, i].copy() for i, name in enumerate(BRANCH_FIELDS[:-1])}
        out["note"] = np.array(["; ".join(notes)])
        return out

    def _starts(self, notes: list[str]) -> list[tuple[float, int, float, tuple[float, ...]]]:
        """The simulated seeds, then the closed-form impact orbit's admissible stretches."""
        starts = list(self.seeds)
        try:
            starts += _closed_form_starts(self.concept, self.amplitude, self.low, self.high)
        except Exception as error:  # noqa: BLE001 - no closed-form starts: the simulated ones remain
            notes.append(f"closed-form starts failed: {type(error).__name__}: {error}")
        return starts

    def _known(self, points: list, mapping: ImpactMap, y: NDArray[np.float64], period: int) -> bool:
        """Does a branch already found pass through the orbit that a march from ``y`` settles on (same period and
        impacts, |X1| within :data:`SAME_ORBIT` at the nearest branch frequency)?"""
        if not points:
            return False
        frequency = float(mapping.parameters[0])
        run = mapping.engine.integrate(mapping.problem, y, 0.0, period, moments=True)
        x1 = abs(measure(run).displacements[0])
        impacts = run.impulses.size / period
        table = np.array(points)
        same = (table[:, 5] == period) & (np.abs(table[:, 4] - impacts) < 1e-9)
        for branch in np.unique(table[same, 6]):
            rows = table[same & (table[:, 6] == branch)]
            for a, b in zip(rows[:-1], rows[1:]):
                if min(a[0], b[0]) <= frequency <= max(a[0], b[0]) and abs(np.interp(frequency, sorted([a[0], b[0]]), [a[1], b[1]] if a[0] <= b[0] else [b[1], a[1]]) - x1) <= SAME_ORBIT * x1:
                    return True
        return False


def _measure(mapping: ImpactMap, branch: Branch, label: int) -> list[tuple[float, float, float, float, float, float, float]]:
    """(frequency, |X1|, |base force|, Floquet modulus, impacts per excitation period, period, branch) per orbit."""
    rows = []
    base = mapping.periods
    for orbit in branch.orbits:
        periods = orbit.period * base
        problem = mapping.problem_at(orbit.parameters)
        run = mapping.engine.integrate(problem, orbit.state, 0.0, periods, moments=True)
        m = measure(run)
        rows.append((orbit.parameter("frequency"), abs(m.displacements[0]), abs(m.force), orbit.floquet_modulus, m.impacts_per_period, float(periods), float(label)))
    return rows


def _closed_form_starts(concept: Concept, amplitude: float, low: float, high: float) -> list[tuple[float, int, float, tuple[float, ...]]]:
    """The middle of each stretch where the closed-form impact orbit (one stop, or a symmetric two-sided pair) is
    admissible, as a state at t = 0; none where no closed form applies."""
    frequency = np.arange(low, high + 0.005, 0.01)
    try:
        orbit = solve_impact_orbit(concept.problem(amplitude, float(frequency[0])), omega=2.0 * np.pi * frequency)
    except ValueError:
        return []
    admissible = np.flatnonzero(orbit.admissible())
    starts = []
    for run in np.split(admissible, np.flatnonzero(np.diff(admissible) > 1) + 1):
        if run.size:
            k = int(run[run.size // 2])
            state = orbit.take([k]).state_at(np.zeros((1, 1)))[0, 0]
            if np.all(np.isfinite(state)):
                starts.append((float(frequency[k]), 1, 0.0, tuple(float(v) for v in state)))
    return starts


def branch_seeds(frequency: NDArray[np.float64], converged: NDArray, multiplicity: NDArray, impacts: NDArray, states: NDArray, times: NDArray) -> tuple:
    """Simulated periodic steady states with impacts as seeds (frequency, period, phase, state): the state at time
    ``times`` of a problem whose force has phase 0 is the state at t = 0 of the problem whose force has phase w t."""
    seeds = []
    for i, f in enumerate(frequency):
        if converged[i] == 1.0 and impacts[i] > 0.0 and np.all(np.isfinite(states[i])) and math.isfinite(times[i]):
            phase = float((2.0 * math.pi * f * times[i]) % (2.0 * math.pi))
            seeds.append((float(f), int(multiplicity[i]), phase, tuple(float(v) for v in states[i])))
    return tuple(seeds)
