"""The general closed form on Budd & Dux's undamped impact oscillator (Phil. Trans. R. Soc. A 347 (1994) 365):
x'' + x = cos(w t), x <= sigma, x' -> -r x' at the stop, unit mass.

Their period-one orbits' impact velocities V satisfy the ellipse

    (sigma + c V / 2)^2 + ((1 - r) V / (2 w))^2 = gamma^2,  gamma = 1 / (1 - w^2),  c = (1 + r) sin T / (1 - cos T)

and the one-impact closed form (analysis.impact_orbit, with h(t) = sin t: chi0 = sin T / (2 (1 - cos T)),
chi'(0-) = -1/2, J = (1 + r) V) must put every orbit on it. Stability: the monodromy S exp(A T) of the 1-dof orbit
has det = r^2 (the saltation matrix is [[-r, 0], [(1 + r) a / V, -r]] with a = x''(t0) = cos(w t0) - sigma, and the
flow is a rotation) and trace tr = (1 + r) sin T a / V - 2 r cos T, where cos(w t0) = (sigma + c V / 2) / gamma
(the ellipse's phase). Period doubling: tr = -(1 + r^2). With a = (c V / 2) (1 - w^2) - w^2 sigma this is linear in
(sigma, V): sigma = kappa V, kappa = (c (1 - w^2) / 2 + D / ((1 + r) sin T)) / w^2, D = 1 + r^2 - 2 r cos T, and the
ellipse gives V = |gamma| / sqrt((kappa + c / 2)^2 + ((1 - r) / (2 w))^2).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.stability import floquet_multipliers
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.structure import LinearStructure

OSCILLATOR = LinearStructure([[1.0]], [[1.0]], [[0.0]], ("x",))
CASES = [(2.8, 0.8), (3.5, 0.5), (0.6, 0.7), (1.3, 0.2)]


def budd_dux(w: float, r: float) -> ImpactProblem:
    return ImpactProblem(OSCILLATOR, (Stop(RigidStop(0.0, r), 0),), HarmonicForce(1.0, w / (2 * math.pi)))


def constants(w: float, r: float) -> tuple[float, float, float]:
    period = 2 * math.pi / w
    return 1.0 / (1.0 - w * w), (1 + r) * math.sin(period) / (1 - math.cos(period)), period


@pytest.mark.parametrize(("w", "r"), CASES)
def test_impact_velocities_lie_on_the_ellipse(w: float, r: float) -> None:
    """Both roots, sigma from -1.2 |gamma| to 1.2 |gamma| (negative included): residual of the ellipse < 1e-12 gamma^2;
    the ellipse's phase gamma cos(w t0) = sigma + c V / 2, gamma sin(w t0) = -(1 - r) V / (2 w) to 1e-12."""
    gamma, c, period = constants(w, r)
    sigma = np.linspace(-1.2, 1.2, 241) * abs(gamma)
    found = 0
    for root in ("+", "-"):
        orbit = solve_impact_orbit(budd_dux(w, r), clearance=sigma, root=root)
        e = orbit.exists
        found += int(e.sum())
        v = orbit.impulse[e] / (1 + r)
        residual = (sigma[e] + c * v / 2) ** 2 + ((1 - r) * v / (2 * w)) ** 2 - gamma**2
        assert np.all(np.abs(residual) <= 1e-12 * gamma**2)
        forcing_phase = w * orbit.impact_time[e]
        np.testing.assert_allclose(gamma * np.cos(forcing_phase), sigma[e] + c * v / 2, atol=1e-12 * abs(gamma))
        np.testing.assert_allclose(gamma * np.sin(forcing_phase), -(1 - r) * v / (2 * w), atol=1e-12 * abs(gamma))
    assert found > 100


@pytest.mark.parametrize(("w", "r"), CASES)
def test_multipliers_have_the_impact_map_trace_and_determinant(w: float, r: float) -> None:
    """Sum and product of the monodromy's multipliers equal tr and r^2 of the module docstring (1e-10 of |tr| + 1)."""
    gamma, c, period = constants(w, r)
    sigma = np.linspace(-1.0, 1.0, 41) * abs(gamma)
    orbit = solve_impact_orbit(budd_dux(w, r), clearance=sigma)
    e = orbit.exists & (orbit.impulse > 1e-6 * abs(gamma))  # not at grazing (V = 0)
    v = orbit.impulse[e] / (1 + r)
    acceleration = (sigma[e] + c * v / 2) / gamma - sigma[e]
    trace = (1 + r) * math.sin(period) * acceleration / v - 2 * r * math.cos(period)
    mu = floquet_multipliers(orbit)[e]
    assert np.all(np.abs(mu.sum(axis=-1).real - trace) <= 1e-10 * (np.abs(trace) + 1))
    np.testing.assert_allclose(mu.prod(axis=-1).real, r * r, atol=1e-10)


def test_period_doubling_in_closed_form() -> None:
    """w = 2.8, r = 0.8: the '+' orbit (stable for sigma below the doubling, admissible on both sides) has a multiplier
    -1 at the sigma of the module docstring's formula: located by Brent's method on the closed form's multipliers to
    1e-10 relative, with its V on the ellipse; the formula gives sigma = -0.06858, V = 0.49308."""
    w, r = 2.8, 0.8
    gamma, c, period = constants(w, r)
    d = 1 + r * r - 2 * r * math.cos(period)
    kappa = (c * (1 - w * w) / 2 + d / ((1 + r) * math.sin(period))) / (w * w)
    velocity = abs(gamma) / math.hypot(kappa + c / 2, (1 - r) / (2 * w))
    expected = kappa * velocity
    problem = budd_dux(w, r)

    def doubling(sigma: float) -> float:
        mu = floquet_multipliers(solve_impact_orbit(problem, clearance=sigma))
        return float(np.min(mu.real) + 1.0)

    located = brentq(doubling, -0.07, -0.05, xtol=1e-15, rtol=1e-15)
    assert located == pytest.approx(expected, rel=1e-10)
    orbit = solve_impact_orbit(problem, clearance=np.array([located - 0.01, located, located + 0.01]))
    assert np.all(orbit.admissible())
    assert float(orbit.impulse[1]) / (1 + r) == pytest.approx(velocity, rel=1e-10)
    moduli = np.max(np.abs(floquet_multipliers(orbit)), axis=-1)
    assert moduli[0] < 1.0 < moduli[2]
