"""Every periodic orbit of one restitution over a frequency band: branches continued from the closed form, at period
doublings and at grazing points, the linear orbit, and their special points, as flat arrays for a dataset.

Everything works on the general problem (:class:`~vibroimpact.model.problem.ImpactProblem` with a tuple of rigid
:class:`~vibroimpact.model.contact.Stop`, any structure and harmonic load; the paper's layout is one of them).
:func:`find_branches` starts a branch at the middle of every frequency segment where a root of the impulse equation
(eq. 16 corrected, :func:`vibroimpact.analysis.impact_orbit.solve_impact_orbit`) gives an admissible closed-form
orbit (one impact per period on one stop, the symmetric two impacts per period on a two-sided stop), unless an
earlier branch already passes through that orbit (same impulse at that frequency); each branch gets its own
stroboscopic section, away from the impacts of its band (:func:`vibroimpact.orbits.maps.section_phase`). A layout
without a closed form (:func:`vibroimpact.analysis.layout.closed_form_refusal`) starts no such branch; its orbits
come from the brute force (:mod:`~vibroimpact.kinds.bifurcation.cases`). Period doublings of period-1 branches switch to the period-2
branch; grazing points where an orbit with another, non-zero impact count continues start a branch there. The linear
orbit comes from the closed form wherever it fits inside every stop (|n_k H F| + n_k K^-1 F0 <= Delta_k). Failures
of a continuation are recorded, never fatal.

A problem whose stops are Kelvin-Voigt bumpers has no closed form of its own: its one-contact branches start from its
rigid twin's (:func:`rigid_twin`: the same stops, rigid, with the bumpers' restitution R), whose orbit is shot on the
rigid map and continued to the bumper in its stiffness (:func:`~vibroimpact.kinds.bifurcation.bumper_start.bumper_start`;
where it has none, ``OrbitSet.absent`` says so), and are continued on the bumper's exact stroboscopic map
(:class:`~vibroimpact.orbits.maps.ImpactMap` picks its engine by capabilities); their grazing points are contact
onsets at tangency.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from vibroimpact.analysis.impact_orbit import ROOTS, ImpactOrbit, solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.kinds.bifurcation.born import MAX_GRAZING_BRANCHES, grow_at_grazing
from vibroimpact.kinds.bifurcation.bumper_start import bumper_start
from vibroimpact.model.contact import BUMPER, RigidStop
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.bifurcations import switch_period_doubling
from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS, Branch, Iterated, PeriodicOrbit, SpecialPoint
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap, closed_form_state, section_phase
from vibroimpact.orbits.onset_start import contact_orbit_at_onset
from vibroimpact.orbits.orbit_measures import orbit_measures
from vibroimpact.orbits.shooting import shoot

__all__ = ["rigid_twin", "MAX_GRAZING_BRANCHES", "ORIGINS", "MAX_ORBIT_IMPACTS", "SAME_POINT_FREQUENCY", "SAME_POINT_ORBIT", "same_special_point", "map_bounds", "problem_at", "stop_values", "OrbitSet", "find_branches", "closed_form_orbits", "linear_segments", "band_step"]

#: How a branch was found (CF flags of ``branch_origin``): the closed forms' kinds (one impact per period, the
#: symmetric two impacts of a two-sided stop) are :data:`vibroimpact.analysis.layout.KINDS`.
ORIGINS = ("linear", "one_impact", "period_doubling", "grazing", "brute_force", "two_impacts")
#: Impact velocities kept per orbit (the rest are dropped; ``impacts_per_period`` counts them all).
MAX_ORBIT_IMPACTS = 8
#: Frequency step of the closed-form scan for closed-form starts [Hz] (at most; a narrower band than
#: :data:`MIN_POINTS` steps of it is scanned at band / MIN_POINTS) ...
SCAN_STEP = 0.01
#: ... and of the linear orbit's curve, sampled in closed form [Hz] (at most, likewise).
LINEAR_STEP = 0.02
#: Fewest scan and linear-orbit points over the band (a 0.05 Hz band of a 0.1 Hz structure is sampled as densely as
#: the paper's 30 Hz band, relative to it, not in 3 points drawn as two straight lines) [-].
MIN_POINTS = 400


def band_step(low: float, high: float, step: float) -> float:
    """``step`` [Hz], or (high - low) / :data:`MIN_POINTS` where that is finer (a narrow band)."""
    return min(step, (high - low) / MIN_POINTS)
#: Largest relative impulse difference of an orbit from a branch it is taken to lie on [-].
SAME_ORBIT = 0.02
#: |max |mu| - 1| up to which an orbit is marginal (``stable`` = 2) [-].
MARGINAL = 1e-9
#: Two special points of one kind are one point when their frequencies differ by at most this, relative [-]. The
#: continuation locates a special point to 1e-10 relative (``locate_tolerance``): the same point found from two
#: branches (a branch and the branch born there, a seeded branch on a known orbit, an isola lapped several times)
#: agreed to 3.5e-12 in the shipped study; its closest distinct pairs of one kind (a period-k orbit's grazing point
#: and its period-2k child's, 36.01 Hz at R = 0.8 and 38.49 Hz at R = 0.2) differ by 4.7e-6 and 7.6e-6.
SAME_POINT_FREQUENCY = 1e-6
#: ... and when the fundamental amplitudes of every coordinate of their orbits differ by at most this, relative to the
#: larger (Euclidean norms) [-]. At a fold or a grazing point an orbit moves as the square root of the distance in
#: frequency, so a location good to 1e-10 leaves the orbit good to ~1e-5 (measured: up to 4.5e-6, the golden
#: scene's grazing point at 33.97 Hz found from a period-1 and a period-7 branch); the two distinct pairs above differ
#: in X1 by 2.9e-3 and 2.5e-4. Amplitudes, not states: each branch has its own stroboscopic section, so one orbit has
#: different states on two branches, while a period-1 orbit has the same amplitudes as its period-k description.
SAME_POINT_ORBIT = 1e-4


def same_special_point(a: dict, b: dict) -> bool:
    """Are two special-point records (``kind``, ``frequency`` [Hz], ``amplitudes`` [m] of every coordinate) one
    point: same kind, frequencies within :data:`SAME_POINT_FREQUENCY` and amplitudes within :data:`SAME_POINT_ORBIT`,
    relative?"""
    if a["kind"] != b["kind"]:
        return False
    if abs(a["frequency"] - b["frequency"]) > SAME_POINT_FREQUENCY * max(abs(a["frequency"]), abs(b["frequency"])):
        return False
    x, y = np.asarray(a["amplitudes"], dtype=float), np.asarray(b["amplitudes"], dtype=float)
    return bool(np.linalg.norm(x - y) <= SAME_POINT_ORBIT * max(np.linalg.norm(x), np.linalg.norm(y)))


def problem_at(problem: ImpactProblem, frequency: float, clearance: float | None = None, phase: float | None = None) -> ImpactProblem:
    """``problem`` at another excitation frequency [Hz] and, when given, with every stop at ``clearance`` [m] and the
    load's phase ``phase`` [rad]; the structure, the load's distribution and static part and each stop's restitution
    are kept."""
    excitation = dataclasses.replace(problem.harmonic, frequency=float(frequency))
    if phase is not None:
        excitation = dataclasses.replace(excitation, phase=float(phase))
    stops = problem.stops
    if clearance is not None:
        stops = tuple(dataclasses.replace(stop, law=RigidStop(float(clearance), stop.law.restitution)) for stop in stops)
    return ImpactProblem(problem.system, stops, excitation)


def rigid_twin(problem: ImpactProblem) -> ImpactProblem:
    """``problem`` with every stop rigid, at its own clearance and with its law's restitution (a bumper's R)."""
    stops = tuple(dataclasses.replace(stop, law=RigidStop(stop.clearance, stop.law.restitution)) for stop in problem.stops)
    return ImpactProblem(problem.system, stops, problem.excitation)


def stop_values(problem: ImpactProblem) -> tuple[float, float]:
    """(Delta [m], R [-]) shared by every stop of a bifurcation study's problem (the scene checks they are equal)."""
    first = problem.stops[0]
    return first.clearance, first.law.restitution


