"""Curves of folds, period doublings and Neimark-Sacker points in two parameters, against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from tests.orbits.toy_maps import DelayedLogisticMap, HenonMap
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.shooting import shoot
from vibroimpact.orbits.continuation import continue_special_point


@pytest.fixture(scope="module")
def henon_branch():
    m, b = HenonMap(), 0.3
    x = m.fixed_points(0.2, b)[0]
    return continue_branch(m, shoot(m, [x, b * x], [0.2, b]), "a", ContinuationSettings(lower=-0.5, upper=0.6, max_steps=60))


def test_henon_fold_curve(henon_branch) -> None:
    curve = continue_special_point(HenonMap(), henon_branch.special("fold")[0], "b", ContinuationSettings(step=0.1), bounds={"b": (-0.5, 0.9)})
    a, b = curve.values("a"), curve.values("b")
    assert curve.end == "bound, bound" and b.min() == pytest.approx(-0.5) and b.max() == pytest.approx(0.9)
    assert np.max(np.abs(a + (1.0 - b) ** 2 / 4.0)) < 1e-10
    assert all(np.min(np.abs(o.multipliers - 1.0)) < 1e-7 for o in curve.orbits)


def test_henon_period_doubling_curve(henon_branch) -> None:
    curve = continue_special_point(HenonMap(), henon_branch.special("period_doubling")[0], "b", ContinuationSettings(step=0.1), bounds={"b": (-0.5, 0.9)})
    a, b = curve.values("a"), curve.values("b")
    assert np.max(np.abs(a - 3.0 * (1.0 - b) ** 2 / 4.0)) < 1e-10


def test_neimark_sacker_curve_of_the_delayed_logistic_map() -> None:
    m, s = DelayedLogisticMap(), 0.7
    y = 1.0 - 1.0 / 1.5
    branch = continue_branch(m, shoot(m, [y / s, y], [1.5, s]), "r", ContinuationSettings(lower=1.2, upper=2.5))
    curve = continue_special_point(m, branch.special("neimark_sacker")[0], "s", ContinuationSettings(step=0.1), bounds={"s": (0.2, 3.0)})
    r, ss = curve.values("r"), curve.values("s")
    assert ss.min() == pytest.approx(0.2) and ss.max() == pytest.approx(3.0)
    assert np.max(np.abs(r - 2.0)) < 1e-10
    assert all(np.abs(o.multipliers) == pytest.approx([1.0, 1.0], abs=1e-8) for o in curve.orbits)


def test_a_neimark_sacker_point_beside_a_strongly_unstable_multiplier_is_followed() -> None:
    """The paper's second band (R = 0.2, 3 mm): its Neimark-Sacker point at 37.574128 Hz has a real multiplier of 35
    beside the critical pair. The curve's old defining function, det(J(2) - I), carries that multiplier's factors and
    its round-off kept Newton off the curve ('does not solve its extended system'); on the pair's own |mu|^2 - 1 the
    curve in (frequency, clearance) runs to both clearance bounds, with a pair on the unit circle at every point."""
    from vibroimpact import PAPER_SYSTEM, HarmonicForce, ImpactMap, ImpactProblem, RigidStop, closed_form_state

    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(0.003, 0.2), HarmonicForce(10.0, 25.0))
    system = ImpactMap(problem)
    branch = continue_branch(system, shoot(system, closed_form_state(problem), system.parameters), "frequency")
    point = min(branch.special("neimark_sacker"), key=lambda p: abs(p.value - 37.574128))
    assert point.value == pytest.approx(37.574128, abs=1e-6) and point.orbit.floquet_modulus > 30.0
    curve = continue_special_point(system, point, "clearance", bounds={"clearance": (0.0025, 0.0035)})
    assert curve.end == "bound, bound" and len(curve.orbits) > 10
    for orbit in curve.orbits:
        pair = orbit.multipliers[np.abs(orbit.multipliers.imag) > 1e-6]
        assert pair.size == 2 and np.max(np.abs(np.abs(pair) - 1.0)) <= 1e-8
