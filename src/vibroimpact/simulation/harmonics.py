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
from scipy.integrate import cumulative_trapezoid

from vibroimpact.engines.base import Trajectory
from vibroimpact.model.excitation import SweptSine

__all__ = ["HarmonicMeasures", "RunningEstimate", "measure", "running_fundamental", "running_at", "window_times"]


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

    @property
    def force(self) -> complex:
        """Fundamental of the total force on the base (suspension plus stop) [N]."""
        return self.suspension_force + self.contact_force


def measure(trajectory: Trajectory) -> HarmonicMeasures:
    """Fundamental harmonics, RMS and impact statistics over all periods of ``trajectory`` (needs its moments)."""
    periods = trajectory.periods
    if periods == 0 or trajectory.moments.shape[0] != periods:
        raise ValueError("measure() needs a trajectory of at least one period integrated with moments=True")
    problem = trajectory.problem
    window = periods * problem.period
    total = trajectory.moments.sum(axis=0)
    x1 = complex(2.0 * total[0] / window)
    impacts = trajectory.impulses.size
    peaks = trajectory.contact_peaks
    if peaks.shape[0]:
        peak_force, peak_acceleration = float(peaks[:, 0].max()), float(peaks[:, 1].max())
    elif impacts:
        peak_force = peak_acceleration = math.nan  # a rigid stop: impulses, no finite peak
    else:
        peak_force = peak_acceleration = 0.0
    return HarmonicMeasures(
        x1=x1,
        x2=complex(2.0 * total[1] / window),
        suspension_force=(problem.system.k1 + 1j * problem.omega * problem.system.b1) * x1,
        contact_force=complex(2.0 * total[2] / window),
        x1_rms=math.sqrt(max(total[3].real, 0.0) / window),
        x2_rms=math.sqrt(max(total[4].real, 0.0) / window),
        impacts_per_period=impacts / periods,
        mean_impulse=float(np.mean(trajectory.impulses)) if impacts else 0.0,
        impulse_per_period=float(np.sum(trajectory.impulses)) / periods,
        periods=periods,
        peak_contact_force=peak_force,
        peak_acceleration=peak_acceleration,
    )


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
