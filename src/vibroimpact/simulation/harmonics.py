"""Fundamental harmonics and RMS: over whole periods of a steady state, and running over a swept sine.

Over N whole periods of length T the complex fundamental amplitude of a signal x(t) is
``(2 / (N T)) * integral x(t) exp(-j w t) dt`` (|.| is the amplitude of its cos(w t + phi) component), and its RMS is
``sqrt(integral x^2 dt / (N T))``. Engines accumulate the integrals exactly per period (Gauss-Legendre on each smooth
segment for ``exact``, quadrature states for the integrators), impulses included as their exact Fourier terms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_trapezoid

from vibroimpact.analysis.linear import base_coupling, base_force  # their home; here for the callers of this module
from vibroimpact.engines.base import Trajectory
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure

__all__ = ["base_force", "suspension_force", "base_coupling", "base_weights", "LinearState", "linear_state", "static_offset", "resting_state", "gaps", "HarmonicMeasures", "RunningEstimate", "measure", "running_fundamental", "running_at", "window_times"]


# --------------------------------------------------------------------------------------------------------------------
# What steady states need to know of any layout: the linear steady state, the force on the base and a start that
# respects every stop.
# --------------------------------------------------------------------------------------------------------------------

def suspension_force(system: LinearStructure, omega: float, x: NDArray[np.complex128]) -> complex:
    """Fundamental of the force on the base through springs and dashpots [N] for coordinate fundamentals ``x`` [m]."""
    return complex(base_force(system, omega, x))


def base_weights(problem: ImpactProblem) -> NDArray[np.float64]:
    """1^T n_k of every stop: +1 an upper stop against the base, -1 a lower one, 0 a relative stop, shape (K,)."""
    return problem.normals().sum(axis=1)


def static_offset(problem: ImpactProblem) -> NDArray[np.float64]:
    """x0 = K^-1 F0, the static displacement under the constant load [m] (least squares on a free structure:
    no offset along a rigid-body mode); zeros without a static load."""
    _, static = problem.load()
    if not np.any(static):
        return np.zeros(problem.size)
    return np.linalg.lstsq(problem.structure.stiffness_matrix, static, rcond=None)[0]


class LinearState:
    """The linear steady state without stops: x(t) = x0 + Re(X e^{j w t}) (force phase included).

    Attributes
    ----------
    amplitudes : ndarray of complex, shape (N,)
        X [m].
    offset : ndarray, shape (N,)
        x0 [m].
    """

    def __init__(self, amplitudes: NDArray[np.complex128], offset: NDArray[np.float64]) -> None:
        self.amplitudes, self.offset = amplitudes, offset

    def state(self, omega: float) -> NDArray[np.float64]:
        """(x, x') at t = 0 [m, m s-1]."""
        return np.concatenate([self.offset + self.amplitudes.real, (1j * omega * self.amplitudes).real])

    def rms(self) -> NDArray[np.float64]:
        """RMS of each coordinate over a period [m]."""
        return np.sqrt(self.offset**2 + 0.5 * np.abs(self.amplitudes) ** 2)

    def fits(self, problem: ImpactProblem) -> bool:
        """Does the motion stay clear of every stop: n_k . x0 + |n_k . X| <= Delta_k?"""
        normals = problem.normals()
        reach = normals @ self.offset + np.abs(normals @ self.amplitudes)
        return bool(np.all(reach <= problem.clearances()))


def linear_state(problem: ImpactProblem) -> LinearState:
    """The linear steady state of ``problem`` without its stops (harmonic force with its phase)."""
    harmonic, _ = problem.load()
    h = problem.structure.receptance_matrix(problem.omega)
    return LinearState(h @ harmonic, static_offset(problem))


def gaps(problem: ImpactProblem, state: NDArray[np.float64]) -> NDArray[np.float64]:
    """Delta_k - n_k . x of every stop [m] (negative: inside the stop)."""
    return problem.clearances() - problem.normals() @ np.asarray(state[: problem.size], dtype=float)


def resting_state(problem: ImpactProblem) -> NDArray[np.float64]:
    """A state at rest that respects every stop: the static position, pushed onto the stops it would cross.

    The push is the one a contact gives, along M^-1 n_k: x = x0 - M^-1 N_a^T lambda with N_a x = Delta_a on the
    stops crossed (solved in the least-squares sense, repeated while another stop is crossed). Zeros for the paper's
    layout with a non-negative clearance.
    """
    size = problem.size
    x = static_offset(problem)
    normals, clearances = problem.normals(), problem.clearances()
    minv_n = np.linalg.solve(problem.structure.mass_matrix, normals.T)  # (N, K)
    active = np.zeros(len(clearances), dtype=bool)
    for _ in range(len(clearances) + 1):
        crossed = clearances - normals @ x < -1e-15 * (1.0 + np.abs(clearances))
        if not np.any(crossed & ~active):
            break
        active |= crossed
        a = normals[active]
        lam = np.linalg.lstsq(a @ minv_n[:, active], a @ x - clearances[active], rcond=None)[0]
        x = x - minv_n[:, active] @ lam
    return np.concatenate([x, np.zeros(size)])


def velocity_length(problem: ImpactProblem) -> float:
    """A length typical of the motion [m]: the problem's velocity scale over w (Delta + q |H12| for the paper)."""
    return problem.length_scale() if problem.omega > 0.0 else math.inf

@dataclass(frozen=True)
class HarmonicMeasures:
    """Steady-state quantities measured over whole periods.

    Attributes
    ----------
    x1, x2 : complex
        Fundamental-harmonic complex amplitudes of X1 and X2 [m] (phase relative to cos(w t)).
    suspension_force : complex
        Fundamental of K1 X1 + B1 X1' [N], taken as (K1 + j w B1) times the X1 fundamental.
    contact_force : complex
        Fundamental of the force of the stop on the base: impulses plus the holding force while stuck [N].
    x1_rms, x2_rms : float
        RMS of X1 and X2 [m].
    impacts_per_period : float
        Impacts per period [-].
    mean_impulse : float
        Mean impulse per impact [N s]; 0 if there was none. With chattering it depends on how many impacts were
        resolved before sticking (``EngineSettings.sticking_velocity``): prefer ``impulse_per_period``.
    impulse_per_period : float
        Total impulse of the impacts per period [N s]: the impact impulse for one impact per period; with
        chattering, the converged sum of the sequence (the unresolved rest is negligible).
    periods : int
        Whole periods measured.
    peak_contact_force : float
        Largest contact force over the measured contacts [N]: compliant bumpers only (NaN for a rigid stop, whose
        force is an impulse; 0 without contact).
    peak_acceleration : float
        Largest deceleration of the absorber in contact [m s-2]: compliant bumpers only (NaN for a rigid stop).
    displacements : tuple of complex
        Fundamental of every coordinate [m] (N values; ``x1``, ``x2`` are the first two).
    rms : tuple of float
        RMS of every coordinate [m].
    stop_contact_forces : tuple of complex
        Fundamental of each stop's contact force lambda_k [N] (K values).
    stop_impacts : tuple of float
        Impacts per period on each stop [-].
    stop_impulses : tuple of float
        Impulse per period on each stop [N s].
    stop_peak_forces, stop_peak_accelerations : tuple of float
        Per stop as ``peak_contact_force`` and ``peak_acceleration`` (the stopped coordinate's deceleration).
    """

    x1: complex
    x2: complex
    suspension_force: complex
    contact_force: complex
    x1_rms: float
    x2_rms: float
    impacts_per_period: float
    mean_impulse: float
    impulse_per_period: float
    periods: int
    peak_contact_force: float = math.nan
    peak_acceleration: float = math.nan
    displacements: tuple[complex, ...] = ()
    rms: tuple[float, ...] = ()
    stop_contact_forces: tuple[complex, ...] = ()
    stop_impacts: tuple[float, ...] = ()
    stop_impulses: tuple[float, ...] = ()
    stop_peak_forces: tuple[float, ...] = ()
    stop_peak_accelerations: tuple[float, ...] = ()

    @property
    def force(self) -> complex:
        """Fundamental of the total force on the base (suspension plus stop) [N]."""
        return self.suspension_force + self.contact_force


def measure(trajectory: Trajectory) -> HarmonicMeasures:
    """Fundamental harmonics, RMS and impact statistics over all periods of ``trajectory`` (needs its moments).

    Moments are (coordinates, contact force of each stop, squares of the coordinates) per period; the force on the
    base is the suspension's plus the absolute stops' ((1^T n_k) lambda_k: a relative stop acts inside the structure).
    """
    periods = trajectory.periods
    if periods == 0 or trajectory.moments.shape[0] != periods:
        raise ValueError("measure() needs a trajectory of at least one period integrated with moments=True")
    problem = trajectory.problem
    size, count = problem.size, len(problem.stops)
    window = periods * problem.period
    total = trajectory.moments.sum(axis=0)
    x = 2.0 * total[:size] / window
    forces = 2.0 * total[size : size + count] / window
    squares = total[size + count : 2 * size + count].real
    rms = np.sqrt(np.maximum(squares, 0.0) / window)
    impacts = trajectory.impulses.size
    stops = trajectory.impact_stops
    stop_impacts = np.bincount(stops, minlength=count)[:count] / periods
    stop_impulses = np.bincount(stops, weights=trajectory.impulses, minlength=count)[:count] / periods
    peaks = trajectory.contact_peaks
    peak_force, peak_acceleration = _peaks(peaks, impacts)
    per_stop = [_peaks(peaks[trajectory.contact_peak_stops == k], int(np.count_nonzero(stops == k))) for k in range(count)]
    contact = complex(base_weights(problem) @ forces)
    nan = complex(math.nan, math.nan)
    return HarmonicMeasures(
        x1=complex(x[0]),
        x2=complex(x[1]) if size > 1 else nan,
        suspension_force=suspension_force(problem.system, problem.omega, x),
        contact_force=contact,
        x1_rms=math.sqrt(max(squares[0], 0.0) / window),
        x2_rms=math.sqrt(max(squares[1], 0.0) / window) if size > 1 else math.nan,
        impacts_per_period=impacts / periods,
        mean_impulse=float(np.mean(trajectory.impulses)) if impacts else 0.0,
        impulse_per_period=float(np.sum(trajectory.impulses)) / periods,
        periods=periods,
        peak_contact_force=peak_force,
        peak_acceleration=peak_acceleration,
        displacements=tuple(complex(v) for v in x),
        rms=tuple(float(v) for v in rms),
        stop_contact_forces=tuple(complex(v) for v in forces),
        stop_impacts=tuple(float(v) for v in stop_impacts),
        stop_impulses=tuple(float(v) for v in stop_impulses),
        stop_peak_forces=tuple(p[0] for p in per_stop),
        stop_peak_accelerations=tuple(p[1] for p in per_stop),
    )


def _peaks(peaks: np.ndarray, impacts: int) -> tuple[float, float]:
    """Largest contact force [N] and deceleration [m s-2] of compliant contacts; NaN for impulses of a rigid stop;
    0 without contact."""
    if peaks.shape[0]:
        return float(peaks[:, 0].max()), float(peaks[:, 1].max())
    if impacts:
        return math.nan, math.nan
    return 0.0, 0.0


@dataclass(frozen=True)
class RunningEstimate:
    """Running fundamental harmonic and RMS of a swept-sine response (the paper's "Statistics" blocks).

    Attributes
    ----------
    time : ndarray
        Centre of each window (in phase) [s]: one per sample where a whole window ends.
    frequency : ndarray
        Instantaneous excitation frequency at that centre [Hz]: the axis to plot against.
    amplitude : ndarray
        Fundamental-harmonic amplitude over the window [units of the signal].
    rms : ndarray
        RMS over the same window [units of the signal].
    """

    time: np.ndarray
    frequency: np.ndarray
    amplitude: np.ndarray
    rms: np.ndarray


def running_fundamental(t: np.ndarray, x: np.ndarray, sweep: SweptSine, cycles: int = 8, centres: np.ndarray | None = None) -> RunningEstimate:
    """Demodulate ``x`` against the sweep's own sin and cos over a moving window of ``cycles`` whole cycles.

    Each window spans ``cycles`` whole cycles of the excitation phase theta, centred (in phase) on its time; the
    integrals are taken in theta, so for x = A sin(theta + phi) the estimate is exactly A, however fast the sweep
    (sampling error aside: trapezoidal sums, second order in the step), and harmonics and offsets cancel.

    Parameters
    ----------
    t : ndarray
        Increasing sample times [s].
    x : ndarray
        Signal at those times.
    sweep : SweptSine
        The excitation (its phase theta(t)).
    cycles : int
        Window length in excitation cycles, >= 1.
    centres : ndarray, optional
        Window centres [s]; by default one window ending at each sample (where a whole window fits). NaN where a
        window leaves the samples.
    """
    if cycles < 1:
        raise ValueError(f"cycles = {cycles!r} is out of range: allowed [1, inf)")
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    theta = sweep.phase(t)
    if centres is None:
        ends = theta[theta - 2.0 * np.pi * cycles >= theta[0]]
        centres = sweep.time_at_phase(ends - np.pi * cycles)
    centres = np.asarray(centres, dtype=float)
    rotor = np.exp(-1j * theta) * (2.0 * np.pi * sweep.frequency(t))  # exp(-j theta) d theta / dt
    fourier = running_at(t, cumulative_trapezoid(x * rotor, t, initial=0.0), sweep, centres, cycles)
    start, end = window_times(sweep, centres, cycles)
    squares = running_at(t, cumulative_trapezoid(x * x, t, initial=0.0), sweep, centres, cycles)
    return RunningEstimate(time=centres, frequency=sweep.frequency(centres), amplitude=np.abs(fourier) / (np.pi * cycles), rms=np.sqrt(squares / (end - start)))


def window_times(sweep: SweptSine, centres: np.ndarray, cycles: int) -> tuple[np.ndarray, np.ndarray]:
    """Start and end [s] of the windows of ``cycles`` whole excitation cycles centred (in phase) on ``centres`` [s]."""
    theta = sweep.phase(centres)
    half = np.pi * cycles
    return sweep.time_at_phase(theta - half), sweep.time_at_phase(theta + half)


def running_at(t: np.ndarray, cumulative: np.ndarray, sweep: SweptSine, centres: np.ndarray, cycles: int) -> np.ndarray:
    """Increase of a cumulative integral sampled at ``t`` over each window of :func:`window_times`.

    ``cumulative`` may be complex (e.g. the integral of x exp(-j theta) theta' dt). NaN where a window leaves the
    samples. Linear interpolation between samples: exact for integrals that are constant between them (impulses).
    """
    start, end = window_times(sweep, centres, cycles)
    slack = 1e-12 * (t[-1] - t[0])  # a window ending exactly at the last sample is inside despite round-off
    with np.errstate(invalid="ignore"):
        inside = (start >= t[0] - slack) & (end <= t[-1] + slack)

    def at(times: np.ndarray) -> np.ndarray:
        if np.iscomplexobj(cumulative):
            return np.interp(times, t, cumulative.real) + 1j * np.interp(times, t, cumulative.imag)
        return np.interp(times, t, cumulative)

    values = at(np.where(inside, end, t[0])) - at(np.where(inside, start, t[0]))
    return np.where(inside, values, np.nan)
