"""The closed-form worst case of a rigid-stop design over a band (issue 32): the design search's fast objective,
against the linear optimum's band peak (stop out of reach), the closed form's own bounded search (the paper's design),
and the motions that coexist at one frequency; its scan, fine wherever the structure can resonate, so that the worst
case does not depend on the band's width."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from vibroimpact.analysis.band_worst import MOTIONS, SCAN, closed_form_at, closed_form_worst, uncovered_share
from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.analysis.linear_optimum import band_peak
from vibroimpact.analysis.scan_grid import RESONANCE_SPACING, resonances, scan_frequencies
from vibroimpact.analysis.stability import MARGINAL_MODULUS, floquet_multipliers
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM

from tests.analysis.impact_flow import ImpactFlow


def paper(clearance: float, restitution: float) -> ImpactProblem:
    return ImpactProblem(PAPER_SYSTEM, RigidStop(clearance, restitution), HarmonicForce(10.0, 25.0))


def test_a_stop_out_of_reach_gives_the_linear_band_peak() -> None:
    """Delta = 1 m: the contact-free motion everywhere, its peak equal to the linear band peak (located there to
    1e-12 rad/s) to 1e-9 relative; nothing uncovered."""
    found = closed_form_worst(paper(1.0, 0.5), (15.0, 45.0))
    linear = band_peak(PAPER_SYSTEM, 10.0, (15.0, 45.0))
    assert found.motion == MOTIONS[1] and found.impacts == 0 and found.uncovered == 0.0  # exact: a count of none
    assert found.amplitude == pytest.approx(linear.amplitude, rel=1e-9)
    assert found.frequency == pytest.approx(linear.frequency, rel=1e-6)


def test_the_paper_design_is_set_by_its_one_impact_orbit() -> None:
    """Delta = 3 mm, R = 0.2: 2.7526 mm at 25.161 Hz, the stable root's maximum by a bounded search on eqs. 15-18 to
    1e-10 relative (the same number the continued branch gives, tests/orbits/test_worst_case.py)."""
    problem = paper(0.003, 0.2)
    found = closed_form_worst(problem, (15.0, 45.0))
    closed = minimize_scalar(lambda f: -float(np.abs(solve_impact_orbit(problem, frequency=np.array([f]), root="+").harmonics())[0, 0]),
                             bounds=(25.0, 25.3), method="bounded", options={"xatol": 1e-12})  # fmt: skip
    assert found.motion == MOTIONS[2] and found.impacts == 1
    assert found.amplitude == pytest.approx(-closed.fun, rel=1e-10)
    assert found.frequency == pytest.approx(closed.x, abs=1e-4)
    assert 0.0 < found.uncovered < 0.5 and 0.0 < found.estimate  # between the bands, no period-1 motion is stable


def test_at_one_frequency_the_worst_coexisting_motion_is_taken() -> None:
    """Delta = 2 mm, R = 0.6 at 20.85 Hz: the linear motion does not fit (its stop coordinate exceeds Delta), the
    stable impact orbit is the answer, |X1| of one root of eq. 16 to 1e-12; with the stop out of reach, the notch's
    own |X1|."""
    problem = paper(0.002, 0.6)
    at = closed_form_at(problem, 20.85)
    linear = linear_amplitudes(problem, frequency=20.85)
    assert not bool(linear.fits(problem.clearances()))
    roots = [float(np.abs(solve_impact_orbit(problem, frequency=np.array([20.85]), root=r).harmonics())[0, 0]) for r in "+-"]
    assert at.motion == MOTIONS[2] and min(abs(at.amplitude / x - 1.0) for x in roots if np.isfinite(x)) < 1e-12
    free = closed_form_at(paper(1.0, 0.6), 20.85)
    assert free.motion == MOTIONS[1]
    assert free.amplitude == pytest.approx(abs(linear_amplitudes(paper(1.0, 0.6), frequency=20.85).amplitudes[0]), rel=1e-12)


def test_a_bad_band_is_refused() -> None:
    with pytest.raises(ValueError, match="band"):
        closed_form_worst(paper(0.003, 0.2), (45.0, 15.0))


def test_the_screen_s_impulse_is_an_impact_an_independent_integration_measures() -> None:
    """The paper's design (Delta = 3 mm, R = 0.2): the screen's largest impulse of one impact over 15-45 Hz is the
    largest over its scan frequencies of the stable, admissible one-impact orbits' impulses; started on that orbit,
    DOP853 with exact impact events (tests/analysis/impact_flow.py, no closed form inside) measures the same impulse,
    m_eff (1 + R) times the approach speed, at every impact of 3 periods (1e-8 relative); with the stop out of reach
    there is no impact and the impulse is 0."""
    problem = paper(0.003, 0.2)
    found = closed_form_worst(problem, (15.0, 45.0))
    f = np.linspace(15.0, 45.0, 241)
    largest, where = 0.0, np.nan
    for root in ("+", "-"):
        orbit = solve_impact_orbit(problem, frequency=f, root=root)
        for k in np.flatnonzero(orbit.exists):
            one = orbit.take([k])
            if np.max(np.abs(floquet_multipliers(one))) < 1.0 - MARGINAL_MODULUS and bool(one.admissible(samples=128)[0]) and float(one.impulse[0]) > largest:
                largest, where = float(one.impulse[0]), float(f[k])
    assert found.impulse == pytest.approx(largest, rel=1e-12) and largest > 0.0
    at = ImpactProblem(PAPER_SYSTEM, RigidStop(0.003, 0.2), HarmonicForce(10.0, where))
    orbit = next(o for o in (solve_impact_orbit(at, root=r) for r in ("+", "-")) if bool(o.exists) and float(o.impulse) == pytest.approx(largest, rel=1e-9))
    _, impacts = ImpactFlow(at).run(orbit.state_at(np.array([0.0]))[0], 0.0, 3 * at.period)
    assert len(impacts) == 3 and all(impact.impulse == pytest.approx(largest, rel=1e-8) for impact in impacts)
    assert closed_form_worst(paper(1.0, 0.2), (15.0, 45.0)).impulse == 0.0  # exact: no impact, no impulse


@pytest.mark.parametrize("high", [450.0, 4500.0])
def test_the_paper_design_s_worst_case_does_not_depend_on_the_band_s_width(high: float) -> None:
    """Delta = 3 mm, R = 0.2: over 15-450 and 15-4500 Hz the same 2.7526 mm of the one-impact orbit near 25.16 Hz as
    over 15-45 Hz, to 1e-6 relative (241 evenly spaced points over 15-4500 Hz step 18.7 Hz, over both resonances:
    1.8292 mm before the scan was made fine around them)."""
    problem = paper(0.003, 0.2)
    narrow, wide = closed_form_worst(problem, (15.0, 45.0)), closed_form_worst(problem, (15.0, high))
    assert narrow.amplitude == pytest.approx(2.7526e-3, rel=1e-4)
    assert wide.amplitude == pytest.approx(narrow.amplitude, rel=1e-6) and wide.motion == MOTIONS[2]
    assert wide.frequency == pytest.approx(narrow.frequency, rel=1e-6)


def test_the_shipped_scan_is_the_evenly_spaced_one_and_a_wide_band_s_is_fine_over_the_resonances() -> None:
    """Over 15-45 Hz the 241 points are the evenly spaced grid, bit for bit (0.125 Hz is within 1 % of every
    frequency above 12.5 Hz). Over 15-4500 Hz the step is at most 1 % of the frequency (to round-off) from the contact
    onset below the first mode to beyond the last; the paper's modes are 23.02 and 36.07 Hz free, and
    sqrt((k1 + k2) / m1) / 2 pi = 27.24 Hz with the absorber locked (its stop is on x2 against the base)."""
    problem = paper(0.003, 0.2)
    np.testing.assert_array_equal(scan_frequencies((15.0, 45.0), SCAN, problem), np.linspace(15.0, 45.0, SCAN))
    modes, engaged = resonances(problem)
    np.testing.assert_allclose(modes, [23.0221, np.sqrt(29300.0) / (2.0 * np.pi), 36.0744], rtol=1e-5)
    assert engaged.size == 0  # a rigid stop has no spring to engage
    f = scan_frequencies((15.0, 4500.0), SCAN, problem)
    assert np.all(np.diff(f) > 0.0) and f[0] == pytest.approx(15.0, rel=1e-15) and f[-1] == pytest.approx(4500.0, rel=1e-15)
    dense = (f >= 19.0) & (f <= 1.1 * 36.0744)
    assert np.max(np.diff(f)[dense[1:]] / f[1:][dense[1:]]) <= RESONANCE_SPACING * (1.0 + 1e-9)
    assert f.size < SCAN + 100  # the span of resonances, 18.6-41.6 Hz, holds 84 more


def test_the_uncovered_share_weighs_each_frequency_by_the_width_it_stands_for() -> None:
    """Evenly spaced: the share of the points (3 of 11, to 1e-12). Uneven, 0, 1, 2, 2.5, 3 Hz with 2 and 2.5 Hz
    uncovered: each point stands for half the steps to its neighbours, the ends a whole step, (0.75 + 0.5) / 3.75."""
    covered = np.ones(11, dtype=bool)
    covered[[0, 4, 5]] = False
    assert uncovered_share(np.linspace(10.0, 20.0, 11), covered) == pytest.approx(3.0 / 11.0, rel=1e-12)
    share = uncovered_share(np.array([0.0, 1.0, 2.0, 2.5, 3.0]), np.array([True, True, False, False, True]))
    assert share == pytest.approx(1.25 / 3.75, rel=1e-12)
