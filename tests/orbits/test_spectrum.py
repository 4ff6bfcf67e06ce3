"""Rotation number and spectral lines of strobe sequences: quasi-periodic signals on a 2-torus with a known rotation,
circle maps whose rotation is known from their own lift, periodic orbits, the Henon attractor and noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.orbits.motion import rotation_number, strobe_spectrum

GOLDEN = (3.0 - math.sqrt(5.0)) / 2.0  # 0.381966..., the most irrational rotation in (0, 1/2)


def torus_strobes(rho: float, n: int = 2000, theta0: float = 0.3) -> np.ndarray:
    """Strobes x_k = g(theta0 + 2 pi k rho) of a two-frequency motion: a smooth, non-circular, tilted closed curve
    in four dimensions with units of displacement [m] and velocity [m/s] (very different spreads)."""
    theta = theta0 + 2.0 * np.pi * rho * np.arange(n)
    c, s = np.cos(theta), np.sin(theta)
    return np.column_stack([1e-3 * (c + 0.2 * np.cos(2 * theta)), 2e-3 + 5e-4 * (s + 0.1 * c), 0.3 * (0.7 * s - 0.4 * c), 0.1 * (c * s + 1.5 * s)])


@pytest.mark.parametrize("rho", [GOLDEN, math.sqrt(2.0) - 1.0, 0.0317, 1.0 - GOLDEN, 0.4721])
def test_rotation_number_of_a_torus_signal_is_the_irrational_rotation(rho: float) -> None:
    """The estimate equals the rotation used (folded into [0, 1/2]) to O(1/n), and the order test says regular."""
    estimate = rotation_number(torus_strobes(rho))
    assert estimate.rotation_number == pytest.approx(min(rho, 1.0 - rho), abs=1e-3)
    assert estimate.regular and estimate.order_fraction > 0.999


def test_rotation_number_of_a_nonlinear_circle_map_equals_its_lift() -> None:
    """Arnold's circle map theta -> theta + 2 pi Omega + K sin(theta), K = 0.6 (a homeomorphism, non-uniform speed):
    the truth is the mean increment of its own lifted angle; the strobes are a curve around its centre with that
    angle, seen through a non-linear embedding."""
    omega, k, n = 0.2137, 0.6, 4000
    theta = np.empty(n)
    theta[0] = 1.0
    for i in range(n - 1):
        theta[i + 1] = theta[i] + 2.0 * np.pi * omega + k * np.sin(theta[i])
    truth = (theta[-1] - theta[0]) / (n - 1) / (2.0 * np.pi)
    strobes = np.column_stack([np.cos(theta) * (1.0 + 0.3 * np.sin(theta) ** 2), np.sin(theta), 0.2 * np.cos(theta) ** 3, 0.5 * np.sin(theta)])
    estimate = rotation_number(strobes)
    assert estimate.rotation_number == pytest.approx(min(truth, 1 - truth), abs=2e-3)
    assert estimate.regular


def test_a_periodic_orbit_rotates_by_a_rational_number() -> None:
    """Five points visited in the order k -> k + 2: rotation 2/5, order kept, a line spectrum at multiples of 1/5."""
    strobes = torus_strobes(0.4, n=500)
    estimate = rotation_number(strobes)
    assert estimate.rotation_number == pytest.approx(0.4, abs=1.0 / 500)  # mean over 499 unequal increments: O(1/n)
    assert estimate.regular
    spectrum = strobe_spectrum(strobes)
    assert spectrum.line_fraction > 0.999
    assert np.min(np.abs(spectrum.peak_frequencies[0] - np.array([0.2, 0.4]))) < 1.0 / 500


def test_a_chaotic_attractor_has_no_rotation_and_a_broadband_spectrum() -> None:
    x, y, points = 0.1, 0.1, []
    for k in range(5000):
        x, y = 1.0 - 1.4 * x * x + y, 0.3 * x
        if k >= 1000:
            points.append((x, y))
    strobes = np.array(points)
    estimate = rotation_number(strobes)
    assert not estimate.regular and estimate.order_fraction < 0.05
    assert strobe_spectrum(strobes).line_fraction < 0.2


def test_the_line_fraction_of_a_tone_noise_and_a_constant() -> None:
    """A pure tone at any frequency, on or between bins: all but ~1e-4 of its power in its line (Hann leakage).
    White noise: the lines hold only their share of the bins. A constant (period-one orbit): a single line."""
    k = np.arange(1000)
    for frequency in (0.1234567, 0.25, 0.4999):
        tone = strobe_spectrum(np.cos(2.0 * np.pi * frequency * k + 0.4)[:, None])
        assert tone.line_fraction > 0.9995
        assert tone.peak_frequencies[0] == pytest.approx(frequency, abs=1.0 / 1000)
    noise = strobe_spectrum(np.random.default_rng(5).standard_normal((1000, 4)))
    share = 5 * 7 / 501  # five lines of seven bins among 501
    assert noise.line_fraction < 3.0 * share
    constant = strobe_spectrum(np.tile([1e-3, 3e-3, 0.0, 0.0], (100, 1)))
    assert constant.line_fraction == 1.0  # exact: the constant sequence's defined value
    assert rotation_number(np.tile([1e-3, 3e-3, 0.0, 0.0], (100, 1))).regular


def test_the_spectrum_of_a_quasi_periodic_signal_is_a_few_lines_at_multiples_of_its_rotation() -> None:
    spectrum = strobe_spectrum(torus_strobes(GOLDEN, n=2048))
    assert spectrum.line_fraction > 0.999
    harmonics = np.abs(((np.arange(1, 4)[:, None] * GOLDEN + 0.5) % 1.0) - 0.5)  # |m rho| folded into [0, 1/2]
    assert np.min(np.abs(spectrum.peak_frequencies[0] - harmonics)) < 1.0 / 2048
    assert spectrum.frequencies[-1] == pytest.approx(0.5)


def test_bad_strobes_are_refused() -> None:
    with pytest.raises(ValueError, match="n >= 8"):
        rotation_number(np.zeros((5, 4)))
    with pytest.raises(ValueError, match="non-finite"):
        strobe_spectrum(np.full((20, 4), np.inf))
    with pytest.raises(ValueError, match="component"):
        strobe_spectrum(np.zeros((20, 2)), component=2)
    with pytest.raises(ValueError, match="peaks"):
        strobe_spectrum(np.zeros((20, 2)), peaks=0)