@dataclass
class OrbitSet:
    """Branches and special points of one restitution, as lists of per-point records (see :meth:`add_branch`), and
    the continued branches with their maps (``maps``: (ImpactMap, Branch) pairs). A special point is kept once
    (:func:`same_special_point`), with the labels of every branch it was found on (``found_on``). What failed is
    counted (``attempts`` and ``failures`` by kind of work: :meth:`attempted`, :meth:`failed`); ``absent`` says, a
    line each, which closed-form starts a bumper has no orbit for (:class:`~vibroimpact.kinds.bifurcation.bumper_start.BumperStart`);
    ``settled`` what each brute-force seed that settles slowly reached (:mod:`~vibroimpact.kinds.bifurcation.slow_seeds`)."""

    points: list[dict] = field(default_factory=list)
    specials: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    count: int = 0
    maps: list = field(default_factory=list)
    attempts: dict[str, int] = field(default_factory=dict)
    failures: list[tuple[str, str]] = field(default_factory=list)
    absent: list[str] = field(default_factory=list)
    settled: list = field(default_factory=list)
    _index: tuple | None = None

    def attempted(self, what: str) -> None:
        """Count one attempt of a kind of work that may fail (``closed_form``, ``period_doubling``, ``grazing``: a
        branch's start and continuation from there, ``seed``: a brute-force seed;
        :data:`vibroimpact.kinds.bifurcation.logs.FAILURES`)."""
        self.attempts[what] = self.attempts.get(what, 0) + 1

    def failed(self, what: str, detail: str) -> None:
        """Record a failed attempt of kind ``what`` with its raw message ``detail`` (one line), in the notes too."""
        self.failures.append((what, detail))
        self.notes.append(detail)

    def add_branch(self, system: ImpactMap, branch: Branch, origin: str) -> int:
        """Measure every orbit of ``branch`` and keep it with its special points; return its label."""
        label = self.count
        self.count += 1
        for orbit in branch.orbits:
            self.points.append(_record(system, orbit) | {"branch": label, "origin": ORIGINS.index(origin)})
        for point in branch.special_points:
            self.add_special(_record(system, point.orbit) | {"branch": label, "kind": SPECIAL_POINT_KINDS.index(point.kind), "frequency": point.value, "note": point.note,
                                                           "induced_by": math.nan if point.induced_by is None else point.induced_by})
        self.notes.append(f"branch {label} ({origin}): {len(branch.orbits)} points, {branch.values.min():.4f}-{branch.values.max():.4f} Hz, ends: {branch.end}")
        return label

    def add_special(self, record: dict) -> dict:
        """Keep a special point's record (``branch``, ``kind``, ``frequency`` [Hz], ``amplitudes`` [m], ...) unless
        a kept one is the same point (:func:`same_special_point`): then add its branch to that one's ``found_on``;
        return the kept record."""
        twin = next((known for known in self.specials if same_special_point(known, record)), None)
        if twin is None:
            twin = record | {"found_on": [record["branch"]]}
            self.specials.append(twin)
        elif record["branch"] not in twin["found_on"]:
            twin["found_on"].append(record["branch"])
        return twin

    def add_linear(self, problem: ImpactProblem, frequency: NDArray[np.float64]) -> None:
        """The impactless orbit of ``problem`` on one segment of frequencies [Hz] where it fits inside every stop."""
        label = self.count
        self.count += 1
        multipliers = _linear_multipliers(problem, frequency)
        amplitudes = np.abs(linear_amplitudes(problem, omega=2.0 * np.pi * np.asarray(frequency)).amplitudes)
        for k, f in enumerate(frequency):
            modulus = float(np.max(np.abs(multipliers[k])))
            self.points.append({
                "branch": label, "origin": 0, "frequency": float(f), "amplitudes": amplitudes[k], "impulse": 0.0, "floquet_modulus": modulus,
                "stable": int(modulus < 1.0), "impacts": 0, "period": 1, "multipliers": multipliers[k], "velocities": np.zeros(0),
            })  # fmt: skip
        self.notes.append(f"branch {label} (linear): {frequency.size} points, {frequency[0]:.4f}-{frequency[-1]:.4f} Hz")

    def impulse_at(self, frequency: float, period: int, impacts: int) -> list[float]:
        """Impulses per excitation period of the known branches with this period and impact count at ``frequency``."""
        if self._index is None or self._index[0] != len(self.points):
            self._index = (len(self.points), _segments(self.points))
        segments = self._index[1].get((period, impacts))
        if segments is None:
            return []
        fa, fb, ja, jb = segments
        inside = (np.minimum(fa, fb) <= frequency) & (frequency <= np.maximum(fa, fb))
        span = np.where(fb[inside] == fa[inside], 1.0, fb[inside] - fa[inside])
        t = np.where(fb[inside] == fa[inside], 0.0, (frequency - fa[inside]) / span)
        return list(ja[inside] + t * (jb[inside] - ja[inside]))

    def known(self, frequency: float, period: int, impacts: int, impulse: float, tolerance: float = 0.0) -> bool:
        """Does a known branch pass through an orbit of this period, impact count and impulse at ``frequency``
        (within :data:`SAME_ORBIT`, or ``tolerance`` when larger)?"""
        limit = max(SAME_ORBIT, tolerance) * max(abs(impulse), 1e-12)
        return any(abs(j - impulse) <= limit for j in self.impulse_at(frequency, period, impacts))


