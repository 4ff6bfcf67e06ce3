"""Engine ``compliant`` (Kelvin-Voigt bumper through IDA): one collision, independent integration, stiff limit."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution, peak_acceleration_factor, restitution_from_loss_factor
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.engines.base import SweepRecord
from vibroimpact.engines.exact import ExactEngine

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.compliant.ida import CompliantEngine
from vibroimpact.engines.compliant.model import MODE_CONTACT
from vibroimpact.model.excitation import SweptSine
from vibroimpact.simulation.steady import steady_state
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE
from tests.engine_cases import named

TIGHT = EngineSettings(rtol=1e-11, atol=1e-15)
#: The absorber alone: no forcing and a negligible spring, so one collision is the textbook one.
FREE_ABSORBER = TwoDofSystem(m1=1.0, m2=0.1, k1=1.0, k2=1e-12)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("xi", [1e-4, 0.05, 0.3, 0.49, 0.7, 1.0, 1.5, 4.0])
def test_one_collision_restitution_impulse_and_peak(xi: float) -> None:
    """IDA reproduces R(xi), the impulse M2 v0 (1 + R) and the peak deceleration Gamma(xi) Omega v0 to 1e-8."""
    problem = ImpactProblem(FREE_ABSORBER, KelvinVoigtBumper(1e-3, 250.0, xi), HarmonicForce(0.0, 1.0))
    v0, omega_b = 0.5, 2 * math.pi * 250.0
    trajectory = CompliantEngine(TIGHT).integrate(problem, np.array([0.0, 1e-3, 0.0, v0]), 0.0, 1)
    restitution = restitution_from_loss_factor(xi)
    assert trajectory.impulses.size == 1
    assert -trajectory.strobe_states[-1, 3] / v0 == pytest.approx(restitution, rel=1e-8)
    assert trajectory.impulses[0] == pytest.approx(FREE_ABSORBER.m2 * v0 * (1 + restitution), rel=1e-8)
    assert trajectory.contact_peaks[0, 1] == pytest.approx(peak_acceleration_factor(xi) * omega_b * v0, rel=1e-8)


def _reference(problem: ImpactProblem, frequency: float, xi: float, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """The same model integrated independently: solve_ivp (DOP853) with onset and release events, from rest."""
    s = named(problem)
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
    xi = loss_factor_from_restitution(0.2)
    problem = ImpactProblem(system, KelvinVoigtBumper(PAPER_CLEARANCE, 250.0, xi), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    trajectory = CompliantEngine(TIGHT).integrate(problem, np.zeros(4), 0.0, 15)
    onsets, final = _reference(problem, 250.0, xi, 15 / 25.0)
    assert trajectory.impact_times.size == onsets.size >= 10
    np.testing.assert_allclose(trajectory.impact_times, onsets, atol=1e-9)
    np.testing.assert_allclose(trajectory.final_state, final, atol=1e-7 * np.abs(final).max())
    assert np.all(trajectory.segments[trajectory.segments[:, 2] == MODE_CONTACT, 1] > trajectory.segments[trajectory.segments[:, 2] == MODE_CONTACT, 0])


@pytest.mark.timeout(120)
def test_stiffening_bumper_converges_to_momentary_impact(system: TwoDofSystem) -> None:
    """Stated rate: the steady-state |X1| approaches the momentary-impact value (same R) like 1 / Omega_b: each 4x
    stiffer bumper divides the error by about 4 (9.4 %, 2.4 %, 0.6 % at 250, 1000, 4000 Hz at 25 Hz, R = 0.2)."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    reference = steady_state(ExactEngine(), problem, "pgf", SteadySettings(tolerance=1e-10)).measures
    xi = loss_factor_from_restitution(0.2)
    errors = []
    for frequency in (250.0, 1000.0, 4000.0):
        bumper = replace(problem, contact=KelvinVoigtBumper(PAPER_CLEARANCE, frequency, xi))
        result = steady_state(CompliantEngine(EngineSettings(rtol=1e-9, atol=1e-13)), bumper, "pgf", SteadySettings(tolerance=1e-9), problem.rigid_stop)
        assert result.converged and result.measures.impacts_per_period == 1.0  # exact: a count per period
        errors.append(abs(abs(result.measures.x1) - abs(reference.x1)) / abs(reference.x1))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.5) & (ratios < 4.5)), (errors, ratios)
    assert errors[-1] < 0.01


