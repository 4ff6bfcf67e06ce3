"""Folds, period doublings and Neimark-Sacker points of smooth maps, located against their closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from tests.orbits.toy_maps import DelayedLogisticMap, FoldMap, HenonMap, LogisticMap, NeutralSaddleMap
from vibroimpact.orbits.bifurcations import second_compound, switch_period_doubling
from vibroimpact.orbits.branch import Iterated
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.shooting import shoot


def test_second_compound_has_the_pairwise_products_as_eigenvalues() -> None:
    rng = np.random.default_rng(1)
    matrix = rng.normal(size=(4, 4))
    mu = np.linalg.eigvals(matrix)
    products = [mu[i] * mu[j] for i in range(4) for j in range(i + 1, 4)]
    assert np.sort_complex(np.linalg.eigvals(second_compound(matrix))) == pytest.approx(np.sort_complex(np.array(products)), abs=1e-10)


@pytest.mark.parametrize("b", [0.3, -0.2])
def test_henon_fold_and_period_doubling(b: float) -> None:
    m = HenonMap()
    x = m.fixed_points(0.2, b)[0]
    orbit = shoot(m, [x, b * x], [0.2, b])
    branch = continue_branch(m, orbit, "a", ContinuationSettings(lower=-0.5, upper=1.5, max_steps=60))
    fold, doubling = branch.special("fold"), branch.special("period_doubling")
    assert len(fold) == 1 and len(doubling) == 1
    assert fold[0].value == pytest.approx(-((1.0 - b) ** 2) / 4.0, rel=1e-8)
    assert doubling[0].value == pytest.approx(3.0 * (1.0 - b) ** 2 / 4.0, rel=1e-8)
    assert np.min(np.abs(fold[0].orbit.multipliers - 1.0)) < 1e-7
    assert np.min(np.abs(doubling[0].orbit.multipliers + 1.0)) < 1e-7
    # the fixed point at the fold is x = -(1 - b) / (2 a)
    assert fold[0].orbit.state[0] == pytest.approx(-(1.0 - b) / (2.0 * fold[0].value), rel=1e-6)


def test_fold_map_special_points() -> None:
    branch = continue_branch(FoldMap(), shoot(FoldMap(), [0.6], [0.25]), "p", ContinuationSettings(lower=-1.0, upper=1.5))
    assert [s.kind for s in branch.special_points] == ["fold", "period_doubling"]
    assert abs(branch.special_points[0].value) < 1e-12 and branch.special_points[1].value == pytest.approx(1.0, rel=1e-10)


def test_logistic_period_doubling_cascade_by_branch_switching() -> None:
    m = LogisticMap()
    branch = continue_branch(m, shoot(m, [0.6], [2.5]), "r", ContinuationSettings(lower=2.0, upper=3.3))
    (doubling,) = branch.special("period_doubling")
    assert doubling.value == pytest.approx(3.0, rel=1e-10)
    two = switch_period_doubling(m, doubling)
    assert two.period == 2 and two.parameter("r") > 3.0
    second = continue_branch(Iterated(m, 2), two, "r", ContinuationSettings(lower=2.9, upper=3.5))
    assert second.end.startswith("parent")  # it ends where it was born, on the period-one orbit
    (next_doubling,) = second.special("period_doubling")
    assert next_doubling.value == pytest.approx(1.0 + np.sqrt(6.0), rel=1e-9)
    rr = second.values
    upper = ((rr + 1.0) + np.sqrt(np.maximum((rr - 3.0) * (rr + 1.0), 0.0))) / (2.0 * rr)
    lower = ((rr + 1.0) - np.sqrt(np.maximum((rr - 3.0) * (rr + 1.0), 0.0))) / (2.0 * rr)
    x = second.states[:, 0]
    away = rr > 3.0 + 1e-6  # the last point is on the parent, where x depends on r like sqrt(r - 3)
    assert np.max(np.minimum(np.abs(x - upper), np.abs(x - lower))[away]) < 1e-10


def test_neimark_sacker_of_the_delayed_logistic_map() -> None:
    m, s = DelayedLogisticMap(), 0.7
    y = 1.0 - 1.0 / 1.5
    branch = continue_branch(m, shoot(m, [y / s + 0.01, y], [1.5, s]), "r", ContinuationSettings(lower=1.2, upper=2.5))
    (torus,) = branch.special("neimark_sacker")
    assert torus.value == pytest.approx(2.0, rel=1e-9)
    assert np.abs(torus.orbit.multipliers) == pytest.approx([1.0, 1.0], abs=1e-8)
    assert abs(np.angle(torus.orbit.multipliers[0])) == pytest.approx(np.pi / 3.0, abs=1e-8)
    assert not branch.special("period_doubling") and not branch.special("fold")


def test_a_neutral_saddle_is_not_a_neimark_sacker_point() -> None:
    m = NeutralSaddleMap()
    branch = continue_branch(m, shoot(m, [0.0, 0.0], [0.2]), "p", ContinuationSettings(lower=0.0, upper=0.9))
    assert branch.special_points == ()
