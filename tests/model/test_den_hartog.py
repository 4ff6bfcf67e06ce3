"""Den Hartog's damped absorber (Mechanical Vibrations, 4th ed., 1956, sec. 3.3; Brock, J. Appl. Mech. 13, 1946):
the formulas of :mod:`vibroimpact.model.absorber` against the receptance of the structure itself.

|X1| is taken from :meth:`LinearStructure.receptance_matrix` (an undamped primary, force on the primary mass), not
from Den Hartog's formula, so each test checks a published property against an independent computation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.absorber import (
    den_hartog_absorber,
    fixed_point_height,
    fixed_point_ratios,
    flat_point_damping_ratios,
    optimal_damping_ratio,
    optimal_tuning,
    primary_amplitude_ratio,
)

M1, K1 = 1.0, 25000.0
OMEGA_P = math.sqrt(K1 / M1)


def ratio(g: np.ndarray | float, m2: float, k2: float, c2: float) -> np.ndarray:
    """|X1| / (q / k1) at g = w / Omega_p from the structure's receptance (undamped primary)."""
    structure = LinearStructure([[M1, 0.0], [0.0, m2]], [[K1 + k2, -k2], [-k2, k2]], [[c2, -c2], [-c2, c2]])
    return np.abs(structure.receptance_matrix(np.asarray(g) * OMEGA_P)[..., 0, 0]) * K1


def slope(g: float, m2: float, k2: float, c2: float, h: float = 1e-6) -> float:
    """d(|X1| / x_st) / dg by a central difference."""
    return float((ratio(g + h, m2, k2, c2) - ratio(g - h, m2, k2, c2)) / (2.0 * h))


@pytest.mark.parametrize("mu", [0.02, 0.1, 0.25])
@pytest.mark.parametrize("tuning", [None, 0.8, 1.3])
def test_every_damping_passes_through_the_fixed_points(mu: float, tuning: float | None) -> None:
    m2 = mu * M1
    f = optimal_tuning(mu) if tuning is None else tuning
    k2 = m2 * (f * OMEGA_P) ** 2
    for g in fixed_point_ratios(mu, f):
        heights = np.array([ratio(g, m2, k2, c2) for c2 in (1e-4, 0.3, 3.0, 30.0, 1e4)])
        assert np.max(np.abs(heights - heights[0])) <= 1e-9 * heights[0]


@pytest.mark.parametrize("mu", [0.02, 0.1, 0.25])
def test_optimal_tuning_makes_p_and_q_equally_high(mu: float) -> None:
    m2 = mu * M1
    k2 = m2 * (optimal_tuning(mu) * OMEGA_P) ** 2
    p, q = (ratio(g, m2, k2, 2.0) for g in fixed_point_ratios(mu))
    assert abs(p - q) <= 1e-9 * p
    assert abs(p - fixed_point_height(mu)) <= 1e-9 * p


@pytest.mark.parametrize("mu", [0.02, 0.1, 0.25])
def test_the_flat_point_dampings_make_the_curve_horizontal_at_p_and_at_q(mu: float) -> None:
    m2 = mu * M1
    k2 = m2 * (optimal_tuning(mu) * OMEGA_P) ** 2
    g_p, g_q = fixed_point_ratios(mu)
    zeta_p, zeta_q = flat_point_damping_ratios(mu)
    assert zeta_p < optimal_damping_ratio(mu) < zeta_q
    assert math.isclose(optimal_damping_ratio(mu) ** 2, 0.5 * (zeta_p**2 + zeta_q**2), rel_tol=1e-14)
    height = fixed_point_height(mu)
    assert abs(slope(g_p, m2, k2, 2.0 * zeta_p * m2 * OMEGA_P)) <= 1e-6 * height
    assert abs(slope(g_q, m2, k2, 2.0 * zeta_q * m2 * OMEGA_P)) <= 1e-6 * height


@pytest.mark.parametrize("mu, excess", [(0.02, 0.001), (0.1, 0.003), (0.25, 0.006)])
def test_the_optimum_is_flat_at_the_fixed_points_to_the_formulas_approximation(mu: float, excess: float) -> None:
    """Den Hartog's zeta averages the two flat-point conditions: between and around P and Q the optimally damped curve
    rises above their height by a fraction of a percent (0.17 % for mu = 0.1), while halving or doubling the damping
    raises it by far more; and its slopes at P and Q are smaller than with either."""
    m2 = mu * M1
    k2 = m2 * (optimal_tuning(mu) * OMEGA_P) ** 2
    g = np.linspace(0.3, 2.0, 40001)
    height = fixed_point_height(mu)
    optimum = 2.0 * optimal_damping_ratio(mu) * m2 * OMEGA_P
    assert np.max(ratio(g, m2, k2, optimum)) <= (1.0 + excess) * height
    for factor in (0.5, 2.0):
        assert np.max(ratio(g, m2, k2, factor * optimum)) >= (1.0 + 5.0 * excess) * height
    for point in fixed_point_ratios(mu):
        at_optimum = abs(slope(point, m2, k2, optimum))
        assert at_optimum < abs(slope(point, m2, k2, 0.5 * optimum))
        assert at_optimum < abs(slope(point, m2, k2, 2.0 * optimum))


def test_den_hartogs_formula_is_the_receptance() -> None:
    mu, f, zeta = 0.1, 0.93, 0.12
    m2 = mu * M1
    g = np.linspace(0.2, 2.5, 101)
    direct = ratio(g, m2, m2 * (f * OMEGA_P) ** 2, 2.0 * zeta * m2 * OMEGA_P)
    assert np.max(np.abs(primary_amplitude_ratio(g, mu, f, zeta) / direct - 1.0)) <= 1e-12


def test_the_paper_masses_optimum() -> None:
    """mu = 0.1: f = 1/1.1, zeta = sqrt(0.3 / (8 1.331)) = 0.16785; the dashpot is 2 zeta m2 Omega_p whatever the
    tuning (Den Hartog's c_c = 2 m Omega_n with the primary's natural frequency)."""
    absorber = den_hartog_absorber(M1, K1, 0.1)
    assert math.isclose(absorber.tuning, 1.0 / 1.1, rel_tol=1e-15)
    assert math.isclose(absorber.damping_ratio, math.sqrt(0.3 / (8.0 * 1.1**3)), rel_tol=1e-15)
    assert math.isclose(absorber.stiffness, 0.1 * (OMEGA_P / 1.1) ** 2, rel_tol=1e-14)
    assert math.isclose(absorber.damping, 2.0 * absorber.damping_ratio * 0.1 * OMEGA_P, rel_tol=1e-14)
    assert math.isclose(absorber.absorber_frequency, OMEGA_P / 1.1 / (2.0 * math.pi), rel_tol=1e-14)
    # the same optimum written with the absorber's own frequency: zeta_a^2 = 3 mu / (8 (1 + mu))
    assert math.isclose(absorber.damping / (2.0 * 0.1 * OMEGA_P / 1.1), math.sqrt(0.3 / (8.0 * 1.1)), rel_tol=1e-14)


@pytest.mark.parametrize("mu", [0.0, -0.1, math.nan, math.inf])
def test_a_mass_ratio_out_of_range_is_refused(mu: float) -> None:
    with pytest.raises(ValueError, match="mass ratio"):
        optimal_damping_ratio(mu)
