"""Every motion at one frequency (:mod:`vibroimpact.simulation.point_motions`): the constructed case of a notch that a
period-4 motion destroys, found from rest, shot exactly, and its basin share counted."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.analysis.band_worst import closed_form_at
from vibroimpact.kinds.design.study import design_space
from vibroimpact.scene.reader import load_scene
from vibroimpact.simulation.point_motions import PointMotion, PointMotions, point_motions, point_starts
from vibroimpact.simulation.attractors import at_frequency
from vibroimpact.simulation.harmonics import gaps, resting_state

#: The paper's absorber with Delta = 2.3596 mm, R = 0.1893 at 33 Hz: |X1| of its period-4 motion [m] (the exact engine;
#: tests/independent confirms it with scipy's integrator).
PERIOD_4 = 0.77606740e-3


@pytest.fixture(scope="module")
def problem():
    space = design_space(load_scene("studies/design_rigid_stop.yaml"))
    return space.problem_at((2.3596e-3, 0.1893), 0)


def test_period_four_motion_destroys_the_notch(problem) -> None:
    found = point_motions(problem, 33.0, starts=24, seed=3, shoot_orbits=True)
    top = found.largest
    assert top is not None and top.period == 4 and round(top.impacts) == 1 and top.exact
    assert top.value == pytest.approx(PERIOD_4, rel=1e-6)
    assert top.from_rest and top.starts >= 20  # nearly every start settles there
    assert "period-4 motion, 1 impact per 4 periods" in top.text()
    assert found.share_text(top).startswith("reached from rest and from")
    # the contact-free notch coexists (its value the closed form's), reached from the linear state
    free = [m for m in found.motions if m.regime == "linear"]
    assert len(free) == 1 and free[0].from_linear
    assert free[0].value == pytest.approx(closed_form_at(problem, 33.0).amplitude, rel=1e-12)
    assert sum(m.starts for m in found.motions) == found.runs


def test_shooting_agrees_with_the_settled_runs(problem) -> None:
    settled = point_motions(problem, 33.0, starts=8, seed=1).largest
    shot = point_motions(problem, 33.0, starts=8, seed=1, shoot_orbits=True).largest
    assert settled is not None and shot is not None and not settled.exact and shot.exact
    assert shot.value == pytest.approx(settled.value, rel=1e-7)


def test_starts_are_inside_the_stops_and_seeded(problem) -> None:
    moved = at_frequency(problem, 33.0)
    starts = point_starts(moved, 30, seed=5)
    assert [label for label, _ in starts[:2]] == ["linear", "rest"]
    np.testing.assert_array_equal(starts[1][1], resting_state(moved))
    for _, state in starts:
        assert np.all(gaps(moved, state) > 0.0)
    again = point_starts(moved, 30, seed=5)
    assert all(np.array_equal(a[1], b[1]) for a, b in zip(starts, again))
    sizes = [float(np.max(np.abs(s[: moved.size] - resting_state(moved)[: moved.size]))) for _, s in starts[2:]]
    assert min(sizes) < 0.2 * moved.length_scale() < moved.length_scale() < max(sizes)  # small starts and large ones


def test_far_stop_leaves_only_the_linear_state(problem) -> None:
    space = design_space(load_scene("studies/design_rigid_stop.yaml"))
    far = space.problem_at((0.05, 0.5), 0)
    found = point_motions(far, 33.0, starts=6)
    assert len(found.motions) == 1 and found.largest.regime == "linear" and found.largest.starts == 6
    assert found.value == pytest.approx(closed_form_at(far, 33.0).amplitude, rel=1e-12)


def test_refuses_bad_input(problem) -> None:
    with pytest.raises(ValueError, match="frequency"):
        point_motions(problem, -1.0)
    with pytest.raises(ValueError, match="starts"):
        point_starts(problem, 1, 0)


def test_texts() -> None:
    chaotic = PointMotion(1e-3, "chaotic", 0, 2.34, 3, False, False, converged=0.01)
    assert chaotic.text() == "a chaotic (non-periodic) motion, 2.3 impacts per period on average"
    irregular = PointMotion(1e-3, "irregular", 0, 0.3, 1, False, False)
    assert irregular.text().startswith("an irregular")
    found = PointMotions(33.0, 64, (irregular,), 400, 64)
    assert found.share_text(irregular) == "reached from 1 of 64 starts, not from rest"
    assert math.isclose(found.value, 1e-3)


def test_an_untouched_free_mass_counts_with_the_primary_s_own_motion() -> None:
    """The impact damper's free mass (k2 = b2 = 0) in a 150 mm cavity at 24 Hz never reaches a wall from rest: no
    attractor in the strict sense (any push makes it drift), but a motion that lasts while nothing disturbs it. Its
    |X1| is the primary's alone, F / |k1 - m1 w^2 + j w b1| (the free mass exerts nothing), never a NaN that a
    search would skip."""
    space = design_space(load_scene("studies/impact_damper.yaml"))
    problem = space.problem_at((0.15, 0.5), 0)
    omega = 2.0 * math.pi * 24.0
    alone = 10.0 / abs(25000.0 - omega**2 + 1j * omega * 0.31623)
    found = point_motions(problem, 24.0, starts=2, transient=100, strobes=32)
    rest = next(m for m in found.motions if m.from_rest)
    assert rest.regime == "linear" and rest.value == pytest.approx(alone, rel=1e-6)
    from vibroimpact.simulation.band_attractors import band_attractors

    sweep = band_attractors(problem, (23.9, 24.1), frequencies=2, starts=2, transient=100, strobes=32)
    assert np.all(np.isfinite(sweep.amplitude[:, 3]))  # the run from rest
    assert sweep.amplitude[0, 3] == pytest.approx(10.0 / abs(25000.0 - (2 * math.pi * 23.9) ** 2 + 1j * 2 * math.pi * 23.9 * 0.31623), rel=1e-6)