def _segments(points: list[dict]) -> dict[tuple[int, int], tuple[np.ndarray, ...]]:
    """(period, impacts per orbit period) -> (f_a, f_b, J_a, J_b) of each pair of consecutive points of one branch."""
    groups: dict[tuple[int, int], list[tuple[float, float, float, float]]] = {}
    for a, b in zip(points[:-1], points[1:]):
        if a["branch"] == b["branch"] and a["period"] == b["period"] and a["impacts"] == b["impacts"]:
            groups.setdefault((a["period"], a["impacts"]), []).append((a["frequency"], b["frequency"], a["impulse"], b["impulse"]))
    return {key: tuple(np.array(column) for column in zip(*rows)) for key, rows in groups.items()}


def map_bounds(low: float, high: float) -> dict[str, tuple[float, float]]:
    """The parameter box of the study's maps: frequencies within a factor 2 of the band [Hz] (a continuation's trials
    stay physical; outside, the map has no image)."""
    return {"frequency": (0.5 * low, 2.0 * high)}


def _record(system: ImpactMap, orbit: PeriodicOrbit) -> dict:
    measures = orbit_measures(system, orbit)
    periods = orbit.period * system.periods  # excitation periods per orbit period
    multipliers = np.zeros(system.dimension, dtype=complex)
    multipliers[: orbit.multipliers.size] = orbit.multipliers
    modulus = orbit.floquet_modulus
    return {
        "frequency": orbit.parameter("frequency"),
        "amplitudes": measures.amplitudes,
        "impulse": float(measures.impulses.sum()) / periods,
        "floquet_modulus": modulus,
        "stable": 2 if abs(modulus - 1.0) <= MARGINAL else int(modulus < 1.0),
        "impacts": int(measures.impulses.size),
        "period": periods,
        "multipliers": multipliers,
        "velocities": measures.impact_velocities[:MAX_ORBIT_IMPACTS],
    }


