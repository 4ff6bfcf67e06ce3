"""Fundamental harmonics and RMS: ``measure`` over whole periods, the running estimators over a swept sine."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem
from vibroimpact.simulation.harmonics import measure, running_at, running_fundamental, window_times

from tests.conftest import PAPER_AMPLITUDE
from tests.engine_cases import linear_state, named, orbit_force, pgf_start

ENGINE = ExactEngine()


def rigid_stop_problem(system: TwoDofSystem, clearance: float, restitution: float, amplitude: float, frequency: float, phase: float = 0.0) -> ImpactProblem:
    """The one place this file builds a problem: force q cos(2 pi f t + phase), rigid stop at X2 = Delta."""
    return ImpactProblem(system, RigidStop(clearance, restitution), HarmonicForce(amplitude, frequency, phase))


# ------------------------------------------------------------------ measure: whole periods of a Trajectory


@pytest.mark.parametrize(("frequency", "phase"), [(23.0, 0.0), (30.0, 0.7), (45.0, -2.0)])
def test_far_clearance_measures_the_linear_receptance_solution(frequency: float, phase: float) -> None:
    """Clearance 1 m, started on the linear steady state: X1, X2 = q H e^{j phase}, RMS = |X| / sqrt 2, no contact."""
    problem = rigid_stop_problem(PAPER_SYSTEM, 1.0, 0.2, PAPER_AMPLITUDE, frequency, phase)
    trajectory = ENGINE.integrate(problem, linear_state(problem), 0.0, 6, moments=True)
    m = measure(trajectory)
    expected = paper_linear_response(PAPER_SYSTEM, omega=problem.omega, amplitude=PAPER_AMPLITUDE)
    rotation = np.exp(1j * phase)
    assert m.periods == 6
    np.testing.assert_allclose(m.x1, complex(expected.x1) * rotation, rtol=1e-10)
    np.testing.assert_allclose(m.x2, complex(expected.x2) * rotation, rtol=1e-10)
    np.testing.assert_allclose(m.suspension_force, complex(expected.force) * rotation, rtol=1e-10)
    assert m.x1_rms == pytest.approx(abs(expected.x1) / math.sqrt(2.0), rel=1e-10)
    assert m.x2_rms == pytest.approx(abs(expected.x2) / math.sqrt(2.0), rel=1e-10)
    assert m.impacts_per_period == 0.0 and m.impulse_per_period == 0.0 and m.mean_impulse == 0.0  # exact: no impact at all
    assert abs(m.contact_force) == 0.0  # exact: no contact, nothing is added to the contact moment
    assert m.peak_contact_force == 0.0 and m.peak_acceleration == 0.0  # exact: no contact gives 0, not NaN
    np.testing.assert_allclose(m.force, m.suspension_force, rtol=1e-15)


def test_measure_starts_its_fourier_clock_at_zero_not_at_the_trajectory_start() -> None:
    """A trajectory that starts at t0 = 3.3 T measures the same complex amplitudes (phases relative to cos(w t))."""
    problem = rigid_stop_problem(PAPER_SYSTEM, 1.0, 0.2, PAPER_AMPLITUDE, 30.0, 0.4)
    t0 = 3.3 * problem.period
    m = measure(ENGINE.integrate(problem, linear_state(problem, t0), t0, 4, moments=True))
    expected = paper_linear_response(PAPER_SYSTEM, omega=problem.omega, amplitude=PAPER_AMPLITUDE)
    np.testing.assert_allclose(m.x1, complex(expected.x1) * np.exp(0.4j), rtol=1e-10)


@pytest.mark.parametrize(("frequency", "restitution"), [(25.0, 0.2), (22.0, 0.0), (40.0, 0.2)])
def test_one_impact_orbit_measures_the_pgf_solution(frequency: float, restitution: float) -> None:
    """On a stable PGF orbit (impacts at t = k T): one impact and impulse J per period, the PGF harmonics and RMS.

    The stop's force is the impulse train J sum delta(t - k T), whose fundamental is 2 J / T, real.
    """
    problem, state, t0, orbit = pgf_start(frequency, restitution)
    m = measure(ENGINE.integrate(problem, state, t0, 10, moments=True))
    impulse = float(orbit.impulse[0])
    assert m.periods == 10
    assert m.impacts_per_period == 1.0  # exact: 10 impacts counted over 10 periods
    assert m.impulse_per_period == pytest.approx(impulse, rel=1e-10)
    assert m.mean_impulse == pytest.approx(impulse, rel=1e-10)
    np.testing.assert_allclose(m.contact_force, 2.0 * impulse * frequency, rtol=1e-10, atol=1e-10 * impulse * frequency)
    np.testing.assert_allclose(m.x1, orbit.harmonics()[0, 0], rtol=1e-9)
    np.testing.assert_allclose(m.x2, orbit.harmonics()[0, 1], rtol=1e-9)
    np.testing.assert_allclose(m.force, orbit_force(named(problem), orbit)[0], rtol=1e-9)
    x1_rms, x2_rms = orbit.rms()[0]  # Gauss-Legendre over the smooth open period: exact to round-off
    assert m.x1_rms == pytest.approx(x1_rms, rel=1e-9)
    assert m.x2_rms == pytest.approx(x2_rms, rel=1e-9)
    assert math.isnan(m.peak_contact_force) and math.isnan(m.peak_acceleration)  # a rigid stop has no finite peak


def test_measure_refuses_a_trajectory_without_moments_or_periods() -> None:
    problem = rigid_stop_problem(PAPER_SYSTEM, 1.0, 0.2, PAPER_AMPLITUDE, 30.0)
    start = linear_state(problem)
    with pytest.raises(ValueError, match="moments=True"):
        measure(ENGINE.integrate(problem, start, 0.0, 3, moments=False))
    with pytest.raises(ValueError, match="at least one period"):
        measure(ENGINE.integrate(problem, start, 0.0, 0, moments=True))


# ------------------------------------------------------------------ running estimators over a swept sine

SWEEP_UP = SweptSine(amplitude=10.0, start_frequency=10.0, stop_frequency=30.0, rate=4.0)
SWEEP_DOWN = SweptSine(amplitude=10.0, start_frequency=30.0, stop_frequency=10.0, rate=4.0)


def sample_times(sweep: SweptSine, per_cycle: int = 200) -> np.ndarray:
    """Uniform samples over the whole sweep, ``per_cycle`` per cycle at its highest frequency."""
    highest = max(sweep.start_frequency, sweep.stop_frequency)
    return np.linspace(0.0, sweep.duration, int(sweep.duration * highest * per_cycle) + 1)


def harmonic_signal(theta: np.ndarray, a: float) -> np.ndarray:
    """a sin(theta + 0.3) plus a third harmonic of the sweep's phase and an offset (both larger than a)."""
    return a * np.sin(theta + 0.3) + 4e-3 * np.sin(3.0 * theta - 1.0) + 1e-2


