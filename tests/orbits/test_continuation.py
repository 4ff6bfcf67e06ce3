"""Pseudo-arclength continuation on smooth maps: around folds, through unstable parts, to the bounds."""

from __future__ import annotations

import numpy as np
import pytest

from tests.orbits.toy_maps import FoldMap, HenonMap, LogisticMap
from vibroimpact.orbits.branch import Iterated
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.shooting import shoot


def test_branch_goes_around_the_fold_and_stops_on_the_bounds() -> None:
    orbit = shoot(FoldMap(), [0.6], [0.25])
    branch = continue_branch(FoldMap(), orbit, "p", ContinuationSettings(lower=-1.0, upper=0.5))
    x, p = branch.states[:, 0], branch.values
    assert np.max(np.abs(x * x - p)) < 1e-10  # every point is a fixed point: x = +-sqrt(p)
    assert x.min() == pytest.approx(-np.sqrt(0.5), abs=1e-9) and x.max() == pytest.approx(np.sqrt(0.5), abs=1e-9)
    assert branch.end == "bound, bound"
    assert p.min() >= -1e-12  # no fixed point for p < 0: the branch turned back at the fold
    # stable (multiplier 1 - 2x inside the unit circle) exactly on the upper half
    assert np.array_equal(branch.stable, x > 0.0)


def test_both_directions_and_one_direction_agree() -> None:
    m, b = HenonMap(), 0.3
    x = m.fixed_points(0.2, b)[0]
    orbit = shoot(m, [x, b * x], [0.2, b])
    settings = ContinuationSettings(lower=0.1, upper=0.3)
    up = continue_branch(m, orbit, "a", settings, direction=1)
    down = continue_branch(m, orbit, "a", settings, direction=-1)
    both = continue_branch(m, orbit, "a", settings)
    assert up.values[-1] == pytest.approx(0.3, rel=1e-10) and down.values[-1] == pytest.approx(0.1, rel=1e-10)
    assert len(both.orbits) == len(up.orbits) + len(down.orbits) - 1
    exact = np.array([m.fixed_points(a, b)[0] for a in both.values])
    assert both.states[:, 0] == pytest.approx(exact, abs=1e-10)


def test_max_steps_ends_the_branch() -> None:
    orbit = shoot(LogisticMap(), [0.5], [2.5])
    branch = continue_branch(LogisticMap(), orbit, "r", ContinuationSettings(step=0.01, max_step=0.01, max_steps=5), direction=1)
    assert branch.end == "max_steps" and len(branch.orbits) == 6


def test_period_two_branch_by_iterated_map() -> None:
    r = 3.2
    orbit = shoot(LogisticMap(), [0.79], [r], period=2)
    branch = continue_branch(Iterated(LogisticMap(), 2), orbit, "r", ContinuationSettings(lower=3.1, upper=3.4))
    rr = branch.values
    points = ((rr + 1.0) + np.sqrt((rr - 3.0) * (rr + 1.0))) / (2.0 * rr)
    assert branch.states[:, 0] == pytest.approx(points, abs=1e-10)
    assert all(o.period == 2 for o in branch.orbits)


@pytest.mark.parametrize("bad", [{"step": 0.0}, {"lower": 1.0, "upper": 0.0}, {"detect": ("cusp",)}])
def test_settings_are_validated(bad: dict) -> None:
    with pytest.raises(ValueError):
        ContinuationSettings(**bad)