def _linear_multipliers(problem: ImpactProblem, frequency: NDArray[np.float64]) -> NDArray[np.complex128]:
    """exp(lambda T) of the free structure's eigenvalues at each frequency, by decreasing modulus, shape (n, 2N)."""
    eigenvalues = np.linalg.eigvals(problem.structure.state_matrix)
    mu = np.exp(eigenvalues[None, :] / np.asarray(frequency)[:, None])
    order = np.argsort(-np.abs(mu), axis=1, kind="stable")
    return np.take_along_axis(mu, order, axis=1)


def closed_form_orbits(problem: ImpactProblem, frequency: NDArray[np.float64]) -> list[ImpactOrbit]:
    """The closed-form impact orbit of ``problem`` at ``frequency`` [Hz] for each root of the impulse equation
    (:data:`~vibroimpact.analysis.impact_orbit.ROOTS`), NaN impulses where none exists; ``ValueError`` with the
    reason where the layout has no closed form."""
    plus = solve_impact_orbit(problem, omega=2.0 * np.pi * np.asarray(frequency, dtype=float))
    return [plus if root == "+" else plus.with_root(root) for root in ROOTS]


def linear_segments(problem: ImpactProblem, low: float, high: float, step: float = LINEAR_STEP) -> list[NDArray[np.float64]]:
    """Frequency segments [Hz] where the linear orbit fits inside every stop, with their exact grazing ends, sampled
    every :func:`band_step` of ``step`` [Hz] (drawn as curves on any band)."""
    step = band_step(low, high, step)
    frequency = np.arange(low, high + 0.5 * step, step)
    clearances = problem.clearances()

    def gap(f: float) -> float:
        linear = linear_amplitudes(problem, omega=2.0 * np.pi * f)
        if not np.all(linear.conditioned):  # an undamped resonance's band: NaN amplitudes, the orbit unbounded
            return -np.inf
        return float(np.min(clearances - linear.stop_static - np.abs(linear.stop_amplitudes)))

    fits = np.array([gap(f) >= 0.0 for f in frequency])
    segments = []
    for run in np.split(np.flatnonzero(fits), np.flatnonzero(np.diff(np.flatnonzero(fits)) > 1) + 1):
        if run.size == 0:
            continue
        inner = list(frequency[run])
        if run[0] > 0:
            inner.insert(0, _grazing_end(gap, frequency[run[0]], frequency[run[0] - 1]))
        if run[-1] < frequency.size - 1:
            inner.append(_grazing_end(gap, frequency[run[-1]], frequency[run[-1] + 1]))
        segments.append(np.array(inner))
    return segments