@pytest.mark.timeout(60)
@pytest.mark.parametrize(("frequency", "xi"), [(10_000.0, 0.73), (250.0, 1e-4), (250.0, 2.0)])
def test_hard_bumpers(system: TwoDofSystem, frequency: float, xi: float) -> None:
    """Very stiff, nearly elastic and overdamped bumpers: no failure; every contact that began also released (an
    impact is recorded at release), with a finite positive peak force and impulse."""
    problem = ImpactProblem(system, KelvinVoigtBumper(PAPER_CLEARANCE, frequency, xi), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    trajectory = CompliantEngine().integrate(problem, np.zeros(4), 0.0, 20)
    assert trajectory.impact_times.size >= 10
    assert trajectory.stats["contacts"] - trajectory.impact_times.size in (0, 1)
    assert np.all(np.isfinite(trajectory.strobe_states))
    assert np.all((trajectory.contact_peaks > 0.0) & np.isfinite(trajectory.contact_peaks))
    assert np.all(trajectory.impulses > 0.0)


@pytest.mark.timeout(60)
def test_slow_sweep_without_contact_follows_the_linear_response(system: TwoDofSystem) -> None:
    """Swept sine 15 -> 17 Hz at 0.2 Hz/s, clearance far away, started on the linear steady state: the running
    fundamental of X1 is |q H11| at the window's frequency to 1e-3 (sweep lag and sampling included)."""
    from vibroimpact.model.excitation import SweptSine
    from vibroimpact.simulation.harmonics import running_fundamental
    from vibroimpact.analysis.linear import paper_linear_response

    sweep = SweptSine(PAPER_AMPLITUDE, 15.0, 17.0, 0.2)
    h = paper_linear_response(system, omega=2 * math.pi * 15.0, amplitude=PAPER_AMPLITUDE)
    x = np.array([h.x1, h.x2]) * -1j  # the response to q sin(theta) at theta = 0
    state = np.concatenate([x.real, (2j * math.pi * 15.0 * x).real])
    record = CompliantEngine().sweep(ImpactProblem(system, KelvinVoigtBumper(1.0, 250.0, 0.73), sweep), 2000.0, state)
    assert record.trajectory.impact_times.size == 0 and np.all(record.contact_forces[:, 0] == 0.0)  # exact: no contact: force set to 0
    estimate = running_fundamental(record.time, record.displacement("x1"), sweep, cycles=8)
    linear = np.abs(paper_linear_response(system, omega=2 * math.pi * estimate.frequency, amplitude=PAPER_AMPLITUDE).x1)
    np.testing.assert_allclose(estimate.amplitude, linear, rtol=1e-3)


@pytest.mark.timeout(60)
def test_slow_sweep_with_contact_follows_the_one_impact_orbit(system: TwoDofSystem) -> None:
    """Swept sine 24 -> 25 Hz at 0.1 Hz/s through stable one-impact orbits (R = 0.2, stiff 4 kHz bumper), from rest:
    after the 5 s transient the running fundamental of X1 is the PGF value to 1.5 % (0.6 % is the bumper's)."""
    from vibroimpact.model.excitation import SweptSine
    from vibroimpact.simulation.harmonics import running_fundamental
    from vibroimpact.analysis.pgf import solve_one_impact

    sweep = SweptSine(PAPER_AMPLITUDE, 24.0, 25.0, 0.1)
    record = CompliantEngine().sweep(ImpactProblem(system, KelvinVoigtBumper(PAPER_CLEARANCE, 4000.0, loss_factor_from_restitution(0.2)), sweep), 2000.0)
    estimate = running_fundamental(record.time, record.displacement("x1"), sweep, cycles=8)
    settled = estimate.time > 5.0
    orbit = solve_one_impact(system, omega=2 * math.pi * estimate.frequency[settled], clearance=PAPER_CLEARANCE, restitution=0.2, amplitude=PAPER_AMPLITUDE)
    np.testing.assert_allclose(estimate.amplitude[settled], np.abs(orbit.harmonics()[..., 0]), rtol=0.015)
    assert record.trajectory.impact_times.size == pytest.approx(sweep.duration * 24.5, rel=0.02)  # one contact per period


def _paper_sweep_record(settings: EngineSettings, start: float, stop: float, sample_rate: float = 1000.0) -> tuple[SweptSine, SweepRecord]:
    """The paper's swept-sine test (250 Hz bumper, R = 0.2) from ``start`` to ``stop`` Hz at 0.1 Hz/s."""
    sweep = SweptSine(PAPER_AMPLITUDE, start, stop, 0.1)
    bumper = KelvinVoigtBumper(PAPER_CLEARANCE, 250.0, loss_factor_from_restitution(0.2))
    return sweep, CompliantEngine(settings).sweep(ImpactProblem(PAPER_SYSTEM, bumper, sweep), sample_rate)


@pytest.mark.slow
@pytest.mark.timeout(60)
def test_sweep_settings_agree_with_a_tight_run() -> None:
    """The paper's sweep settings (rtol 1e-6, atol 1e-10 m) against rtol 1e-9 over a contact-rich 10 s (24 -> 25 Hz,
    one contact per period): same contacts, onsets to 1e-6 s, running X1 fundamental to 2e-5 of its largest value
    (measured 4e-6), peak force and deceleration and impulses to 2e-4 (measured ~3e-5)."""
    from vibroimpact.engines.settings import SWEEP_SETTINGS
    from vibroimpact.simulation.harmonics import running_fundamental

    sweep, record = _paper_sweep_record(SWEEP_SETTINGS, 24.0, 25.0)
    _, tight = _paper_sweep_record(EngineSettings(rtol=1e-9, atol=1e-13), 24.0, 25.0)
    a, b = record.trajectory, tight.trajectory
    assert a.impact_times.size == b.impact_times.size == a.stats["contacts"] == pytest.approx(sweep.duration * 24.5, rel=0.01)
    np.testing.assert_allclose(a.impact_times, b.impact_times, atol=1e-6)
    np.testing.assert_allclose(a.contact_peaks, b.contact_peaks, rtol=2e-4)
    np.testing.assert_allclose(a.impulses, b.impulses, rtol=2e-4)
    fundamental = running_fundamental(record.time, record.displacement("x1"), sweep, cycles=8).amplitude
    reference = running_fundamental(tight.time, tight.displacement("x1"), sweep, cycles=8).amplitude
    assert np.max(np.abs(fundamental - reference)) < 2e-5 * reference.max()
    np.testing.assert_allclose(record.contact_fourier[:, 0], tight.contact_fourier[:, 0], atol=1e-4 * np.abs(tight.contact_fourier[:, 0]).max())


@pytest.mark.slow
@pytest.mark.timeout(60)
def test_sweep_record_contacts_stats_and_force_quadrature() -> None:
    """Per contact: onset, peak force and deceleration (one row each, positive); counters; samples of the bumper
    force; and the Fourier integral of the force (integrated with the motion) against the trapezoidal rule on
    100 kHz samples (1e-2: the force jumps at each onset, which the samples only resolve to one step)."""
    from scipy.integrate import cumulative_trapezoid

    sweep, record = _paper_sweep_record(EngineSettings(rtol=1e-8, atol=1e-12), 24.0, 24.3, sample_rate=100_000.0)
    trajectory = record.trajectory
    assert trajectory.impact_times.size >= 60 and trajectory.contact_peaks.shape == (trajectory.impact_times.size, 2)
    assert np.all(trajectory.contact_peaks > 0.0) and np.all(np.diff(trajectory.impact_times) > 0.0)
    assert trajectory.stats["contacts"] - trajectory.impact_times.size in (0, 1)
    assert trajectory.stats["steps"] > 0 and trajectory.stats["rhs_calls"] >= trajectory.stats["steps"]
    assert np.all(record.contact_forces[:, 0] >= 0.0) and record.contact_forces[:, 0].max() <= trajectory.contact_peaks[:, 0].max() * (1 + 1e-6)
    assert record.contact_forces[:, 0].max() > 0.9 * trajectory.contact_peaks[:, 0].max()
    rotor = np.exp(-1j * sweep.phase(record.time)) * 2 * math.pi * sweep.frequency(record.time)
    sampled = cumulative_trapezoid(record.contact_forces[:, 0] * rotor, record.time, initial=0.0)
    np.testing.assert_allclose(record.contact_fourier[:, 0], sampled, atol=1e-2 * np.abs(sampled).max())


def test_sweep_clears_the_event_records() -> None:
    """scikit-sundae keeps every root on the event function (NOTES): the run must leave none behind, or each call
    gets slower over a long sweep."""
    from vibroimpact.engines.base import TrajectoryBuilder
    from vibroimpact.engines.compliant.ida import _Run
    from vibroimpact.engines.compliant.model import BumperModel

    sweep = SweptSine(PAPER_AMPLITUDE, 24.0, 24.5, 0.1)
    problem = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(PAPER_CLEARANCE, 250.0, 0.3), sweep)
    model = BumperModel(problem, False)
    engine = CompliantEngine()
    run = _Run(engine, model, TrajectoryBuilder(problem, False), 0.0, np.zeros(4), 2 * math.pi * 25.0)
    run.run(np.arange(0.0, sweep.duration, 1e-3), lambda t, y, contact: None)
    assert run.counts["contacts"] > 50
    for _, events in run.solvers.values():
        assert all(len(getattr(events, name)) == 0 for name in ("_i", "_t", "_y", "_yp"))


