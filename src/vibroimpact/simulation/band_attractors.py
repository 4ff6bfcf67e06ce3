"""Every attractor brute force finds over a frequency band, and the largest |X1| among them: the true worst case a
design is judged by, non-periodic motions included (:func:`band_attractors`).

At equally spaced frequencies, the stepped sweeps of :mod:`vibroimpact.simulation.attractors` run up and down (each
carrying its end state to the next frequency), and more runs start at each frequency from the contact-free linear
state, rest on the stops and random states of the motion's size (:func:`attractor_starts`, seeded). Each run's motion
is measured and classified as :func:`~vibroimpact.simulation.attractors.measure_motion` does, every run (sweeps
included) in one call of :func:`~vibroimpact.simulation.attractors.measure_motions` (one compiled call for an engine
that batches, bit for bit the single runs); a contact-free motion's
|X1| is the closed form's (the only contact-free attractor is the linear steady state, where it clears the stops;
an undamped free mass's too, where it fits: no attractor, :func:`~vibroimpact.analysis.linear.contact_free_is_stable`, but
a motion that lasts while nothing disturbs it, and a run from rest stays on it).
The largest is :class:`AttractorMaximum`: where, which run, which motion, and its peak |x1(t)|.

It finds what continuation from the closed forms (:func:`vibroimpact.orbits.worst_case.worst_response`) does not
search: on the paper's layout with Delta = 3 mm, R = 0.8, a stable period-1 orbit with two impacts a period reaches
|X1| = 9.40 mm at 25.8 Hz, where the one-impact orbit's largest is 7.16 mm (tests/simulation/test_attractors.py).
Where the one-impact orbit sets the maximum, the two agree to the grid's resolution, |X''| h^2 / 8 at a smooth peak.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.measures import Measure, as_measure
from vibroimpact.engines.registry import engine_for
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.simulation.attractors import MOTION_CLASSES, at_frequency, measure_motions, sweep_arrays, sweep_chain
from vibroimpact.simulation.harmonics import gaps, linear_state, resting_state
from vibroimpact.simulation.history import engine_of

__all__ = ["PEAK_SAMPLES", "INSIDE", "pulled_inside", "AttractorMaximum", "AttractorSweep", "band_attractors", "attractor_labels", "attractor_starts"]

#: Samples per excitation period of the run that measures the peak |x1(t)| of the largest attractor [-] (a harmonic
#: motion's peak is then low by at most 1 - cos(pi / 256) = 7.5e-5, relative).
PEAK_SAMPLES = 256
#: A start that crosses a stop is moved to this fraction of the way from rest to touching it, strictly inside [-].
INSIDE = 0.999


@dataclass(frozen=True, eq=False)
class AttractorMaximum:
    """The largest |X1| of a brute-force search (:func:`band_attractors`) and the motion that has it.

    Attributes
    ----------
    amplitude : float
        |X1| [m]: the largest per-period fundamental of the first coordinate over the measured periods.
    frequency : float
        Where [Hz] (a point of the grid).
    motion : str
        Which motion: ``contact-free``, ``period k, n impacts`` (n impacts per k excitation periods), or a
        non-periodic class of :data:`MOTION_CLASSES` (``quasi_periodic``, ``chaotic``, ``irregular``) with its
        impacts per period.
    regime : str
        Its :data:`MOTION_CLASSES` name.
    period : int
        k [excitation periods] (0: the strobes do not repeat).
    impacts : float
        Impacts per excitation period [-].
    run : str
        The run that found it (``up``, ``down``, ``linear``, ``rest``, ``random i``).
    state : tuple of float
        Its state at the end of the measured periods, a strobe (t = 0 mod T) [m, m s-1], 2N entries.
    peak : float
        max |x1(t)| over the measured periods [m], sampled :data:`PEAK_SAMPLES` times a period from ``state`` (NaN
        where the engine cannot sample).
    """

    amplitude: float
    frequency: float
    motion: str
    regime: str
    period: int
    impacts: float
    run: str
    state: tuple[float, ...]
    peak: float = math.nan


@dataclass(frozen=True, eq=False)
class AttractorSweep:
    """Every attractor a brute-force search found over a band (:func:`band_attractors`), per frequency and run.

    Attributes
    ----------
    frequency : ndarray, shape (n,)
        The grid [Hz], increasing.
    runs : tuple of str, length r
        The runs at each frequency: ``up`` and ``down`` (the sweeps, each carrying its state), then the starts
        (``linear``, ``rest``, ``random 1`` ...).
    amplitude : ndarray, shape (n, r)
        |X1| of each run's attractor [m]: the largest per-period fundamental over the measured periods (the last
        period's, for a periodic orbit still being approached; the closed form's for a contact-free motion); NaN where
        the engine failed or the run is no attractor (a contact-free transient of a linear state that crosses a stop).
    measured : ndarray, shape (n, r)
        The largest per-period |X1| each run showed over its measured periods [m], as the engine gave it (a
        contact-free run included; NaN where the engine failed).
    regime : ndarray of int8, shape (n, r)
        :data:`MOTION_CLASSES` index, -1 where the engine failed.
    period : ndarray of int16, shape (n, r)
        k [excitation periods], 0 where the strobes do not repeat.
    impacts : ndarray, shape (n, r)
        Impacts per excitation period [-].
    lyapunov : ndarray, shape (n, r)
        The largest Lyapunov exponent [1/period] where the strobes do not repeat, else NaN.
    state : ndarray, shape (n, r, 2N)
        Each run's end state, a strobe [m, m s-1] (a seed for shooting).
    maximum : AttractorMaximum
        The largest |X1| over every run and frequency.
    """

    frequency: NDArray[np.float64]
    runs: tuple[str, ...]
    amplitude: NDArray[np.float64]
    measured: NDArray[np.float64]
    regime: NDArray[np.int8]
    period: NDArray[np.int16]
    impacts: NDArray[np.float64]
    lyapunov: NDArray[np.float64]
    state: NDArray[np.float64]
    maximum: AttractorMaximum

    def __post_init__(self) -> None:
        shape = (self.frequency.size, len(self.runs))
        for name in ("amplitude", "measured", "regime", "period", "impacts", "lyapunov"):
            if getattr(self, name).shape != shape:
                raise ValueError(f"{name}: expected shape {shape} (frequencies, runs), got {getattr(self, name).shape}")
        if self.state.shape[:2] != shape:
            raise ValueError(f"state: expected shape {shape} + (2N,), got {self.state.shape}")

    def largest(self) -> NDArray[np.float64]:
        """The largest |X1| over the runs at each frequency [m], shape (n,) (NaN where no run found an attractor)."""
        found = np.isfinite(self.amplitude)
        return np.where(found.any(axis=1), np.max(np.where(found, self.amplitude, -np.inf), axis=1), np.nan)


def band_attractors(
    problem: ImpactProblem, band: tuple[float, float], frequencies: int = 301, starts: int = 4, transient: int = 300, strobes: int = 64,
    engine: Any = None, seed: int = 0, measure: int | Measure = 0,
) -> AttractorSweep:  # fmt: skip
    """Every attractor brute force finds over ``band``, and the largest |X1| among them: the true worst case a design
    is judged by, non-periodic motions included.

    At ``frequencies`` equally spaced points of the band, sweeps up and down (as :func:`~vibroimpact.simulation.attractors.stepped_sweep`, each carrying its
    end state to the next point, in the same call as the starts) and ``starts`` more runs per point (:func:`attractor_starts`: the contact-free linear
    state, rest on the stops, then random states of the motion's size, seeded); each drops ``transient`` periods and
    measures ``strobes`` (:func:`~vibroimpact.simulation.attractors.measure_motion`). Every run's motion is stable by construction: it is what the flow
    settled on.

    What it can miss: an attractor whose basin none of the runs enters; one that exists only between grid points (a
    narrow window of frequency) or settles more slowly than ``transient`` periods; the exact maximum, which lies
    between grid points: off by the curvature times h^2 / 8 at a smooth peak, by the slope times h where a stable
    stretch ends at a fold, a grazing point or a period doubling (h = the band over frequencies - 1). A periodic
    orbit of period above :data:`~vibroimpact.simulation.attractors.MAX_PERIOD` is counted as non-periodic; a non-periodic run still in its transient
    (``irregular``) counts with the largest |X1| it showed.

    Parameters
    ----------
    problem : ImpactProblem
        Structure, stops (rigid or Kelvin-Voigt bumpers) and harmonic load; its frequency is replaced.
    band : (float, float)
        (low, high) [Hz].
    frequencies : int
        Points of the grid (>= 2).
    starts : int
        Runs per point besides the two sweeps (>= 0).
    transient, strobes : int
        Periods dropped, then measured, by every run (strobes >= 16; 2 :data:`~vibroimpact.simulation.attractors.MAX_PERIOD`
        = 64 to find every period and to tell a non-periodic motion's kind, else ``irregular``).
    engine : str or engine, optional
        A registry name or a built engine with exact Jacobians; by default the registry's first with them for the
        problem's contact law (:func:`vibroimpact.engines.registry.engine_for`: the compiled exact engine for rigid
        stops, the bumper's closed-form engine for Kelvin-Voigt bumpers).
    seed : int
        Of the random starts.
    measure : int or Measure
        What is measured and maximised: a row of :mod:`vibroimpact.analysis.measures`, or a coordinate index for its
        |X| (0: x1; the name |X1| above stands for it).
    """
    low, high = (float(f) for f in band)
    if not 0.0 < low < high or frequencies < 2 or starts < 0 or transient < 0 or strobes < 16:
        raise ValueError(f"band = {band!r}, frequencies = {frequencies!r}, starts = {starts!r}, transient = {transient!r}, strobes = {strobes!r}: "
                         "expected 0 < low < high [Hz], at least 2 frequencies and 16 strobes, no negative starts or transient")  # fmt: skip
    measure = as_measure(measure, problem)
    engine = engine_of(engine_for(problem.contact_law, "exact_jacobians") if engine is None else engine)
    f = np.linspace(low, high, frequencies)
    runs = ("up", "down") + attractor_labels(starts)
    n, r, s = f.size, len(runs), strobes
    rows = [sweep_arrays(n, s, 2 * problem.size) for _ in range(2 + starts)]
    rng = np.random.default_rng(seed)
    moved_all = [at_frequency(problem, float(f[k])) for k in range(n)]
    # the sweeps (each point from the previous one's end, from rest after a failure: stepped_sweep's rule), then every
    # start at every frequency: one call (one compiled call for an engine that batches); regime -1: no progress
    begun: list[tuple[int, int, NDArray[np.float64], int]] = []
    for j, order in enumerate((list(range(n)), list(range(n - 1, -1, -1)))):
        sweep_starts, links = sweep_chain([moved_all[k] for k in order], len(begun))
        begun += [(k, j, start, link) for k, start, link in zip(order, sweep_starts, links)]
    begun += [(k, 2 + j, start, -1) for k in range(n) for j, (_label, start) in enumerate(attractor_starts(moved_all[k], starts, rng))]
    found = measure_motions(engine, moved_all, [k for k, *_ in begun], [start for _k, _j, start, _c in begun], transient, s, measure, [c for *_, c in begun])
    for i, (k, j, _start, _link) in enumerate(begun):
        for name, values in found.items():
            rows[j][name][k] = values[i]
    amplitude = np.full((n, r), np.nan)
    measured = np.stack([np.where(row["regime"] >= 0, np.max(row["amplitude"], axis=1), np.nan) for row in rows], axis=1)
    for k, moved in enumerate(moved_all):
        linear = linear_state(moved)
        # an undamped free mass's contact-free motion is no attractor (a push makes it drift), but it lasts while
        # nothing disturbs it: a run that never touched a stop counts with it, where it fits
        free = measure.of_state(moved, linear.amplitudes) if linear.fits(moved) else math.nan
        for j, row in enumerate(rows):
            amplitude[k, j] = _attractor_amplitude(row, k, free)
    stack = {name: np.stack([row[name] for row in rows], axis=1) for name in ("regime", "period", "impacts", "lyapunov", "state")}
    maximum = _maximum(problem, engine, f, runs, amplitude, stack, s, measure)
    return AttractorSweep(f, runs, amplitude, measured, stack["regime"], stack["period"], stack["impacts"], stack["lyapunov"], stack["state"], maximum)


def attractor_labels(starts: int) -> tuple[str, ...]:
    """The names of ``starts`` runs of :func:`attractor_starts`: ``linear``, ``rest``, ``random 1`` ..."""
    return tuple(("linear", "rest")[:starts]) + tuple(f"random {i}" for i in range(1, starts - 1))


def attractor_starts(problem: ImpactProblem, starts: int, rng: np.random.Generator) -> list[tuple[str, NDArray[np.float64]]]:
    """``starts`` initial states at t = 0 [m, m s-1], each strictly inside every stop: the contact-free linear steady
    state, rest on the stops (:func:`~vibroimpact.simulation.harmonics.resting_state`), then random states about rest,
    each coordinate uniform in +-L and each velocity in +-w L with L the motion's length (:meth:`ImpactProblem.length_scale`)
    times a factor uniform in [0.5, 2]. A state that crosses a stop is pulled towards rest along the line to it until
    it is :data:`INSIDE` of the way to touching (the linear state: shrunk about rest)."""
    rest = resting_state(problem)
    size, length = problem.size, problem.length_scale()
    found = []
    for label in attractor_labels(starts):
        if label == "linear":
            state = linear_state(problem).state(problem.omega)
        elif label == "rest":
            state = rest.copy()
        else:
            spread = length * rng.uniform(0.5, 2.0)
            state = rest + np.concatenate([spread * rng.uniform(-1.0, 1.0, size), problem.omega * spread * rng.uniform(-1.0, 1.0, size)])
        found.append((label, pulled_inside(problem, rest, state)))
    return found


def pulled_inside(problem: ImpactProblem, rest: NDArray[np.float64], state: NDArray[np.float64]) -> NDArray[np.float64]:
    """``state``, or the point of the line from ``rest`` to it :data:`INSIDE` of the way to the first stop it touches."""
    towards = problem.normals() @ (state - rest)[: problem.size]  # n_k . (x - x_rest): how much closer to each stop
    room = gaps(problem, rest)
    crossing = (towards > 0.0) & (room - towards < 0.0)
    if not np.any(crossing):
        return np.asarray(state, dtype=float)
    scale = INSIDE * float(np.min(np.maximum(room[crossing], 0.0) / towards[crossing]))
    return rest + scale * (state - rest)


def _attractor_amplitude(row: dict[str, NDArray[Any]], k: int, free: float) -> float:
    """|X1| of the attractor of point ``k`` of a run [m]: the closed form's ``free`` for a contact-free motion (NaN:
    the linear state crosses a stop, a transient; an undamped free mass that never touched its stops counts with it:
    its motion lasts while nothing disturbs it), the last period's for a periodic orbit still being approached (a
    negative exponent), else the largest per-period |X1| over the measured periods."""
    regime = int(row["regime"][k])
    if regime < 0:
        return math.nan
    if regime == 0:
        return free
    per_period = row["amplitude"][k]
    if int(row["period"][k]) and np.isfinite(row["lyapunov"][k]):  # approached slowly: the last period is the closest
        return float(np.max(per_period[-int(row["period"][k]) :]))
    return float(np.max(per_period))


def _maximum(
    problem: ImpactProblem, engine: Any, f: NDArray[np.float64], runs: tuple[str, ...], amplitude: NDArray[np.float64], stack: dict[str, NDArray[Any]], strobes: int,
    measure: Measure,
) -> AttractorMaximum:  # fmt: skip
    """The largest entry of ``amplitude``, its motion, and the peak |x(t)| of the measure's coordinate from a sampled
    run (NaN for a measure of no coordinate)."""
    if not np.any(np.isfinite(amplitude)):
        return AttractorMaximum(math.nan, math.nan, "none", "none", 0, math.nan, "", ())
    k, j = np.unravel_index(int(np.nanargmax(amplitude)), amplitude.shape)
    regime, period, impacts = MOTION_CLASSES[int(stack["regime"][k, j])], int(stack["period"][k, j]), float(stack["impacts"][k, j])
    if regime == "linear":
        motion = "contact-free"
    elif period:
        count = int(round(impacts * period))
        motion = f"period {period}, {count} impact{'s' if count != 1 else ''}"
    else:
        motion = f"{regime}, {impacts:.3g} impacts per period"
    state = stack["state"][k, j]
    moved = at_frequency(problem, float(f[k]))
    peak = math.nan
    if hasattr(engine, "sample") and measure.coordinate is not None:
        times = np.linspace(0.0, strobes * moved.period, strobes * PEAK_SAMPLES + 1)
        peak = float(np.max(np.abs(engine.sample(moved, state, 0.0, strobes, times)[1][:, measure.coordinate])))
    return AttractorMaximum(float(amplitude[k, j]), float(f[k]), motion, regime, period, impacts, runs[j], tuple(float(x) for x in state), peak)