def _grazing_end(gap: Callable[[float], float], inside: float, outside: float) -> float:
    """Where the linear orbit's least ``gap`` [m] to a stop reaches 0 between ``inside`` (it fits: gap >= 0) and
    ``outside`` (it does not) [Hz]: brentq to 1e-12 Hz. An ``outside`` in the band of an undamped resonance (gap -inf:
    the response is unbounded and not evaluated there, within ~1.6e-5 relative of the natural frequency) is first
    stepped off towards ``inside`` by bisection until the gap is finite (before: brentq's ValueError 'The function
    value at x=... is NaN'); a graze inside that band ends the segment at its edge (the last frequency that fits)."""
    end = gap(outside)
    while not np.isfinite(end):
        if abs(outside - inside) <= 1e-12:
            return inside  # the graze lies within the band where the response is not evaluated: its edge
        middle = 0.5 * (inside + outside)
        value = gap(middle)
        if np.isfinite(value) and value >= 0.0:
            inside = middle
        else:
            outside, end = middle, value
    return float(brentq(gap, min(inside, outside), max(inside, outside), xtol=1e-12))  # low to high, as before


def find_branches(
    problem: ImpactProblem, low: float, high: float,
    one_impact: bool = True, period_doubling: bool = True, grazing: bool = True, linear: bool = True,
    max_steps: int = 2000, max_step: float = 0.1, progress=None,
) -> OrbitSet:  # fmt: skip
    """Every branch of ``problem``'s restitution over [low, high] Hz (module docstring); ``progress`` gets a line per
    branch.

    Parameters
    ----------
    problem : ImpactProblem
        Structure, rigid stops sharing one clearance and restitution, harmonic load; its frequency is not used.
    low, high : float
        The band [Hz].
    one_impact : bool
        Branches from the closed form (one impact per period, or two on a symmetric two-sided stop) at both roots.
    period_doubling, grazing, linear : bool
        Period-2 branches at period doublings, branches born at grazing points, the linear orbit.
    max_steps : int
        Most continuation steps per direction of a branch.
    max_step : float
        Largest arclength step [-].
    """
    found = OrbitSet()
    settings = ContinuationSettings(lower=low, upper=high, max_steps=max_steps, max_step=max_step, stop_at_grazing=True)
    bounds = map_bounds(low, high)
    restitution = stop_values(problem)[1]

    def say(message: str) -> None:
        if progress is not None:
            progress(f"R = {restitution:g}: {message}")

    def attempt(kind: str, what: str, run) -> None:
        found.attempted(kind)
        try:
            run()
        except Exception as error:  # noqa: BLE001 - a failed branch is recorded, the others go on
            found.failed(kind, f"{what} failed: {type(error).__name__}: {str(error)[:200]}")

    maps: list[tuple[ImpactMap, Branch]] = []
    segments = linear_segments(problem, low, high)
    if linear:
        for segment in segments:
            found.add_linear(problem, segment)
    bumper = problem.contact_law == BUMPER
    reference = rigid_twin(problem) if bumper else problem  # whose closed form starts the branches
    refusal = closed_form_refusal(reference) if one_impact else None
    if refusal is not None:
        found.notes.append(f"no closed-form orbit for this layout ({refusal}): its branches come from the brute force")
    elif one_impact:
        scan = band_step(low, high, SCAN_STEP)
        frequency = np.arange(low, high + 0.5 * scan, scan)
        orbits = closed_form_orbits(reference, frequency)
        exists = np.logical_or.reduce([orbit.exists for orbit in orbits])
        for root, orbit in zip(ROOTS, orbits):
            admissible = orbit.admissible()
            kind, impacts = orbit.layout.kind, orbit.impacts_per_period
            runs = np.split(np.flatnonzero(admissible), np.flatnonzero(np.diff(np.flatnonzero(admissible)) > 1) + 1)
            for run in (r for r in runs if r.size):
                k = int(run[run.size // 2])
                f0 = float(frequency[k])
                if found.known(f0, 1, impacts, impacts * float(orbit.impulse[k])):
                    continue
                band = _segment(exists, k)
                phase = section_phase(problem_at(reference, f0), frequency[band[0] : band[1] + 1])
                mapping = ImpactMap(problem_at(problem, f0, phase=phase), bounds=bounds)

                def start(mapping: ImpactMap = mapping, f0: float = f0, root: str = root, kind: str = kind, phase: float = phase) -> None:
                    if bumper:  # the rigid twin's orbit, shot, then continued to the bumper in its stiffness
                        twin = ImpactMap(problem_at(reference, f0, phase=phase), bounds=bounds)
                        rigid = shoot(twin, closed_form_state(twin.problem, solve_impact_orbit(twin.problem, root=root)), twin.parameters)
                        begun = bumper_start(mapping, rigid)
                        if begun.orbit is None:  # no such orbit of this bumper here: an answer, not a failure
                            found.absent.append(f"the rigid stop's {kind.replace('_', '-')} orbit at {f0:.2f} Hz (root {root}) has no counterpart with this bumper: {begun.why}")
                            found.notes.append(found.absent[-1])
                            return
                        first = begun.orbit
                        if found.known(f0, 1, first.impacts, float(orbit_measures(mapping, first).impulses.sum())):
                            return  # the bumper's branch from the other root already passed through it
                    else:
                        closed = solve_impact_orbit(mapping.problem, root=root)
                        first = shoot(mapping, closed_form_state(mapping.problem, closed), mapping.parameters)
                    branch = continue_branch(mapping, first, "frequency", settings)
                    label = found.add_branch(mapping, branch, kind)
                    maps.append((mapping, branch))
                    say(f"{kind.replace('_', '-')} branch {label} from {f0:.2f} Hz: {len(branch.orbits)} points, {len(branch.special_points)} special points")

                attempt("closed_form", f"{kind.replace('_', '-')} branch from {f0:.2f} Hz", start)
    if bumper and grazing:  # a bumper's contact branch is born smoothly where the contact-free orbit touches it (where
        # no branch from the rigid twin's closed form reached that onset already)
        for onset, outside in _onsets(segments, low, high):

            def from_onset(onset: float = onset, outside: float = outside) -> None:
                if any(point["kind"] == SPECIAL_POINT_KINDS.index("grazing") and abs(point["frequency"] - onset) <= SAME_POINT_FREQUENCY * onset for point in found.specials):
                    return  # a branch from another onset already ended here
                mapping = ImpactMap(problem_at(problem, onset), bounds=bounds)
                first = contact_orbit_at_onset(mapping, onset, outside)
                if first is None:
                    found.notes.append(f"no orbit with a contact found next to the contact onset at {onset:.6g} Hz")
                    return
                if found.known(first.parameter("frequency"), 1, first.impacts, float(orbit_measures(mapping, first).impulses.sum())):
                    return  # a branch from another onset already passed through it
                branch = continue_branch(mapping, first, "frequency", settings)
                label = found.add_branch(mapping, branch, "grazing")
                maps.append((mapping, branch))
                say(f"contact branch {label} from the contact onset at {onset:.6g} Hz: {len(branch.orbits)} points, {len(branch.special_points)} special points")

            attempt("grazing", f"contact branch from the onset at {onset:.6g} Hz", from_onset)
    if period_doubling:
        for mapping, branch in list(maps):
            for point in branch.special("period_doubling"):
                if point.orbit.period != 1 or point.induced_by is not None:
                    continue  # (a doubling induced by a contact onset has no smooth period-2 branch next to it)

                def doubled(mapping: ImpactMap = mapping, point: SpecialPoint = point) -> None:
                    orbit = switch_period_doubling(mapping, point)
                    child = continue_branch(Iterated(mapping, 2), orbit, "frequency", settings)
                    label = found.add_branch(mapping, child, "period_doubling")
                    maps.append((mapping, child))
                    say(f"period-2 branch {label} from the period doubling at {point.value:.3f} Hz: {len(child.orbits)} points")

                attempt("period_doubling", f"period-2 branch at {point.value:.3f} Hz", doubled)
    if grazing:
        grow_at_grazing(found, maps, settings, say=say)
    found.maps = maps
    return found


def _onsets(segments: list[NDArray[np.float64]], low: float, high: float) -> list[tuple[float, float]]:
    """(frequency [Hz], side) of each end of the contact-free orbit's ``segments`` that is a contact onset rather than
    an end of the band [low, high]: side -1 for a segment's first point (beyond it, below, the orbit crosses a stop),
    +1 for its last."""
    edge = 1e-9 * (high - low)
    out = []
    for segment in segments:
        if segment[0] > low + edge:
            out.append((float(segment[0]), -1.0))
        if segment[-1] < high - edge:
            out.append((float(segment[-1]), 1.0))
    return out


def _segment(mask: NDArray[np.bool_], k: int) -> tuple[int, int]:
    """First and last index of the run of True in ``mask`` that contains index ``k``."""
    first, last = k, k
    while first > 0 and mask[first - 1]:
        first -= 1
    while last < mask.size - 1 and mask[last + 1]:
        last += 1
    return first, last
