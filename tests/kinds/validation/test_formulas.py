"""The closed forms of the validation scenes against independent derivations: each impact map is written out here
from its flight (root-found next impact, finite-difference Jacobian), so a slip in the algebra of
:mod:`vibroimpact.kinds.validation.formulas` shows as a disagreement."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from vibroimpact.kinds.validation.formulas import (
    ball_existence,
    ball_multipliers,
    ball_period_doubling,
    ball_period_doubling_high_bounce,
    ball_phase,
    ball_state,
    budd_dux_constants,
    budd_dux_multipliers,
    budd_dux_period_doubling,
    budd_dux_phase,
    budd_dux_residual,
    budd_dux_state,
    budd_dux_velocities,
    grazing_amplitude,
    zeno_sticking_bounds,
    zeno_sticking_deficit,
    zeno_time,
)

W, R = 2.8, 0.8


def _budd_dux_impact_map(sigma: float, w: float, r: float):
    """(t0, V0) -> (t1, V1) of x'' + x = cos(w t) from an impact at sigma, flight written out, next impact root-found."""
    gamma, _c, period = budd_dux_constants(w, r)

    def step(t0: float, v0: float) -> np.ndarray:
        a = sigma - gamma * math.cos(w * t0)
        b = -r * v0 + gamma * w * math.sin(w * t0)

        def gap(t: float) -> float:
            return gamma * math.cos(w * t) + a * math.cos(t - t0) + b * math.sin(t - t0) - sigma

        t1 = brentq(gap, t0 + period - 0.05, t0 + period + 0.05, xtol=1e-15, rtol=1e-15)
        return np.array([t1, -gamma * w * math.sin(w * t1) - a * math.sin(t1 - t0) + b * math.cos(t1 - t0)])

    return step


def _jacobian(step, point: np.ndarray, steps: np.ndarray) -> np.ndarray:
    columns = []
    for j in range(2):
        d = np.zeros(2)
        d[j] = steps[j]
        columns.append((step(*(point + d)) - step(*(point - d))) / (2.0 * steps[j]))
    return np.column_stack(columns)


@pytest.mark.parametrize("sigma", [0.1, 0.02, -0.05, -0.3])
def test_budd_dux_ellipse_is_a_periodic_orbit(sigma: float) -> None:
    """Budd & Dux, Phil. Trans. R. Soc. A 347 (1994) 365: a point of the ellipse with its phase is a fixed point of the
    impact map (next impact one period later at the same speed, to round-off) and lies on the ellipse (residual)."""
    velocity = budd_dux_velocities(sigma, W, R)[1]
    assert abs(budd_dux_residual(sigma, velocity, W, R)) < 1e-14
    t0 = budd_dux_phase(sigma, velocity, W, R) / W
    _gamma, _c, period = budd_dux_constants(W, R)
    t1, v1 = _budd_dux_impact_map(sigma, W, R)(t0, velocity)
    assert abs(t1 - t0 - period) < 1e-13 * period
    assert abs(v1 - velocity) < 1e-13 * velocity
    before, after = budd_dux_state(sigma, velocity, W, R, t0 + period * (1 - 1e-12)), budd_dux_state(sigma, velocity, W, R, t0)
    assert before == pytest.approx([sigma, velocity], abs=1e-9)
    assert after == pytest.approx([sigma, -R * velocity], abs=1e-12)


@pytest.mark.parametrize("sigma", [0.1, -0.05, -0.3])
def test_budd_dux_multipliers_match_the_impact_map(sigma: float) -> None:
    """The closed-form trace and determinant (det = r^2) against the finite-difference Jacobian of the written-out
    impact map (central differences, step 1e-6: agreement to ~1e-8 relative)."""
    velocity = budd_dux_velocities(sigma, W, R)[1]
    t0 = budd_dux_phase(sigma, velocity, W, R) / W
    jac = _jacobian(_budd_dux_impact_map(sigma, W, R), np.array([t0, velocity]), np.array([1e-6, 1e-6]))
    expected = budd_dux_multipliers(sigma, velocity, W, R)
    got = np.linalg.eigvals(jac)
    assert np.linalg.det(jac) == pytest.approx(R * R, rel=1e-8)
    assert np.sort_complex(got) == pytest.approx(np.sort_complex(expected), abs=1e-7 * max(1.0, abs(expected[0])))


def test_budd_dux_period_doubling_has_a_multiplier_minus_one() -> None:
    """The closed-form period-doubling point lies on the ellipse and has a multiplier -1 (the other r^2)."""
    sigma, velocity = budd_dux_period_doubling(W, R)
    assert abs(budd_dux_residual(sigma, velocity, W, R)) < 1e-14
    assert velocity == pytest.approx(budd_dux_velocities(sigma, W, R)[1], rel=1e-13)
    mu = budd_dux_multipliers(sigma, velocity, W, R)
    assert mu[0] == pytest.approx(-1.0, abs=1e-13)
    assert mu[1] == pytest.approx(-R * R, abs=1e-13)


def _ball_impact_map(gamma: float, e: float, g: float, omega: float):
    """(t0, u0) -> (t1, u1): absolute take-off velocity u after each impact on the table A sin(w t), written out."""
    period = 2.0 * math.pi / omega
    amplitude = gamma * g / omega**2

    def step(t0: float, u0: float) -> np.ndarray:
        def height(t: float) -> float:
            return amplitude * math.sin(omega * t0) + u0 * (t - t0) - 0.5 * g * (t - t0) ** 2 - amplitude * math.sin(omega * t)

        t1 = brentq(height, t0 + 0.5 * period, t0 + 1.5 * period, xtol=1e-16, rtol=1e-15)
        arrival = u0 - g * (t1 - t0)
        return np.array([t1, (1.0 + e) * amplitude * omega * math.cos(omega * t1) - e * arrival])

    return step


@pytest.mark.parametrize("e", [0.3, 0.5, 0.8])
def test_ball_thresholds_against_the_exact_map(e: float) -> None:
    """Issue 12's Gamma_pd = sqrt((pi (1-e)/(1+e))^2 + (2 (1+e^2)/(1+e)^2)^2) is the exact table's period doubling:
    the written-out exact impact map has a multiplier -1 there (finite differences, ~1e-7); the high-bounce value
    sqrt((pi (1-e)/(1+e))^2 + 1) of Holmes' map is not (the two agree at e = 1 only)."""
    g, omega = 9.81, 2.0 * math.pi * 10.0
    period = 2.0 * math.pi / omega
    for gamma, expect_pd in ((ball_period_doubling(e), True), (0.5 * (ball_existence(e) + ball_period_doubling(e)), False)):
        step = _ball_impact_map(gamma, e, g, omega)
        t0, u = ball_phase(gamma, e) / omega, 0.5 * g * period
        assert step(t0, u) == pytest.approx([t0 + period, u], rel=1e-13, abs=1e-15)
        jac = _jacobian(step, np.array([t0, u]), np.array([1e-7 * period, 1e-7 * u]))
        got = np.sort_complex(np.linalg.eigvals(jac))
        assert got == pytest.approx(np.sort_complex(ball_multipliers(gamma, e)), abs=1e-6)
        assert (abs(got[0] + 1.0) < 1e-6) == expect_pd
    high = ball_period_doubling_high_bounce(e)
    assert abs(high - ball_period_doubling(e)) > 1e-3
    t0 = ball_phase(high, e) / omega
    jac = _jacobian(_ball_impact_map(high, e, g, omega), np.array([t0, 0.5 * g * period]), np.array([1e-7 * period, 1e-7 * g * period]))
    assert np.min(np.abs(np.linalg.eigvals(jac) + 1.0)) > 1e-2


