"""The physics of one swept-sine run of the compliant model: where it starts, and what is measured from it.

The running estimators are the paper's "Statistics" blocks (section 5): evaluated over windows of whole excitation
cycles, centred (in phase) where the instantaneous frequency equals each frequency of a grid, and on a uniform time
grid for plots against time. Fundamentals are demodulated against the sweep's own phase; the contact force enters
through its exact quadrature (it is a pulse far shorter than the output sampling); impulses, impacts and peak force
and deceleration are counted per window from the contacts themselves.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import cumulative_trapezoid

from vibroimpact.engines.base import SweepRecord
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.simulation.harmonics import running_at, running_fundamental, window_times

__all__ = ["SWEEP_QUANTITIES", "sweep_start_state", "sweep_estimates", "running_quantities"]

#: Quantities estimated per window, on the frequency grid and (prefixed ``running_``) on the time grid.
SWEEP_QUANTITIES = (
    "x1_amplitude",
    "x2_amplitude",
    "force_amplitude",
    "suspension_force_amplitude",
    "impulse",
    "impacts_per_period",
    "x1_rms",
    "x2_rms",
    "peak_acceleration",
    "peak_contact_force",
)
def sweep_start_state(system: TwoDofSystem, sweep: SweptSine, clearance: float) -> NDArray[np.float64] | None:
    """(X1, X2, X1', X2') of the linear steady response to q sin(2 pi f0 t) at t = 0, or None (rest) if its absorber
    amplitude exceeds the clearance."""
    omega = 2.0 * np.pi * sweep.start_frequency
    h = system.receptances(omega)
    x = sweep.amplitude * np.array([complex(h.h11), complex(h.h12)]) * -1j  # sin = cos delayed by a quarter period
    if abs(x[1]) > clearance:
        return None
    return np.concatenate([x.real, (1j * omega * x).real])


def sweep_estimates(record: SweepRecord, sweep: SweptSine, frequencies: tuple[float, ...], times: NDArray[np.float64], cycles: int) -> dict[str, NDArray[np.generic]]:
    """What a swept run measured: each of :data:`SWEEP_QUANTITIES` over windows of ``cycles`` cycles centred where the
    instantaneous frequency of ``sweep`` equals each of ``frequencies`` [Hz] (NaN outside the sweep or its windows),
    the same prefixed ``running_`` on the time grid ``times`` [s], and the time axes ``time`` [s] and
    ``instantaneous_frequency`` [Hz]."""
    grid = np.asarray(frequencies, dtype=float)
    with np.errstate(invalid="ignore"):
        at_frequency = (grid - sweep.start_frequency) / sweep.alpha
    inside = (at_frequency >= 0.0) & (at_frequency <= sweep.duration)
    centres = np.where(inside, at_frequency, np.nan)
    on_grid = running_quantities(record, centres, cycles)
    on_times = running_quantities(record, times, cycles)
    out: dict[str, NDArray[np.generic]] = {name: on_grid[name] for name in SWEEP_QUANTITIES}
    out |= {f"running_{name}": on_times[name] for name in SWEEP_QUANTITIES}
    out["time"] = times
    out["instantaneous_frequency"] = sweep.frequency(times)
    return out


def running_quantities(record: SweepRecord, centres: NDArray[np.float64], cycles: int) -> dict[str, NDArray[np.float64]]:
    """The paper's running estimates of a sweep over windows of ``cycles`` cycles centred on ``centres`` [s].

    Fundamentals |x| are ``|integral x exp(-j theta) d theta| / (pi cycles)``; RMS over the window's duration;
    impulse and impacts per excitation period; peak force and deceleration over the window's contacts (0 without
    contact). NaN where the window leaves the run (or the centre is NaN).
    """
    sweep: SweptSine = record.sweep
    t = record.time
    rotor = np.exp(-1j * sweep.phase(t)) * (2.0 * np.pi * sweep.frequency(t))  # exp(-j theta) d theta / dt
    suspension = record.base_force - record.contact_force
    span = np.pi * cycles
    x1 = running_fundamental(t, record.x1, sweep, cycles, centres)
    x2 = running_fundamental(t, record.x2, sweep, cycles, centres)
    safe = np.nan_to_num(centres, nan=t[0])
    start, end = window_times(sweep, safe, cycles)
    valid = np.isfinite(x1.amplitude)
    contact = running_at(t, record.contact_fourier, sweep, centres, cycles)
    suspension_fourier = running_at(t, cumulative_trapezoid(suspension * rotor, t, initial=0.0), sweep, centres, cycles)
    trajectory = record.trajectory
    onsets = trajectory.impact_times
    first = np.searchsorted(onsets, np.where(valid, start, t[0]))
    last = np.searchsorted(onsets, np.where(valid, end, t[0]))
    impulses = np.concatenate([[0.0], np.cumsum(trajectory.impulses)])
    peaks = trajectory.contact_peaks if trajectory.contact_peaks.shape[0] == onsets.size else np.full((onsets.size, 2), np.nan)
    peak_force, peak_acceleration = np.zeros(centres.shape), np.zeros(centres.shape)
    for i in np.flatnonzero(valid & (last > first)):
        peak_force[i], peak_acceleration[i] = peaks[first[i] : last[i]].max(axis=0)
    nan = np.where(valid, 1.0, np.nan)
    return {
        "x1_amplitude": x1.amplitude,
        "x2_amplitude": x2.amplitude,
        "force_amplitude": np.abs(suspension_fourier + contact) / span,
        "suspension_force_amplitude": np.abs(suspension_fourier) / span,
        "impulse": (impulses[last] - impulses[first]) / cycles * nan,
        "impacts_per_period": (last - first) / cycles * nan,
        "x1_rms": x1.rms,
        "x2_rms": x2.rms,
        "peak_acceleration": peak_acceleration * nan,
        "peak_contact_force": peak_force * nan,
    }