@pytest.mark.slow
@pytest.mark.timeout(300)
def test_sweep_memory_stays_flat() -> None:
    """Beyond its output, a sweep's memory grows only by its per-contact records: between a 5 s and a 20 s
    contact-rich sweep (22 -> 22.5 / 24 Hz, ~110 / ~460 contacts) the peak traced allocation minus the samples grows
    by less than 2 kB per added contact (measured ~1 kB: impact, peaks and two segment rows). Anything kept per
    step (~170 steps per contact) would exceed it many times over."""
    import tracemalloc

    def extra_memory(stop: float) -> tuple[float, int]:
        tracemalloc.start()
        try:
            _, record = _paper_sweep_record(EngineSettings(rtol=1e-6, atol=1e-10), 22.0, stop, sample_rate=500.0)
            _, peak = tracemalloc.get_traced_memory()
        finally:
            tracemalloc.stop()
        return peak - record.time.nbytes * 7, record.trajectory.impact_times.size

    (short, few), (long, many) = extra_memory(22.5), extra_memory(24.0)
    assert many > 3 * few > 300
    assert (long - short) / (many - few) < 2048, (short, long, few, many)


def _first_apex(system: TwoDofSystem, state: np.ndarray) -> tuple[float, float]:
    """Time and X2 of the first apex (X2' = 0) of the free motion from ``state`` (matrix exponential: exact)."""
    from scipy.linalg import expm
    from scipy.optimize import brentq

    a = system.state_matrix
    t = brentq(lambda t: (expm(a * t) @ state)[3], 1e-3, 0.012, xtol=1e-15)
    return t, float((expm(a * t) @ state)[1])