def test_ball_state_leaves_and_lands_on_the_table() -> None:
    """The orbit's height above the table is 0 at the impact and 0 one period later, positive in between."""
    e, g, omega, gamma = 0.5, 9.81, 2.0 * math.pi * 10.0, 1.3
    period = 2.0 * math.pi / omega
    t0 = ball_phase(gamma, e) / omega
    assert ball_state(gamma, e, g, omega, t0)[0] == pytest.approx(0.0, abs=1e-15)
    assert ball_state(gamma, e, g, omega, t0 + period * (1 - 1e-13))[0] == pytest.approx(0.0, abs=1e-12)
    inside = [ball_state(gamma, e, g, omega, t0 + s * period)[0] for s in np.linspace(0.01, 0.99, 99)]
    assert min(inside) > 0.0


@pytest.mark.parametrize("e", [0.2, 0.5, 0.9])
def test_zeno_deficit_is_the_series_left_out(e: float) -> None:
    """Summing the bounces one by one until the first impact no faster than v_s gives the Zeno time minus the
    closed-form deficit, and the deficit lies in the stated interval."""
    h, g, v_s = 1.0, 9.81, 1e-5
    v, t = math.sqrt(2 * g * h), math.sqrt(2 * h / g)
    while v > v_s:
        t += 2 * e * v / g
        v *= e
    assert t == pytest.approx(zeno_time(h, g, e) - zeno_sticking_deficit(h, g, e, v_s), rel=1e-13)
    low, high = zeno_sticking_bounds(e, g, v_s)
    assert low < zeno_sticking_deficit(h, g, e, v_s) <= high


def test_grazing_amplitude_is_the_linear_amplitude() -> None:
    """|A / (k - m w^2 + j c w)| = d at the grazing amplitude."""
    m, k, c, w, d = 2.0, 3.0, 0.4, 0.9, 0.25
    a = grazing_amplitude(d, m, k, c, w)
    assert abs(a / complex(k - m * w * w, c * w)) == pytest.approx(d, rel=1e-15)