@pytest.mark.parametrize("sweep", [SWEEP_UP, SWEEP_DOWN], ids=["up", "down"])
@pytest.mark.parametrize("cycles", [1, 8])
def test_running_fundamental_recovers_the_amplitude_of_the_sweeps_own_harmonic(sweep: SweptSine, cycles: int) -> None:
    """x = a sin(theta + phi) + b sin(3 theta) + c: the windowed estimate is a, however fast the sweep.

    Harmonics and offset cancel exactly over whole cycles of theta; what is left is the trapezoidal sum's error,
    second order in the step: doubling the samples divides it by about 4 (a bias of the method would not shrink).
    """
    a = 2.5e-3
    errors = []
    for per_cycle in (200, 400):
        t = sample_times(sweep, per_cycle)
        theta = sweep.phase(t)
        estimate = running_fundamental(t, harmonic_signal(theta, a), sweep, cycles=cycles)
        assert estimate.amplitude.size == np.count_nonzero(theta - theta[0] >= 2.0 * np.pi * cycles)
        errors.append(float(np.max(np.abs(estimate.amplitude / a - 1.0))))
    assert errors[1] < 1e-4
    assert 3.0 < errors[0] / errors[1] < 5.0


@pytest.mark.parametrize("sweep", [SWEEP_UP, SWEEP_DOWN], ids=["up", "down"])
@pytest.mark.parametrize("cycles", [1, 8])
def test_running_rms_of_a_pure_sine_is_amplitude_over_root_two(sweep: SweptSine, cycles: int) -> None:
    """RMS over whole cycles of a sin(theta) is a / sqrt 2, to the sweep's change of frequency within the window.

    The mean of sin^2 over whole cycles of theta but uniform in t differs from 1/2 by the end terms of
    integral cos(2 theta) / theta' d theta: relatively at most about |alpha| / (8 pi f^2) on the RMS, f the window's
    lowest frequency (first order in |alpha| / f^2; 1.6e-3 at 10 Hz and 4 Hz/s, allowed 25 % over).
    """
    t = sample_times(sweep)
    estimate = running_fundamental(t, 3.0 * np.sin(sweep.phase(t)), sweep, cycles=cycles)
    start, end = window_times(sweep, estimate.time, cycles)
    lowest = np.minimum(sweep.frequency(start), sweep.frequency(end))
    error = np.abs(estimate.rms / (3.0 / math.sqrt(2.0)) - 1.0)
    assert bool(np.all(error <= 1.25 * sweep.rate / (8.0 * np.pi * lowest**2)))
    assert error.max() > 1e-4  # the bound is not loose by orders of magnitude: the effect is there and measured