@pytest.mark.timeout(60)
@pytest.mark.parametrize("settings", [EngineSettings(rtol=1e-6, atol=1e-10), EngineSettings(rtol=1e-8, atol=1e-9)])
def test_near_tangent_touches(system: TwoDofSystem, settings: EngineSettings) -> None:
    """Free motion from X2 = 0 whose first apex (exact) passes the bumper by 1e-8 ... 1e-7 m (beyond it for
    3e-5 ... 1e-4 s): one contact each, starting before the apex; 1e-8 m short of it: none. (The gap is a state with
    an absolute tolerance, so the steps shrink as it nears zero and the onset event sees these touches.)"""
    state = np.array([0.0, 0.0, 0.0, 0.3])
    apex_time, apex = _first_apex(system, state)
    for overshoot in (1e-8, 3e-8, 1e-7, -1e-8, -1e-7):
        problem = ImpactProblem(system, KelvinVoigtBumper(apex - overshoot, 250.0, 0.3), HarmonicForce(0.0, 1.0 / (4 * apex_time)))  # one period: to the next apex
        trajectory = CompliantEngine(settings).integrate(problem, state, 0.0, 1)
        expected = 1 if overshoot > 0 else 0
        assert trajectory.stats["contacts"] == trajectory.impact_times.size == expected, overshoot
        if expected:
            assert apex_time - 2 * math.sqrt(2 * overshoot / 40.0) < trajectory.impact_times[0] < apex_time
            assert 0.0 < trajectory.contact_peaks[0, 0] < 0.5  # ~100 N in a real contact


