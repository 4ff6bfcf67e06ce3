"""Shooting on smooth maps with known fixed points and periodic orbits."""

from __future__ import annotations

import numpy as np
import pytest

from tests.orbits.toy_maps import FoldMap, HenonMap, LogisticMap
from vibroimpact.orbits.branch import Iterated
from vibroimpact.orbits.shooting import ShootingError, ShootingSettings, shoot


def test_henon_fixed_point_and_multipliers() -> None:
    a, b = 1.0, 0.3
    x = HenonMap.fixed_points(a, b)[0]
    orbit = shoot(HenonMap(), [x + 0.05, b * x - 0.03], [a, b])
    assert orbit.state == pytest.approx([x, b * x], abs=1e-12)
    jacobian = np.array([[-2.0 * a * x, 1.0], [b, 0.0]])
    assert np.sort_complex(orbit.multipliers) == pytest.approx(np.sort_complex(np.linalg.eigvals(jacobian).astype(complex)), abs=1e-12)
    assert orbit.residual <= 1e-11
    # Newton with the exact Jacobian: quadratic convergence, a few iterations from a nearby guess
    history = orbit.residual_history
    assert len(history) <= 6 and history[-2] < 1e-4


def test_period_two_orbit_of_the_logistic_map_equals_its_closed_form() -> None:
    r = 3.2
    points = ((r + 1.0) + np.array([1.0, -1.0]) * np.sqrt((r - 3.0) * (r + 1.0))) / (2.0 * r)
    orbit = shoot(LogisticMap(), [0.79], [r], period=2)
    assert orbit.period == 2
    assert orbit.state[0] == pytest.approx(points[0], abs=1e-12)
    # its multiplier: the product of the derivatives at both points, 4 + 2r - r^2
    assert orbit.multipliers[0].real == pytest.approx(4.0 + 2.0 * r - r * r, abs=1e-10)
    assert orbit.stable
    same = shoot(Iterated(LogisticMap(), 2), [0.79], [r])
    assert same.state == pytest.approx(orbit.state, abs=1e-14)


def test_no_fixed_point_raises_with_the_residual_history() -> None:
    with pytest.raises(ShootingError, match="residual history") as caught:
        shoot(FoldMap(), [0.3], [-0.1], settings=ShootingSettings(max_iterations=15))
    assert len(caught.value.residual_history) >= 2
    assert min(caught.value.residual_history) >= 0.1 - 1e-12  # |x + p - x^2 - x| >= 0.1 everywhere


def test_settings_are_validated() -> None:
    with pytest.raises(ValueError, match="tolerance"):
        ShootingSettings(tolerance=0.0)