def test_running_fundamental_follows_a_changing_amplitude() -> None:
    """An amplitude that jumps from 1 to 2 halfway: windows wholly before read 1, wholly after read 2."""
    t = sample_times(SWEEP_UP)
    jump = SWEEP_UP.duration / 2.0
    x = np.where(t < jump, 1.0, 2.0) * np.sin(SWEEP_UP.phase(t))
    estimate = running_fundamental(t, x, SWEEP_UP, cycles=4)
    start, end = window_times(SWEEP_UP, estimate.time, 4)
    np.testing.assert_allclose(estimate.amplitude[end < jump], 1.0, rtol=2e-4)
    np.testing.assert_allclose(estimate.amplitude[start > jump], 2.0, rtol=2e-4)


@pytest.mark.parametrize("sweep", [SWEEP_UP, SWEEP_DOWN], ids=["up", "down"])
def test_windows_span_whole_cycles_centred_in_phase(sweep: SweptSine) -> None:
    """Each window spans exactly ``cycles`` cycles of theta, its centre half-way in phase, inside the samples."""
    t = sample_times(sweep, per_cycle=20)
    cycles = 5
    estimate = running_fundamental(t, np.sin(sweep.phase(t)), sweep, cycles=cycles)
    start, end = window_times(sweep, estimate.time, cycles)
    np.testing.assert_allclose(sweep.phase(end) - sweep.phase(start), 2.0 * np.pi * cycles, rtol=1e-10)
    np.testing.assert_allclose(sweep.phase(estimate.time) - sweep.phase(start), np.pi * cycles, rtol=1e-10)
    # by default one window ends at each sample from the first where a whole window fits
    first = int(np.argmax(sweep.phase(t) - sweep.phase(t[0]) >= 2.0 * np.pi * cycles))
    np.testing.assert_allclose(end, t[first:], rtol=1e-10, atol=1e-12)
    assert start.min() >= t[0] - 1e-12 and bool(np.all(np.diff(estimate.time) > 0.0))


def test_running_at_is_the_increase_of_a_cumulative_integral_over_each_window() -> None:
    """A cumulative 3 t + 1 (linear: interpolation is exact) rises by 3 (end - start); NaN where the window leaves."""
    t = sample_times(SWEEP_UP, per_cycle=20)
    cycles = 2
    centres = np.array([0.01, 1.0, 2.5, 4.9, SWEEP_UP.duration])
    start, end = window_times(SWEEP_UP, centres, cycles)
    increase = running_at(t, 3.0 * t + 1.0, SWEEP_UP, centres, cycles)
    inside = (start >= t[0]) & (end <= t[-1])
    assert inside.tolist() == [False, True, True, True, False]
    np.testing.assert_allclose(increase[inside], 3.0 * (end - start)[inside], rtol=1e-12)
    assert bool(np.all(np.isnan(increase[~inside])))


def test_running_at_agrees_with_running_fundamental() -> None:
    """The fundamental is |increase of the cumulative integral of x e^{-j theta} theta'| / (pi cycles) over each window."""
    t = sample_times(SWEEP_UP)
    theta = SWEEP_UP.phase(t)
    x = 0.7 * np.cos(theta) + 0.2 * np.sin(2.0 * theta)
    cycles = 6
    centres = np.linspace(0.5, 4.5, 9)
    estimate = running_fundamental(t, x, SWEEP_UP, cycles=cycles, centres=centres)
    rotor = np.exp(-1j * theta) * 2.0 * np.pi * SWEEP_UP.frequency(t)
    fourier = running_at(t, cumulative_trapezoid(x * rotor, t, initial=0.0), SWEEP_UP, centres, cycles)
    np.testing.assert_allclose(estimate.amplitude, np.abs(fourier) / (np.pi * cycles), rtol=1e-12)
    np.testing.assert_allclose(estimate.amplitude, 0.7, rtol=2e-4)
    np.testing.assert_allclose(estimate.time, centres, rtol=1e-15)


def test_running_fundamental_at_given_centres_matches_the_default_windows() -> None:
    """Windows asked for at some of the default centres give the default estimates there; outside, NaN."""
    t = sample_times(SWEEP_UP)
    x = np.sin(SWEEP_UP.phase(t) + 1.0)
    default = running_fundamental(t, x, SWEEP_UP, cycles=3)
    chosen = default.time[::997]
    asked = running_fundamental(t, x, SWEEP_UP, cycles=3, centres=np.append(chosen, 1e-3))
    np.testing.assert_allclose(asked.amplitude[:-1], default.amplitude[::997], rtol=1e-9)
    np.testing.assert_allclose(asked.rms[:-1], default.rms[::997], rtol=1e-9)
    assert math.isnan(asked.amplitude[-1]) and math.isnan(asked.rms[-1])


def test_running_fundamental_needs_a_whole_cycle() -> None:
    t = sample_times(SWEEP_UP, per_cycle=10)
    with pytest.raises(ValueError, match="cycles"):
        running_fundamental(t, np.sin(SWEEP_UP.phase(t)), SWEEP_UP, cycles=0)