@pytest.mark.timeout(60)
def test_apex_check_catches_what_the_onset_event_misses(system: TwoDofSystem, monkeypatch: pytest.MonkeyPatch) -> None:
    """With the onset event switched off, the apex check alone finds a touch 1e-8 m deep: the contact starts at the
    apex (flagged as grazing), the outputs integrated past it are redone, and the period ends as with the onset
    event but for the touch itself (it starts 14 us later, at rest instead of at 1 mm/s: the final states differ by
    ~2e-5 of the largest state value)."""
    from vibroimpact.engines.compliant import model as compliant

    state = np.array([0.0, 0.0, 0.0, 0.3])
    apex_time, apex = _first_apex(system, state)
    problem = ImpactProblem(system, KelvinVoigtBumper(apex - 1e-8, 250.0, 0.3), HarmonicForce(0.0, 1.0 / (4 * apex_time)))
    engine = CompliantEngine(EngineSettings(rtol=1e-8, atol=1e-12))
    normal = engine.integrate(problem, state, 0.0, 2)
    events = compliant.BumperModel.events

    def without_onset(model: compliant.BumperModel, contact: bool):  # type: ignore[no-untyped-def]
        function = events(model, contact)
        if contact:
            return function

        def blind(t: float, y: np.ndarray, yp: np.ndarray, out: np.ndarray) -> None:
            function(t, y, yp, out)
            out[0] = -1.0

        blind.terminal, blind.direction = function.terminal, function.direction  # type: ignore[attr-defined]
        return blind

    monkeypatch.setattr(compliant.BumperModel, "events", without_onset)
    blind = engine.integrate(problem, state, 0.0, 2)
    assert blind.stats["grazing"] == blind.stats["contacts"] == blind.impact_times.size == normal.impact_times.size == 1
    assert blind.impact_times[0] == pytest.approx(apex_time, rel=1e-8)
    np.testing.assert_allclose(blind.strobe_times, normal.strobe_times, rtol=1e-15)
    np.testing.assert_allclose(blind.strobe_states, normal.strobe_states, atol=1e-4 * np.abs(normal.strobe_states).max())


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_paper_sweep_is_fast_and_close_to_a_tight_run() -> None:
    """The paper's 300 s sweep (15 -> 45 Hz) with :data:`SWEEP_SETTINGS` (~10 s measured, see ``sweep_cost``; the
    timeout catches a hang), and over the contact-rich, reproducible 21 -> 24 Hz (60 - 90 s) the same contacts and
    running X1 fundamental as rtol 1e-9 to 1e-4 of its largest value."""

    from vibroimpact.engines.settings import SWEEP_SETTINGS
    from vibroimpact.simulation.harmonics import running_fundamental

    sweep, record = _paper_sweep_record(SWEEP_SETTINGS, 15.0, 45.0)  # the timeout bounds it; speed is benchmarked
    _, tight = _paper_sweep_record(EngineSettings(rtol=1e-9, atol=1e-13), 15.0, 45.0)
    onsets = [r.trajectory.impact_times[(r.trajectory.impact_times >= 60.0) & (r.trajectory.impact_times < 90.0)] for r in (record, tight)]
    assert onsets[0].size == onsets[1].size > 600
    np.testing.assert_allclose(onsets[0], onsets[1], atol=1e-5)
    a = running_fundamental(record.time, record.displacement("x1"), sweep, cycles=8)
    b = running_fundamental(tight.time, tight.displacement("x1"), sweep, cycles=8)
    window = (a.time >= 60.0) & (a.time < 90.0)
    assert np.max(np.abs(a.amplitude[window] - b.amplitude[window])) < 1e-4 * b.amplitude[window].max()
