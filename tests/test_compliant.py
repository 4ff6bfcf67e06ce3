"""Engine ``compliant`` (Kelvin-Voigt bumper through IDA): one collision, independent integration, stiff limit."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vibroimpact.contact import loss_factor_from_restitution, peak_acceleration_factor, restitution_from_loss_factor
from vibroimpact.engines import EngineSettings, ExactEngine, ImpactProblem
from vibroimpact.engines.compliant import MODE_CONTACT, CompliantEngine
from vibroimpact.steady import SteadySettings, steady_state
from vibroimpact.system import TwoDofSystem

from .conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

TIGHT = EngineSettings(rtol=1e-11, atol=1e-15)
#: The absorber alone: no forcing and a negligible spring, so one collision is the textbook one.
FREE_ABSORBER = TwoDofSystem(m1=1.0, m2=0.1, k1=1.0, k2=1e-12)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("xi", [1e-4, 0.05, 0.3, 0.49, 0.7, 1.0, 1.5, 4.0])
def test_one_collision_restitution_impulse_and_peak(xi: float) -> None:
    """IDA reproduces R(xi), the impulse M2 v0 (1 + R) and the peak deceleration Gamma(xi) Omega v0 to 1e-8."""
    problem = ImpactProblem(FREE_ABSORBER, 1e-3, 0.5, 0.0, 1.0)
    v0, omega_b = 0.5, 2 * math.pi * 250.0
    trajectory = CompliantEngine(250.0, xi, TIGHT).integrate(problem, np.array([0.0, 1e-3, 0.0, v0]), 0.0, 1)
    restitution = restitution_from_loss_factor(xi)
    assert trajectory.impulses.size == 1
    assert -trajectory.strobe_states[-1, 3] / v0 == pytest.approx(restitution, rel=1e-8)
    assert trajectory.impulses[0] == pytest.approx(FREE_ABSORBER.m2 * v0 * (1 + restitution), rel=1e-8)
    assert trajectory.contact_peaks[0, 1] == pytest.approx(peak_acceleration_factor(xi) * omega_b * v0, rel=1e-8)


def _reference(problem: ImpactProblem, frequency: float, xi: float, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """The same model integrated independently: solve_ivp (DOP853) with onset and release events, from rest."""
    s = problem.system
    k, b = s.m2 * (2 * math.pi * frequency) ** 2, 2 * s.m2 * xi * 2 * math.pi * frequency
    contact = False

    def rhs(t: float, y: np.ndarray) -> list[float]:
        x1, x2, v1, v2 = y
        spring = s.k2 * (x1 - x2) + s.b2 * (v1 - v2)
        bumper = k * (x2 - problem.clearance) + b * v2 if contact else 0.0
        return [v1, v2, (problem.amplitude * math.cos(problem.omega * t) - s.k1 * x1 - s.b1 * v1 - spring) / s.m1, (spring - bumper) / s.m2]

    def onset(t: float, y: np.ndarray) -> float:
        return y[1] - problem.clearance

    def release(t: float, y: np.ndarray) -> float:
        return k * (y[1] - problem.clearance) + b * y[3]

    onset.terminal, onset.direction = True, 1.0
    release.terminal, release.direction = True, -1.0
    t, y, onsets = 0.0, np.zeros(4), []
    while t < duration:
        run = solve_ivp(rhs, (t, duration), y, method="DOP853", rtol=1e-12, atol=1e-15, events=[release if contact else onset])
        t, y = run.t[-1], run.y[:, -1]
        if run.status == 1:
            if not contact:
                onsets.append(t)
            contact = not contact
    return np.array(onsets), y


@pytest.mark.timeout(120)
def test_agrees_with_an_independent_integration(system: TwoDofSystem) -> None:
    """IDA against DOP853 on the same compliant model, 0.6 s from rest at 25 Hz: contact onsets and final state."""
    problem = ImpactProblem(system, PAPER_CLEARANCE, 0.2, PAPER_AMPLITUDE, 25.0)
    xi = loss_factor_from_restitution(0.2)
    trajectory = CompliantEngine(250.0, xi, TIGHT).integrate(problem, np.zeros(4), 0.0, 15)
    onsets, final = _reference(problem, 250.0, xi, 15 / 25.0)
    assert trajectory.impact_times.size == onsets.size >= 10
    np.testing.assert_allclose(trajectory.impact_times, onsets, atol=1e-9)
    np.testing.assert_allclose(trajectory.final_state, final, atol=1e-7 * np.abs(final).max())
    assert np.all(trajectory.segments[trajectory.segments[:, 2] == MODE_CONTACT, 1] > trajectory.segments[trajectory.segments[:, 2] == MODE_CONTACT, 0])


@pytest.mark.timeout(120)
def test_stiffening_bumper_converges_to_momentary_impact(system: TwoDofSystem) -> None:
    """Stated rate: the steady-state |X1| approaches the momentary-impact value (same R) like 1 / Omega_b: each 4x
    stiffer bumper divides the error by about 4 (9.4 %, 2.4 %, 0.6 % at 250, 1000, 4000 Hz at 25 Hz, R = 0.2)."""
    problem = ImpactProblem(system, PAPER_CLEARANCE, 0.2, PAPER_AMPLITUDE, 25.0)
    reference = steady_state(ExactEngine(), problem, "pgf", SteadySettings(tolerance=1e-10)).measures
    xi = loss_factor_from_restitution(0.2)
    errors = []
    for frequency in (250.0, 1000.0, 4000.0):
        result = steady_state(CompliantEngine(frequency, xi, EngineSettings(rtol=1e-9, atol=1e-13)), problem, "pgf", SteadySettings(tolerance=1e-9))
        assert result.converged and result.measures.impacts_per_period == 1.0
        errors.append(abs(abs(result.measures.x1) - abs(reference.x1)) / abs(reference.x1))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.5) & (ratios < 4.5)), (errors, ratios)
    assert errors[-1] < 0.01


@pytest.mark.timeout(60)
@pytest.mark.parametrize(("frequency", "xi"), [(10_000.0, 0.73), (250.0, 1e-4), (250.0, 2.0)])
def test_hard_bumpers(system: TwoDofSystem, frequency: float, xi: float) -> None:
    """Very stiff, nearly elastic and overdamped bumpers: no failure; every contact that began also released (an
    impact is recorded at release), with a finite positive peak force and impulse."""
    problem = ImpactProblem(system, PAPER_CLEARANCE, 0.2, PAPER_AMPLITUDE, 25.0)
    trajectory = CompliantEngine(frequency, xi).integrate(problem, np.zeros(4), 0.0, 20)
    assert trajectory.impact_times.size >= 10
    assert trajectory.stats["contacts"] - trajectory.impact_times.size in (0, 1)
    assert np.all(np.isfinite(trajectory.strobe_states))
    assert np.all((trajectory.contact_peaks > 0.0) & np.isfinite(trajectory.contact_peaks))
    assert np.all(trajectory.impulses > 0.0)


@pytest.mark.timeout(60)
def test_slow_sweep_without_contact_follows_the_linear_response(system: TwoDofSystem) -> None:
    """Swept sine 15 -> 17 Hz at 0.2 Hz/s, clearance far away, started on the linear steady state: the running
    fundamental of X1 is |q H11| at the window's frequency to 1e-3 (sweep lag and sampling included)."""
    from vibroimpact.excitation import SweptSine
    from vibroimpact.harmonics import running_fundamental
    from vibroimpact.linear import linear_response

    sweep = SweptSine(PAPER_AMPLITUDE, 15.0, 17.0, 0.2)
    h = linear_response(system, 2 * math.pi * 15.0, PAPER_AMPLITUDE)
    x = np.array([h.x1, h.x2]) * -1j  # the response to q sin(theta) at theta = 0
    state = np.concatenate([x.real, (2j * math.pi * 15.0 * x).real])
    record = CompliantEngine(250.0, 0.73).sweep(system, 1.0, sweep, 2000.0, state)
    assert record.trajectory.impact_times.size == 0 and np.all(record.contact_force == 0.0)
    estimate = running_fundamental(record.time, record.x1, sweep, cycles=8)
    linear = np.abs(linear_response(system, 2 * math.pi * estimate.frequency, PAPER_AMPLITUDE).x1)
    np.testing.assert_allclose(estimate.amplitude, linear, rtol=1e-3)


