"""Swept-sine tests of the compliant model as cases of a study (the paper's Simulink runs, section 5).

One case is one sweep direction at one (restitution, clearance, bumper): the compliant engine integrates the whole
sweep, then the running estimators (the paper's "Statistics" blocks) are evaluated over windows of whole excitation
cycles, centred (in phase) where the instantaneous frequency equals each frequency of the study's grid, and on a
uniform time grid for plots against time. Fundamentals are demodulated against the sweep's own phase; the contact
force enters through its exact quadrature (it is a pulse far shorter than the output sampling); impulses, impacts
and peak force and deceleration are counted per window from the contacts themselves.
"""

from __future__ import annotations

import sys
import time
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import cumulative_trapezoid

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.compliant.ida import CompliantEngine, SweepRecord
from vibroimpact.model.excitation import SweptSine
from vibroimpact.study.fingerprint import case_key
from vibroimpact.simulation.harmonics import running_at, running_fundamental, window_times
from vibroimpact.study.runner import ProgressReport
from vibroimpact.scene.schema import SweptSineSettings
from vibroimpact.model.system import TwoDofSystem

__all__ = ["SweepCase", "SWEEP_QUANTITIES", "SWEEP_FIELDS", "run_sweep_case", "running_quantities", "sweep_start_state"]

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
#: Whole-run statistics of a sweep.
SWEEP_STATS = ("wall_time", "steps", "contacts", "rhs_calls", "linear_start", "failed")
SWEEP_FIELDS = SWEEP_QUANTITIES + tuple(f"running_{q}" for q in SWEEP_QUANTITIES) + ("time", "instantaneous_frequency") + SWEEP_STATS


@dataclass(frozen=True)
class SweepCase:
    """One swept-sine run of the compliant model and the frequencies and times its estimates are reported at.

    Attributes
    ----------
    system : TwoDofSystem
        The linear system.
    amplitude : float
        q [N].
    clearance : float
        Delta [m].
    bumper_frequency : float
        Omega_b / 2 pi [Hz].
    bumper_loss_factor : float
        xi_b [-].
    settings : SweptSineSettings
        The sweep (ends, rate, sampling, window).
    direction : str
        ``up`` or ``down``.
    engine_settings : EngineSettings
        IDA tolerances.
    frequencies : tuple of float
        Frequencies at which window-centred estimates are reported [Hz] (NaN outside the sweep or its windows).
    time_points : int
        Points of the uniform time grid of the running estimates.
    """

    system: TwoDofSystem
    amplitude: float
    clearance: float
    bumper_frequency: float
    bumper_loss_factor: float
    settings: SweptSineSettings
    direction: str
    engine_settings: EngineSettings
    frequencies: tuple[float, ...]
    time_points: int = 2001

    engine = "compliant_sweep"
    fields = SWEEP_FIELDS

    progress_unit = "s simulated"

    @property
    def progress_total(self) -> float:
        """The sweep's duration [s]: progress is counted in simulated time."""
        return self.settings.sweep(self.amplitude, self.direction).duration

    def key(self) -> str:
        """A stable hash of everything that determines the result, the package version and its source code."""
        return case_key(asdict(self))

    def run(self, report: ProgressReport | None = None) -> dict[str, NDArray[np.generic]]:
        """Simulate the sweep and estimate (see :func:`run_sweep_case`)."""
        return run_sweep_case(self, report)


def run_sweep_case(case: SweepCase, report: ProgressReport | None = None) -> dict[str, NDArray[np.generic]]:
    """Run one sweep; estimates on ``case.frequencies`` and on the time grid, and the run's cost.

    ``report`` receives the simulated time reached [s] as the run goes on."""
    sweep = case.settings.sweep(case.amplitude, case.direction)
    engine = CompliantEngine(case.bumper_frequency, case.bumper_loss_factor, case.engine_settings)
    started = time.perf_counter()
    state = sweep_start_state(case.system, sweep, case.clearance) if case.settings.initial_state == "linear" else None
    times = np.linspace(0.0, sweep.duration, case.time_points)
    try:
        record = engine.sweep(case.system, case.clearance, sweep, case.settings.sample_rate, state, report)
    except (RuntimeError, ValueError, ArithmeticError) as error:
        # a failing run must not cost the others: it stays NaN, flagged, and the study goes on
        print(f"compliant sweep {case.direction}: Delta = {case.clearance:g} m, bumper {case.bumper_frequency:g} Hz, xi_b = {case.bumper_loss_factor:g} failed: {error}", file=sys.stderr)
        failed: dict[str, NDArray[np.generic]] = {name: np.full(len(case.frequencies), np.nan) for name in SWEEP_QUANTITIES}
        failed |= {f"running_{name}": np.full(times.size, np.nan) for name in SWEEP_QUANTITIES}
        failed |= {"time": times, "instantaneous_frequency": sweep.frequency(times)}
        failed |= {name: np.array(np.nan) for name in SWEEP_STATS}
        failed["linear_start"] = np.array(float(state is not None))
        failed["failed"] = np.array(1.0)
        return failed
    wall_time = time.perf_counter() - started
    frequencies = np.asarray(case.frequencies, dtype=float)
    with np.errstate(invalid="ignore"):
        at_frequency = (frequencies - sweep.start_frequency) / sweep.alpha
    inside = (at_frequency >= 0.0) & (at_frequency <= sweep.duration)
    centres = np.where(inside, at_frequency, np.nan)
    cycles = case.settings.window_cycles
    on_grid = running_quantities(record, centres, cycles)
    on_times = running_quantities(record, times, cycles)
    stats = record.trajectory.stats
    out: dict[str, NDArray[np.generic]] = {name: on_grid[name] for name in SWEEP_QUANTITIES}
    out |= {f"running_{name}": on_times[name] for name in SWEEP_QUANTITIES}
    out["time"] = times
    out["instantaneous_frequency"] = sweep.frequency(times)
    out["wall_time"] = np.array(wall_time)
    for name in ("steps", "contacts", "rhs_calls"):
        out[name] = np.array(float(stats.get(name, np.nan)))
    out["linear_start"] = np.array(float(state is not None))  # the linear start falls back to rest where it would cross the stop
    out["failed"] = np.array(0.0)
    return out


def sweep_start_state(system: TwoDofSystem, sweep: SweptSine, clearance: float) -> NDArray[np.float64] | None:
    """(X1, X2, X1', X2') of the linear steady response to q sin(2 pi f0 t) at t = 0, or None (rest) if its absorber
    amplitude exceeds the clearance."""
    omega = 2.0 * np.pi * sweep.start_frequency
    h = system.receptances(omega)
    x = sweep.amplitude * np.array([complex(h.h11), complex(h.h12)]) * -1j  # sin = cos delayed by a quarter period
    if abs(x[1]) > clearance:
        return None
    return np.concatenate([x.real, (1j * omega * x).real])


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
