"""The physics of one swept-sine run of the compliant model: where it starts, and what is measured from it.

The running estimators are the paper's "Statistics" blocks (section 5): evaluated over windows of whole excitation
cycles, centred (in phase) where the instantaneous frequency equals each frequency of a grid, and on a uniform time
grid for plots against time. Fundamentals are demodulated against the sweep's own phase; the contact forces enter
through their exact quadratures (each is a pulse far shorter than the output sampling); impulses, impacts and peak
force and deceleration are counted per window from the contacts themselves. Any structure and stops: one
fundamental and RMS per coordinate (``<name>_amplitude``, ``<name>_rms``), the impulse and peaks per stop, and the
force on the base through springs, dashpots and the absolute stops (the paper's eq. 23 on its layout).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import cumulative_trapezoid

from vibroimpact.engines.base import SweepRecord
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.simulation.harmonics import running_at, running_fundamental, window_times, base_weights, linear_state

__all__ = ["SWEEP_STOP_QUANTITIES", "sweep_quantities", "sweep_start_state", "sweep_estimates", "running_quantities"]

#: Quantities estimated per window, with one value per stop (a leading axis of K).
SWEEP_STOP_QUANTITIES = ("impulse", "peak_acceleration", "peak_contact_force")
#: Quantities estimated per window, in order; ``x1_*`` stands for one per coordinate (see :func:`sweep_quantities`).
_QUANTITIES = (
    "x1_amplitude",
    "force_amplitude",
    "suspension_force_amplitude",
    "impulse",
    "impacts_per_period",
    "x1_rms",
    "peak_acceleration",
    "peak_contact_force",
)


def sweep_quantities(coordinates: tuple[str, ...]) -> tuple[str, ...]:
    """The quantities a swept run of a structure with these coordinates estimates per window, on the frequency grid
    and (prefixed ``running_``) on the time grid: ``<name>_amplitude`` and ``<name>_rms`` per coordinate (``x1_amplitude,
    x2_amplitude`` ... for the paper's system), the forces on the base, impacts per period, and the per-stop
    :data:`SWEEP_STOP_QUANTITIES`."""
    out: list[str] = []
    for quantity in _QUANTITIES:
        if quantity.startswith("x1_"):
            out += [quantity.replace("x1", name, 1) for name in coordinates]
        else:
            out.append(quantity)
    return tuple(out)


def sweep_start_state(problem: ImpactProblem) -> NDArray[np.float64] | None:
    """(x, x') at t = 0 of the linear steady response (no stops) to the sweep's load at its start frequency,
    q sin(2 pi f0 t) distributed as the sweep says, plus the static deflection under its constant load
    (:func:`vibroimpact.simulation.harmonics.linear_state`); None (start at rest) where that motion would reach a stop.

    Parameters
    ----------
    problem : ImpactProblem
        The structure, its stops and the :class:`~vibroimpact.model.excitation.SweptSine` excitation.
    """
    sweep = problem.sweep
    # sin(theta) = cos(theta - pi / 2): the harmonic load at the start frequency, a quarter period late
    start = HarmonicForce(sweep.amplitude, sweep.start_frequency, phase=-0.5 * np.pi, weights=sweep.weights, static=sweep.static)
    harmonic = ImpactProblem(problem.system, problem.contact, start)
    linear = linear_state(harmonic)
    if not linear.fits(harmonic):
        return None
    return linear.state(harmonic.omega)


def sweep_estimates(record: SweepRecord, sweep: SweptSine, frequencies: tuple[float, ...], times: NDArray[np.float64], cycles: int) -> dict[str, NDArray[np.generic]]:
    """What a swept run measured: each of :func:`sweep_quantities` over windows of ``cycles`` cycles centred where
    the instantaneous frequency of ``sweep`` equals each of ``frequencies`` [Hz] (NaN outside the sweep or its
    windows), the same prefixed ``running_`` on the time grid ``times`` [s], and the time axes ``time`` [s] and
    ``instantaneous_frequency`` [Hz]. Per-stop quantities have a leading axis of one entry per stop."""
    grid = np.asarray(frequencies, dtype=float)
    with np.errstate(invalid="ignore"):
        at_frequency = (grid - sweep.start_frequency) / sweep.alpha
    inside = (at_frequency >= 0.0) & (at_frequency <= sweep.duration)
    centres = np.where(inside, at_frequency, np.nan)
    on_grid = running_quantities(record, centres, cycles)
    on_times = running_quantities(record, times, cycles)
    names = sweep_quantities(record.coordinates)
    out: dict[str, NDArray[np.generic]] = {name: on_grid[name] for name in names}
    out |= {f"running_{name}": on_times[name] for name in names}
    out["time"] = times
    out["instantaneous_frequency"] = sweep.frequency(times)
    return out


def running_quantities(record: SweepRecord, centres: NDArray[np.float64], cycles: int) -> dict[str, NDArray[np.float64]]:
    """The paper's running estimates of a sweep over windows of ``cycles`` cycles centred on ``centres`` [s].

    Fundamentals |x| are ``|integral x exp(-j theta) d theta| / (pi cycles)``; RMS over the window's duration;
    impulse (per stop) and impacts (all stops) per excitation period; peak force and deceleration per stop over the
    window's contacts of that stop (0 without contact). The force on the base is the springs' and dashpots' plus
    (1^T n_k) times each stop's force (a relative stop's cancels). NaN where the window leaves the run (or the
    centre is NaN). Per-stop values have a leading axis of one entry per stop.
    """
    sweep: SweptSine = record.sweep
    t = record.time
    problem = record.trajectory.problem
    weights = base_weights(problem)  # 1^T n_k: +1 upper, -1 lower absolute stop, 0 relative
    rotor = np.exp(-1j * sweep.phase(t)) * (2.0 * np.pi * sweep.frequency(t))  # exp(-j theta) d theta / dt
    suspension = record.base_force - record.contact_forces @ weights
    span = np.pi * cycles
    motions = [running_fundamental(t, record.displacements[:, i], sweep, cycles, centres) for i in range(problem.size)]
    safe = np.nan_to_num(centres, nan=t[0])
    start, end = window_times(sweep, safe, cycles)
    valid = np.isfinite(motions[0].amplitude)
    contact = sum(weight * running_at(t, record.contact_fourier[:, k], sweep, centres, cycles) for k, weight in enumerate(weights) if weight != 0.0)
    suspension_fourier = running_at(t, cumulative_trapezoid(suspension * rotor, t, initial=0.0), sweep, centres, cycles)
    trajectory = record.trajectory
    nan = np.where(valid, 1.0, np.nan)
    count = len(problem.stops)
    impulse, peak_force, peak_acceleration = np.zeros((count, *centres.shape)), np.zeros((count, *centres.shape)), np.zeros((count, *centres.shape))
    impacts = np.zeros(centres.shape, dtype=np.int64)
    complete = trajectory.contact_peaks.shape[0] == trajectory.impact_times.size
    for k in range(count):
        mine = trajectory.impact_stops == k  # one stop's contacts never overlap: their onsets are in order
        onsets = trajectory.impact_times[mine]
        first = np.searchsorted(onsets, np.where(valid, start, t[0]))
        last = np.searchsorted(onsets, np.where(valid, end, t[0]))
        impacts += last - first
        impulses = np.concatenate([[0.0], np.cumsum(trajectory.impulses[mine])])
        impulse[k] = (impulses[last] - impulses[first]) / cycles * nan
        peaks = trajectory.contact_peaks[trajectory.contact_peak_stops == k] if complete else np.full((onsets.size, 2), np.nan)
        for i in np.flatnonzero(valid & (last > first)):
            peak_force[k, i], peak_acceleration[k, i] = peaks[first[i] : last[i]].max(axis=0)
    out = {
        "force_amplitude": np.abs(suspension_fourier + contact) / span,
        "suspension_force_amplitude": np.abs(suspension_fourier) / span,
        "impulse": impulse,
        "impacts_per_period": impacts / cycles * nan,
        "peak_acceleration": peak_acceleration * nan,
        "peak_contact_force": peak_force * nan,
    }
    for name, motion in zip(record.coordinates, motions):
        out[f"{name}_amplitude"] = motion.amplitude
        out[f"{name}_rms"] = motion.rms
    return out
