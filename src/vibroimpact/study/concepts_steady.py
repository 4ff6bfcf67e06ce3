"""Steady states of an absorber concept at one frequency, for any structure and any stops: march until the
stroboscopic state repeats, then measure whole periods.

Everything is read through the engines' trajectory contract (states 2N wide; per-period moments 2N + K wide:
coordinates, then each stop's contact force, then the squares), so the same code serves the paper's layout and
stops between masses or on both sides. The force on the base is what the structure's ground springs and dashpots
and its absolute stops push the base with::

    f_base = 1^T (K x + C x') + sum_k (1^T n_k) lambda_k

(1 the vector of ones: internal springs cancel; a relative stop's normal sums to zero, so its force stays inside the
structure). For the paper's system it is K1 X1 + B1 X1' plus the stop's force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.base import Trajectory
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.simulation.layout import base_force, base_weights
from vibroimpact.simulation.settings import SteadySettings

__all__ = ["Fundamentals", "SteadyOutcome", "fundamentals", "linear_start", "march", "length_scale", "check_stops", "GAP_TOLERANCE"]

#: Largest |gap| at an impact, and largest penetration anywhere recorded, as a fraction of the motion's length scale [-].
GAP_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Fundamentals:
    """Fundamental harmonics and impact statistics over whole periods of a trajectory.

    Attributes
    ----------
    x : ndarray of complex, shape (N,)
        Complex fundamental amplitude of each coordinate [m] (phase relative to cos(w t)).
    contact : ndarray of complex, shape (K,)
        Fundamental of each stop's contact force lambda_k [N].
    base_force : complex
        Fundamental of the force on the base [N] (module docstring).
    impacts_per_period : float
        Impacts (rigid) or contacts (bumper) per period [-].
    impulse_per_period : float
        Total impulse of the impacts (contacts) per period, every stop [N s].
    peak_acceleration : float
        Largest deceleration in contact [m s-2]: bumpers only (NaN for a rigid stop with impacts, 0 without contact).
    peak_contact_force : float
        Largest contact force [N]: bumpers only (NaN for a rigid stop with impacts, 0 without contact).
    """

    x: NDArray[np.complex128]
    contact: NDArray[np.complex128]
    base_force: complex
    impacts_per_period: float
    impulse_per_period: float
    peak_acceleration: float
    peak_contact_force: float


def fundamentals(trajectory: Trajectory) -> Fundamentals:
    """:class:`Fundamentals` over every period of ``trajectory`` (integrated with ``moments=True``)."""
    periods = trajectory.periods
    if periods == 0 or trajectory.moments.shape[0] != periods:
        raise ValueError("fundamentals() needs a trajectory of at least one period integrated with moments=True")
    problem = trajectory.problem
    n, k = problem.size, len(problem.stops)
    total = trajectory.moments.sum(axis=0)
    scale = 2.0 / (periods * problem.period)
    x = total[:n] * scale
    contact = total[n : n + k] * scale
    peaks = trajectory.contact_peaks
    contacts = trajectory.impulses.size
    if peaks.shape[0]:
        peak_force, peak_acceleration = float(peaks[:, 0].max()), float(peaks[:, 1].max())
    elif contacts:
        peak_force = peak_acceleration = math.nan
    else:
        peak_force = peak_acceleration = 0.0
    return Fundamentals(x, contact, complex(base_force(problem.structure, problem.omega, x, base_weights(problem), contact)), contacts / periods, float(np.sum(trajectory.impulses)) / periods, peak_acceleration, peak_force)


def length_scale(problem: ImpactProblem) -> float:
    """A displacement typical of the motion [m]: the largest |Delta_k| + |n_k . H F| over the stops."""
    return problem.velocity_scale() / problem.omega


def linear_start(problem: ImpactProblem) -> NDArray[np.float64]:
    """The linear steady state (no stop) at t = 0 as a state (x, x'), or rest if it starts inside a stop."""
    harmonic, static = problem.load()
    structure = problem.structure
    x = structure.receptance_matrix(problem.omega) @ harmonic
    offset = np.linalg.lstsq(structure.stiffness_matrix, static, rcond=None)[0] if np.any(static) else np.zeros(problem.size)
    state = np.concatenate([x.real + offset, (1j * problem.omega * x).real])
    gaps = problem.clearances() - problem.normals() @ state[: problem.size]
    return state if np.all(gaps >= 0.0) else np.zeros(2 * problem.size)


def check_stops(trajectory: Trajectory) -> None:
    """Rigid stops: ``RuntimeError`` unless every impact of ``trajectory`` happens on its stop's closed gap and no recorded state
    (strobes, segment starts) is inside a stop, to :data:`GAP_TOLERANCE` of the motion's length: an engine that does
    not know a layout (e.g. takes a relative stop for the paper's) is refused instead of trusted."""
    problem = trajectory.problem
    if not all(isinstance(stop.law, RigidStop) for stop in problem.stops):
        return  # a bumper is compressed while in contact: penetration is its law, nothing to check
    normals, clearances = problem.normals(), problem.clearances()
    size = problem.size
    tolerance = GAP_TOLERANCE * length_scale(problem)
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
    measures : Fundamentals
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

    measures: Fundamentals
    converged: bool
    multiplicity: int
    periods: int
    time: float
    state: NDArray[np.float64]


def _repeat(strobes: NDArray[np.float64], scale: NDArray[np.float64], settings: SteadySettings) -> int:
    """Smallest p <= max_multiplicity with the last 2 p + 1 strobes repeating with period p (0 if none); p > 1 only
    when successive strobes differ macroscopically (a slowly turning transient is not a period-p motion)."""
    step = float(np.max(np.abs(strobes[-1] - strobes[-2]) / scale)) if strobes.shape[0] >= 2 else 0.0
    for p in range(1, settings.max_multiplicity + 1):
        if (p > 1 and step < 1e3 * settings.tolerance) or strobes.shape[0] < 2 * p + 1:
            break
        if np.all(np.abs(strobes[-(p + 1) :] - strobes[-(2 * p + 1) : -p]) <= settings.tolerance * scale):
            return p
    return 0


def march(engine: object, problem: ImpactProblem, t: float, y: NDArray[np.float64], settings: SteadySettings, max_periods: int | None = None) -> SteadyOutcome:
    """Integrate from (t [s], y) until the strobes repeat (at most ``max_periods``, default the settings'), then
    measure ``measure_periods`` (a multiple of the period found) or ``irregular_measure_periods`` with moments."""
    length = length_scale(problem)
    n = problem.size
    scale = np.concatenate([np.full(n, length), np.full(n, problem.omega * length)])
    limit = settings.max_periods if max_periods is None else int(max_periods)
    strobes = [np.asarray(y, dtype=float)]
    used = multiplicity = 0
    while used < limit and not multiplicity:
        chunk = min(settings.chunk_periods, limit - used)
        run = engine.integrate(problem, y, t, chunk)  # type: ignore[attr-defined]
        used += chunk
        strobes.extend(run.strobe_states[1:])
        t, y = float(run.strobe_times[-1]), run.final_state
        multiplicity = _repeat(np.array(strobes[-3 * settings.max_multiplicity - 1 :]), scale, settings)
    measured = multiplicity * math.ceil(settings.measure_periods / multiplicity) if multiplicity else settings.irregular_measure_periods
    final = engine.integrate(problem, y, t, measured, moments=True)  # type: ignore[attr-defined]
    check_stops(final)
    return SteadyOutcome(fundamentals(final), multiplicity > 0, multiplicity, used + measured, t, np.array(y, dtype=float))
