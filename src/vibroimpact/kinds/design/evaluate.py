"""One design's worst case, as runner cases (:mod:`vibroimpact.runs.runner`): the screen of a candidate under every
mistuning sample (:class:`DesignCase`: the closed forms, or bumper orbits grown from them, :func:`screen_kind`), and
the certification of one problem by continuation (:class:`CertifyCase`).

A design is a vector of the scene's variables; a mistuning sample a vector of offsets of the robust scalars
(relative for a structural scalar, absolute for the clearance and restitution; sample 0 is the nominal design). Both
set parameters of one :class:`~vibroimpact.orbits.maps.ImpactMap` of the scene's problem, whose
:meth:`~vibroimpact.orbits.maps.ImpactMap.problem_at` builds the problem: the one path from a parameter vector to a
problem that continuation uses too.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.band_worst import MOTIONS, BandWorst, closed_form_at, closed_form_worst
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.analysis.measures import Measure, as_measure
from vibroimpact.simulation.attractors import MOTION_CLASSES
from vibroimpact.simulation.band_attractors import AttractorSweep, band_attractors
from vibroimpact.simulation.point_motions import SAME_SIZE, PointMotion, point_motions
from vibroimpact.model.contact import MIN_BUMPER_RESTITUTION, KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.bumper_screen import bumper_at, bumper_screen_refusal, bumper_worst
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.orbit_measures import branch_measures
from vibroimpact.simulation.certified_worst import SOURCES, certified_worst, sweep_points_for
from vibroimpact.runs.runner import CaseResult, ProgressReport
from vibroimpact.runs.fingerprints import case_key

__all__ = ["DesignSpace", "DesignCase", "sample_chunks", "CHUNKS", "DESIGN_FIELDS", "CertifyCase", "CERTIFY_FIELDS", "SCREENS", "screen_kind", "screen_worst", "ATTRACTOR_POINTS", "SWEEP_ACCURACIES", "MAX_BRANCH_POINTS", "certified_operating", "OPERATING_STARTS", "CERTIFY_OPERATING_STARTS", "SCREEN_MOTIONS", "BRUTE", "BRUTE_SCREEN"]

#: The screen's motions: the closed forms' (:data:`~vibroimpact.analysis.band_worst.MOTIONS`), and brute force's on a
#: layout without a closed form.
BRUTE = "found by brute force"
SCREEN_MOTIONS = (*MOTIONS, BRUTE)
#: The screen's brute force where no closed form applies: frequencies, extra starts, transient and measured periods.
BRUTE_SCREEN = (41, 1, 200, 64)
#: How the screen sees a problem (:func:`screen_kind`): the rigid stops' closed forms, bumper orbits grown from their
#: rigid twin's, or brute force (no closed form: a free mass, stops that are not one or a symmetric pair).
SCREENS = ("closed_form", "bumper_orbits", "brute_force")


def screen_kind(problem: ImpactProblem) -> str:
    """Which of :data:`SCREENS` screens ``problem``."""
    if closed_form_refusal(problem) is None:
        return SCREENS[0]
    return SCREENS[1] if bumper_screen_refusal(problem) is None else SCREENS[2]


def screen_worst(problem: ImpactProblem, band: tuple[float, float], measure: Measure | int, scan: int, kind: str | None = None) -> BandWorst:
    """The screen's worst case of ``problem`` over ``band`` [Hz]: the closed forms' (``scan`` frequencies) or the
    bumper orbits' (:data:`~vibroimpact.orbits.bumper_screen.BUMPER_SCAN` frequencies, each a shot orbit); ``kind``:
    its :func:`screen_kind` where the caller has it."""
    if (kind if kind is not None else screen_kind(problem)) == SCREENS[0]:
        return closed_form_worst(problem, band, measure, scan)
    return bumper_worst(problem, band, measure)


@dataclass(frozen=True, eq=False)
class DesignSpace:
    """The scene's problem and how designs and mistuning samples move it.

    Attributes
    ----------
    problem : ImpactProblem
        The scene's own design (rigid stops: one, or a symmetric pair).
    variables : tuple of str
        The design variables (``clearance``, ``restitution`` or layout scalars).
    mistuned : tuple of str
        The robust scalars, in the order of ``offsets``' columns.
    relative : tuple of bool
        Whether each robust scalar's offset is relative.
    offsets : tuple of tuple of float
        One row per sample, sample 0 the nominal design (all zeros).
    band : (float, float)
        [Hz].
    objective : Measure
        What the objective judges (a row of :mod:`vibroimpact.analysis.measures`; a coordinate index is read as its
        |X|).
    operating : float
        Frequency of the operating constraint [Hz]; NaN: none.
    scan : int
        Frequencies of the closed-form screen's scan.
    constraint : Measure
        What the operating constraint judges there (a coordinate index is read as its |X|; default x1's).
    """

    problem: ImpactProblem
    variables: tuple[str, ...]
    mistuned: tuple[str, ...]
    relative: tuple[bool, ...]
    offsets: tuple[tuple[float, ...], ...]
    band: tuple[float, float]
    objective: Measure | int = 0
    operating: float = math.nan
    scan: int = 241
    constraint: Measure | int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "objective", as_measure(self.objective, self.problem))
        object.__setattr__(self, "constraint", as_measure(self.constraint, self.problem))
        if len(self.relative) != len(self.mistuned) or any(len(row) != len(self.mistuned) for row in self.offsets) or not self.offsets:
            raise ValueError("offsets: one row per sample (the nominal first), one column per mistuned scalar")

    @cached_property
    def map(self) -> ImpactMap:
        """The impact map whose parameters are the design's and the mistuning's scalars."""
        layout = tuple(dict.fromkeys(n for n in (*self.variables, *self.mistuned) if n not in ImpactMap.parameter_names))
        return ImpactMap(self.problem, layout=layout)

    @cached_property
    def bumpers(self) -> bool:
        """The stops are Kelvin-Voigt bumpers (their loss factor the inverse of R)."""
        return any(isinstance(stop.law, KelvinVoigtBumper) for stop in self.problem.stops)

    @property
    def samples(self) -> int:
        """Rows of ``offsets`` (the nominal included)."""
        return len(self.offsets)

    def parameters(self, design: NDArray[np.float64] | tuple[float, ...], sample: int, offset: tuple[float, ...] | None = None) -> NDArray[np.float64]:
        """The map's parameter vector of ``design`` under mistuning sample ``sample``, or under the robust scalars'
        offsets ``offset`` where given (restitution kept in [0, 1], clearance positive)."""
        names = self.map.parameter_names
        p = np.array(self.map.parameters, dtype=float)
        for name, value in zip(self.variables, design):
            p[names.index(name)] = float(value)
        for name, relative, moved in zip(self.mistuned, self.relative, self.offsets[sample] if offset is None else offset):
            i = names.index(name)
            p[i] = p[i] * (1.0 + moved) if relative else p[i] + moved
        r, d = names.index("restitution"), names.index("clearance")
        p[r] = min(max(p[r], MIN_BUMPER_RESTITUTION if self.bumpers else 0.0), 1.0)
        p[d] = max(p[d], 1e-9 * self.map.problem.length_scale())
        return p

    def problem_at(self, design: NDArray[np.float64] | tuple[float, ...], sample: int = 0, offset: tuple[float, ...] | None = None) -> ImpactProblem:
        """The problem of ``design`` under sample ``sample`` (0: nominal), or under the offsets ``offset``."""
        return self.map.problem_at(self.parameters(design, sample, offset))

    def key_content(self) -> dict:
        """What determines every result in this space (for case keys)."""
        return {"problem": repr(self.problem), "variables": self.variables, "mistuned": self.mistuned, "relative": self.relative,
                "offsets": self.offsets, "band": self.band, "objective": self.objective.name, "operating": self.operating, "scan": self.scan,
                "constraint": self.constraint.name}  # fmt: skip


#: Cases one candidate's samples are split into (at most).
CHUNKS = 4


def sample_chunks(samples: int) -> list[tuple[int, ...]]:
    """The samples 0 ... ``samples`` - 1 in min(``samples``, :data:`CHUNKS`) consecutive runs whose sizes differ by
    at most one (two workers share 9 samples as 5 and 4, not 6 and 3)."""
    return [tuple(int(i) for i in part) for part in np.array_split(np.arange(samples), min(samples, CHUNKS))]


#: Fields of :class:`DesignCase`: per sample, the worst stable |X| [m] over the band, where [Hz], which motion (index of
#: :data:`SCREEN_MOTIONS`), the uncovered share and the guess there [m], the worst |X| at the
#: operating frequency [m] (NaN: no constraint) over every motion found there, which motion, its period, impacts per
#: period and how many of the :data:`OPERATING_STARTS` runs reached it; the largest impulse of one impact of a stable
#: closed-form orbit on the scan [N s] (NaN: screened by brute force); ``error``: why a sample has no value.
DESIGN_FIELDS = ("worst", "frequency", "motion", "uncovered", "estimate", "operating", "operating_motion", "operating_period", "operating_impacts", "operating_starts", "impulse", "error")
#: The screen's runs at the operating frequency (rest and the linear state among them), their periods dropped and
#: measured, and their seed: every motion they settle on is judged (:func:`_operating`).
OPERATING_STARTS = 8
OPERATING_RUN = (200, 64)
OPERATING_SEED = 1


@dataclass(frozen=True, eq=False)
class DesignCase:
    """The closed-form worst case of one design under the mistuning samples ``samples`` (module docstring): a
    candidate's samples are split over a few cases, so that workers share even one candidate."""

    space: DesignSpace
    design: tuple[float, ...]
    samples: tuple[int, ...]
    engine: str = "closed_form"
    fields: tuple[str, ...] = DESIGN_FIELDS
    progress_unit: str = "designs"

    @property
    def progress_total(self) -> float:
        """Its samples' share of one design."""
        return len(self.samples) / self.space.samples

    def key(self) -> str:
        """Hash of the space and the design."""
        return case_key({"kind": "design", "space": self.space.key_content(), "design": list(self.design), "samples": list(self.samples),
                         "operating": [OPERATING_STARTS, *OPERATING_RUN, OPERATING_SEED]})  # fmt: skip

    def run(self, report: ProgressReport | None = None) -> CaseResult:
        """Arrays over ``samples`` (:data:`DESIGN_FIELDS`)."""
        n = len(self.samples)
        out = {k: np.full(n, np.nan) for k in ("worst", "frequency", "uncovered", "estimate", "operating", "operating_period", "operating_impacts", "operating_starts", "impulse")}
        motion, operating_motion = np.zeros(n, dtype=np.int8), np.zeros(n, dtype=np.int8)
        errors = [""] * n
        for row, s in enumerate(self.samples):
            try:
                problem = self.space.problem_at(self.design, s)
                kind = screen_kind(problem)
                if kind != SCREENS[2]:
                    found = screen_worst(problem, self.space.band, self.space.objective, self.space.scan, kind)
                    values = (found.amplitude, found.frequency, found.uncovered, found.estimate, SCREEN_MOTIONS.index(found.motion))
                    out["impulse"][row] = found.impulse
                else:  # no closed form (a free mass, stops that are not one or a symmetric pair): brute force screens
                    top = band_attractors(problem, self.space.band, *BRUTE_SCREEN, measure=self.space.objective).maximum
                    values = (top.amplitude, top.frequency, 0.0, 0.0, SCREEN_MOTIONS.index(BRUTE))
                if math.isfinite(self.space.operating):
                    out["operating"][row], operating_motion[row], *rest = _operating(problem, self.space.operating, self.space.constraint, kind)
                    out["operating_period"][row], out["operating_impacts"][row], out["operating_starts"][row] = rest
            except ValueError as error:  # a structure the model refuses (a mass driven non-positive ...)
                errors[row] = f"{type(error).__name__}: {str(error)[:160]}"
                continue
            out["worst"][row], out["frequency"][row], out["uncovered"][row], out["estimate"][row], motion[row] = values
        if report is not None:
            report(self.progress_total)
        return out | {"motion": motion, "operating_motion": operating_motion, "error": np.array(errors, dtype=str)}


def _operating(problem: ImpactProblem, frequency: float, measure: Measure, kind: str) -> tuple[float, int, int, int, int]:
    """The worst coexisting ``measure`` at the operating ``frequency`` [Hz] over every motion found there: the stable
    closed-form ones (``kind`` of :data:`SCREENS`) and every motion :data:`OPERATING_STARTS` seeded runs settle on
    (:func:`~vibroimpact.simulation.point_motions.point_motions`: rest and the linear state among them); with the
    motion that sets it (index of :data:`SCREEN_MOTIONS`, :data:`BRUTE` for a sampled one), its period, impacts per
    period and the runs that reached it (0: a closed form's, not reached by the runs)."""
    closed = (math.nan, MOTIONS[0], 0)  # no stable closed-form motion there: nothing known from the closed forms
    at = _screen_at(problem, frequency, measure, kind)
    if at is not None:
        closed = (at.amplitude, at.motion, at.impacts)
    sampled = point_motions(problem, frequency, measure, OPERATING_STARTS, *OPERATING_RUN, seed=OPERATING_SEED)
    top = sampled.largest
    if top is None and not math.isfinite(closed[0]):
        return math.nan, SCREEN_MOTIONS.index(MOTIONS[0]), 0, 0, 0  # no motion found at all: no value (the candidate is scored infinite), never 0
    if top is not None and not top.value <= closed[0] * (1.0 + SAME_SIZE):
        return max(top.value, closed[0]) if math.isfinite(closed[0]) else top.value, SCREEN_MOTIONS.index(BRUTE), top.period, top.impacts, top.starts
    reached = sum(m.starts for m in sampled.motions if abs(m.value - closed[0]) <= SAME_SIZE * closed[0])
    return max(closed[0], top.value if top is not None else -math.inf), SCREEN_MOTIONS.index(closed[1]), 1, closed[2], reached


#: Fields of :class:`CertifyCase`: the certified worst |X| [m], where [Hz], its motion (text) and source (index of
#: :data:`~vibroimpact.simulation.certified_worst.SOURCES`); the continuation's and the brute force's own answers and
#: wall times [s], and the closed-form screen's wall time on the same problem [s] (NaN: no closed form); the frequencies a stepped sweep needs to reach the same maximum to 1e-4 and 1e-8 (relative) and what
#: it would cost [s] at the brute force's measured cost per point; the
#: continued branches' points (frequency [Hz], |X| [m], stable 0/1, impacts per period, branch index, 1 where its branch
#: stopped at the continuation's step limit), NaN-padded; the
#: brute force's largest |X| at each of its frequencies; ``impacting``: 1 where any stable motion found in the band
#: (a branch or an attractor) strikes a stop; the operating point's worst value over every motion found there (closed
#: forms, :data:`CERTIFY_OPERATING_STARTS` runs with their periodic orbits shot, the brute force's attractors at that
#: frequency), the motion (text), who reached it (text), its period, impacts per period, the runs, and the wall time [s].
CERTIFY_FIELDS = ("worst", "frequency", "motion", "source", "continuation_worst", "continuation_time", "brute_worst", "brute_frequency", "brute_motion", "brute_time", "screen_time",
                  "sweep_points", "sweep_time", "branch_frequency", "branch_amplitude", "branch_stable", "branch_impacts", "branch_index", "branch_cut", "attractor_frequency", "attractor_amplitude",
                  "impacting", "operating_worst", "operating_motion", "operating_reached", "operating_period", "operating_impacts", "operating_runs", "operating_time", "error")  # fmt: skip
#: The certification's runs at the operating frequency (rest and the linear state among them), their periods dropped
#: and measured, and their seed (another than the screen's): every periodic motion they settle on is shot.
CERTIFY_OPERATING_STARTS = 64
CERTIFY_OPERATING_RUN = (400, 64)
CERTIFY_OPERATING_SEED = 2
#: Most branch points kept per certified problem.
MAX_BRANCH_POINTS = 4000
#: Frequencies of the certification's brute force.
ATTRACTOR_POINTS = 121
#: The accuracies (relative) at which a stepped sweep's cost is compared with the certification's.
SWEEP_ACCURACIES = (1e-4, 1e-8)


@dataclass(frozen=True, eq=False)
class CertifyCase:
    """The worst case of one problem certified by continuation and brute force
    (:func:`~vibroimpact.simulation.certified_worst.certified_worst`), and its operating point over every motion found
    there (:func:`certified_operating`); ``offset``: the robust scalars' offsets where the problem is not one of the
    space's samples (a point of the tolerance box, ``sample`` -1)."""

    space: DesignSpace
    design: tuple[float, ...]
    sample: int = 0
    offset: tuple[float, ...] | None = None
    engine: str = "certification"
    fields: tuple[str, ...] = CERTIFY_FIELDS
    progress_unit: str = "designs"

    @property
    def progress_total(self) -> float:
        """One problem."""
        return 1.0

    def key(self) -> str:
        """Hash of the space, the design, the sample (or its offsets) and the certification's coverage."""
        return case_key({"kind": "design_certify", "space": self.space.key_content(), "design": list(self.design), "sample": self.sample, "attractors": ATTRACTOR_POINTS,
                         "offset": list(self.offset) if self.offset is not None else None, "operating": [CERTIFY_OPERATING_STARTS, *CERTIFY_OPERATING_RUN, CERTIFY_OPERATING_SEED]})  # fmt: skip

    def run(self, report: ProgressReport | None = None) -> CaseResult:
        """The certified worst case, each method's, and the branches traced (:data:`CERTIFY_FIELDS`)."""
        points = {k: np.full(MAX_BRANCH_POINTS, np.nan) for k in ("branch_frequency", "branch_amplitude", "branch_stable", "branch_impacts", "branch_index", "branch_cut")}
        attractors = {k: np.full(ATTRACTOR_POINTS, np.nan) for k in ("attractor_frequency", "attractor_amplitude")}
        scalars: dict[str, object] = {k: math.nan for k in ("worst", "frequency", "continuation_worst", "continuation_time", "brute_worst", "brute_frequency", "brute_time", "screen_time")}
        scalars |= {"motion": "", "brute_motion": "", "source": -1, "impacting": math.nan}
        scalars |= {k: math.nan for k in ("operating_worst", "operating_period", "operating_impacts", "operating_runs", "operating_time")} | {"operating_motion": "", "operating_reached": ""}
        problem = self.space.problem_at(self.design, self.sample, self.offset)
        try:
            if screen_kind(problem) != SCREENS[2]:  # what the search's objective costs on this problem, timed alone
                start = time.perf_counter()
                screen_worst(problem, self.space.band, self.space.objective, self.space.scan)
                scalars["screen_time"] = time.perf_counter() - start
            found = certified_worst(problem, self.space.band, frequencies=ATTRACTOR_POINTS, measure=self.space.objective)
        except (ValueError, RuntimeError) as error:
            return {**{k: np.array(v) for k, v in scalars.items()}, "sweep_points": np.full(len(SWEEP_ACCURACIES), np.nan), "sweep_time": np.full(len(SWEEP_ACCURACIES), np.nan), **points, **attractors,
                    "error": np.array(f"{type(error).__name__}: {str(error)[:200]}")}  # fmt: skip
        top = found.attractors.maximum
        scalars |= {"worst": found.amplitude, "frequency": found.frequency, "motion": found.motion, "source": SOURCES.index(found.source),
                    "continuation_worst": found.continuation.amplitude, "continuation_time": found.continuation_time,
                    "brute_worst": top.amplitude, "brute_frequency": top.frequency, "brute_motion": top.motion, "brute_time": found.brute_force_time}  # fmt: skip
        system = ImpactMap(problem)  # the frequency is each branch's own parameter
        branches = [(branch, top) for branch, top in found.continuation.branches] + [(branch, None) for branch in found.extra]
        k, setting = 0, None
        for index, (branch, top) in enumerate(branches):
            count = min(len(branch.values), MAX_BRANCH_POINTS - k)
            if count <= 0:
                break
            period = branch.orbits[0].period
            measured = self.space.objective.of_shot(branch_measures(system if period == 1 else ImpactMap(problem, periods=period), branch))
            stable = np.asarray(branch.stable, dtype=float)
            points["branch_frequency"][k : k + count] = branch.values[:count]
            points["branch_amplitude"][k : k + count] = measured[:count]
            points["branch_stable"][k : k + count] = stable[:count]
            points["branch_impacts"][k : k + count] = np.asarray(branch.impacts, dtype=float)[:count]
            points["branch_index"][k : k + count] = index
            points["branch_cut"][k : k + count] = float("max_steps" in branch.end)  # followed only as far as the step limit
            k += count
            sets_it = found.source == SOURCES[2] if top is None else (found.source == SOURCES[0] and top.amplitude == found.amplitude)  # exact: the same number passed on
            if sets_it:  # the stable stretch of the branch whose maximum is the worst case
                setting = (np.asarray(branch.values)[stable == 1], measured[stable == 1])
        f = found.attractors.frequency
        attractors["attractor_frequency"][: f.size] = f
        attractors["attractor_amplitude"][: f.size] = found.attractors.largest()
        branch_strikes = np.any((points["branch_stable"] == 1.0) & (points["branch_impacts"] > 0.0))  # exact: 0/1 flags and counts
        scalars["impacting"] = float(branch_strikes or bool(np.any(np.isfinite(found.attractors.amplitude) & (found.attractors.impacts > 0.0))))
        if math.isfinite(self.space.operating):
            start = time.perf_counter()
            try:
                scalars |= certified_operating(problem, self.space, found.attractors)
            except (ValueError, RuntimeError) as error:  # no value: the candidate cannot be said to keep the constraint
                scalars["operating_motion"] = f"not judged: {type(error).__name__}: {str(error)[:160]}"
            scalars["operating_time"] = time.perf_counter() - start
        sweep = np.array([sweep_points_for(setting[1], setting[0], a, self.space.band) if setting is not None else math.nan for a in SWEEP_ACCURACIES])
        if report is not None:
            report(1.0)
        return {**{k: np.array(v) for k, v in scalars.items()}, "sweep_points": sweep, "sweep_time": sweep * found.seconds_per_point, **points, **attractors, "error": np.array("")}


def _screen_at(problem: ImpactProblem, frequency: float, measure: Measure, kind: str) -> BandWorst | None:
    """The screen's largest stable motion at one ``frequency`` [Hz] (``kind`` of :data:`SCREENS`: the closed forms or
    the bumper orbits shot from them); None where none of its motions is stable there or it has none (brute force)."""
    if kind == SCREENS[2]:
        return None
    at = closed_form_at(problem, frequency, measure) if kind == SCREENS[0] else bumper_at(problem, frequency, measure)
    return at if at.motion != MOTIONS[0] else None


def certified_operating(problem: ImpactProblem, space: DesignSpace, attractors: AttractorSweep | None = None) -> dict[str, object]:
    """``problem``'s worst value of the constraint's measure at the operating frequency over every motion found there:
    the stable closed-form ones, every motion :data:`CERTIFY_OPERATING_STARTS` runs settle on (rest and the linear
    state among them, every periodic one shot: its orbit exact), and the brute force's attractors where its grid
    holds that frequency and it judged the same measure; the fields ``operating_*`` of :data:`CERTIFY_FIELDS`."""
    frequency, measure = space.operating, space.constraint
    kind = screen_kind(problem)
    candidates: list[tuple[float, str, str, int, int]] = []  # (value, motion, who reached it, period, impacts per period)
    at = _screen_at(problem, frequency, measure, kind)
    if at is not None:
        name = PointMotion(at.amplitude, "linear" if at.motion == MOTIONS[1] else "one_impact", 1, at.impacts, 0, False, False).text()
        candidates.append((at.amplitude, name, "a closed form" if kind == SCREENS[0] else "a bumper orbit shot from the closed form", 1, at.impacts))
    sampled = point_motions(problem, frequency, measure, CERTIFY_OPERATING_STARTS, *CERTIFY_OPERATING_RUN, seed=CERTIFY_OPERATING_SEED, shoot_orbits=True)
    candidates += [(m.value, m.text() + ("" if m.exact or not m.period or m.regime == "linear" else " (its last periods: shooting failed)"), sampled.share_text(m), m.period, m.impacts) for m in sampled.motions]
    if attractors is not None and space.objective.name == measure.name:
        near = np.flatnonzero(np.abs(attractors.frequency - frequency) <= 1e-9 * frequency)
        for k in near:
            for j, value in enumerate(attractors.amplitude[k]):
                if math.isfinite(value):
                    period, impacts = int(attractors.period[k, j]), float(attractors.impacts[k, j])
                    candidates.append((float(value), f"an attractor of the band's brute force ({MOTION_CLASSES[int(attractors.regime[k, j])].replace('_', ' ')}, period {period})",
                                       f"its {attractors.runs[j]} run", period, int(round(impacts * max(period, 1)))))  # fmt: skip
    if not candidates:
        return {"operating_runs": float(sampled.runs)}
    value, motion, reached, period, impacts = max(candidates, key=lambda c: c[0])
    same = [m for m in sampled.motions if abs(m.value - value) <= SAME_SIZE * value]
    if same:  # the runs reached the motion that sets it (a closed form's too): say who
        reached = sampled.share_text(same[0])
    return {"operating_worst": value, "operating_motion": motion, "operating_reached": reached, "operating_period": float(period), "operating_impacts": float(impacts), "operating_runs": float(sampled.runs)}