@pytest.mark.timeout(60)
def test_slow_sweep_with_contact_follows_the_one_impact_orbit(system: TwoDofSystem) -> None:
    """Swept sine 24 -> 25 Hz at 0.1 Hz/s through stable one-impact orbits (R = 0.2, stiff 4 kHz bumper), from rest:
    after the 5 s transient the running fundamental of X1 is the PGF value to 1.5 % (0.6 % is the bumper's)."""
    from vibroimpact.excitation import SweptSine
    from vibroimpact.harmonics import running_fundamental
    from vibroimpact.pgf import solve_one_impact

    sweep = SweptSine(PAPER_AMPLITUDE, 24.0, 25.0, 0.1)
    record = CompliantEngine(4000.0, loss_factor_from_restitution(0.2)).sweep(system, PAPER_CLEARANCE, sweep, 2000.0)
    estimate = running_fundamental(record.time, record.x1, sweep, cycles=8)
    settled = estimate.time > 5.0
    orbit = solve_one_impact(system, 2 * math.pi * estimate.frequency[settled], PAPER_CLEARANCE, 0.2, PAPER_AMPLITUDE)
    np.testing.assert_allclose(estimate.amplitude[settled], np.abs(orbit.x1_harmonic()), rtol=0.015)
    assert record.trajectory.impact_times.size == pytest.approx(sweep.duration * 24.5, rel=0.02)  # one contact per period
