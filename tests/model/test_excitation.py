"""Swept sine and the running fundamental-harmonic / RMS estimators."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.simulation.harmonics import running_fundamental


def test_sweep_frequency_is_the_derivative_of_its_phase() -> None:
    sweep = SweptSine(amplitude=10.0, start_frequency=15.0, stop_frequency=45.0, rate=0.1)
    assert sweep.duration == pytest.approx(300.0) and sweep.alpha == 0.1  # exact: input passed through
    t = np.linspace(0.0, sweep.duration, 10001)
    numeric = np.gradient(sweep.phase(t), t, edge_order=2) / (2 * math.pi)
    np.testing.assert_allclose(numeric, sweep.frequency(t), rtol=1e-9)
    assert sweep.frequency(sweep.duration) == pytest.approx(45.0)


def test_paper_literal_sweep_doubles_the_frequency() -> None:
    """Erratum evidence: sin(w(t) t) with w = 2 pi alpha t has instantaneous frequency 2 alpha t, not alpha t."""
    alpha, t = 0.1, np.linspace(100.0, 200.0, 10001)
    literal = 2 * math.pi * alpha * t * t
    np.testing.assert_allclose(np.gradient(literal, t, edge_order=2) / (2 * math.pi), 2 * alpha * t, rtol=1e-9)


def test_sweep_down() -> None:
    sweep = SweptSine(amplitude=1.0, start_frequency=45.0, stop_frequency=15.0, rate=0.1)
    assert sweep.alpha == -0.1 and sweep.frequency(sweep.duration) == pytest.approx(15.0)  # exact: input negated


@pytest.mark.parametrize(("start", "stop", "rate"), [(15.0, 45.0, 0.1), (45.0, 15.0, 0.1), (15.0, 45.0, 5.0)])
def test_running_estimator_returns_the_exact_amplitude_of_a_chirp(start: float, stop: float, rate: float) -> None:
    """x = A sin(theta + phi) + offset + a third harmonic: the estimate is A to 1e-6, the offset and harmonic cancel."""
    sweep = SweptSine(amplitude=1.0, start_frequency=start, stop_frequency=stop, rate=rate)
    duration = min(sweep.duration, 20.0)
    t = np.linspace(0.0, duration, int(duration * max(start, stop) * 1200))  # trapezoid error ~ (2 pi / 1200)^2 / 12
    theta = sweep.phase(t)
    amplitude, phase = 2.5e-3, 0.7
    x = amplitude * np.sin(theta + phase) + 1e-3 + 0.3 * amplitude * np.sin(3 * theta - 0.2)
    estimate = running_fundamental(t, x, sweep, cycles=8)
    assert estimate.time.size > 0.9 * t.size
    np.testing.assert_allclose(estimate.amplitude, amplitude, rtol=1e-6)
    np.testing.assert_allclose(estimate.frequency, sweep.frequency(estimate.time))


def test_running_rms_of_a_chirp() -> None:
    sweep = SweptSine(amplitude=1.0, start_frequency=15.0, stop_frequency=45.0, rate=0.1)
    t = np.linspace(0.0, 20.0, 200001)
    estimate = running_fundamental(t, 2.0 * np.sin(sweep.phase(t)), sweep, cycles=8)
    np.testing.assert_allclose(estimate.rms, 2.0 / math.sqrt(2.0), rtol=1e-4)


def test_estimator_follows_a_changing_amplitude() -> None:
    """A slowly growing amplitude is tracked: the estimate is the envelope near the window's centre (to 5e-4:
    the average is weighted by phase, and the frequency changes across the window)."""
    sweep = SweptSine(amplitude=1.0, start_frequency=20.0, stop_frequency=30.0, rate=1.0)
    t = np.linspace(0.0, 10.0, 400001)
    envelope = 1.0 + 0.05 * t
    estimate = running_fundamental(t, envelope * np.sin(sweep.phase(t)), sweep, cycles=4)
    np.testing.assert_allclose(estimate.amplitude, 1.0 + 0.05 * estimate.time, rtol=5e-4)


def test_validation() -> None:
    with pytest.raises(ValueError, match="stop_frequency = 15.0 must differ from start_frequency"):
        SweptSine(amplitude=1.0, start_frequency=15.0, stop_frequency=15.0, rate=0.1)
    with pytest.raises(ValueError, match=r"rate = -0.1 is out of range: allowed \(0, inf\)"):
        SweptSine(amplitude=1.0, start_frequency=15.0, stop_frequency=45.0, rate=-0.1)
    with pytest.raises(ValueError, match="cycles = 0 is out of range"):
        sweep = SweptSine(amplitude=1.0, start_frequency=15.0, stop_frequency=45.0, rate=0.1)
        running_fundamental(np.linspace(0, 1, 100), np.zeros(100), sweep, cycles=0)
    assert HarmonicForce(2.0, 10.0).force(0.0) == 2.0  # exact: 2 cos(0)


@pytest.mark.parametrize(("start", "stop"), [(15.0, 45.0), (45.0, 15.0)])
def test_time_at_phase_inverts_the_phase(start: float, stop: float) -> None:
    sweep = SweptSine(amplitude=1.0, start_frequency=start, stop_frequency=stop, rate=0.1)
    t = np.linspace(0.0, sweep.duration, 1001)
    np.testing.assert_allclose(sweep.time_at_phase(sweep.phase(t)), t, rtol=1e-12, atol=1e-12)


def test_estimates_at_chosen_centres_are_exact_and_nan_outside() -> None:
    """Windows centred where the instantaneous frequency is 20, 25, 30 Hz (as a study reports them): exact A for a
    sine; NaN where the window would leave the record."""
    sweep = SweptSine(amplitude=1.0, start_frequency=19.5, stop_frequency=30.5, rate=1.0)
    t = np.linspace(0.0, sweep.duration, int(sweep.duration * 30.5 * 1200))
    amplitude = 1.5e-3
    x = amplitude * np.sin(sweep.phase(t) - 1.1)
    centres = (np.array([19.51, 20.0, 25.0, 30.0, 30.49]) - 19.5) / sweep.alpha
    estimate = running_fundamental(t, x, sweep, cycles=8, centres=centres)
    assert np.all(np.isnan(estimate.amplitude[[0, -1]]))  # half a window does not fit at either end
    np.testing.assert_allclose(estimate.amplitude[1:-1], amplitude, rtol=1e-6)
    np.testing.assert_allclose(estimate.rms[1:-1], amplitude / math.sqrt(2.0), rtol=1e-3)
    np.testing.assert_allclose(estimate.frequency[1:-1], [20.0, 25.0, 30.0])
