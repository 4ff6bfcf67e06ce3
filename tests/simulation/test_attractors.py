"""Every attractor over a band by brute force (issue 32): the largest |X1| a design shows, against the closed forms
where they answer, and against the continuation-based worst case (:func:`vibroimpact.orbits.worst_case.worst_response`)
on designs with coexisting motions, where brute force also finds what the continuation does not search.

A maximum found on a grid of spacing h lies within h / 2 of a smooth peak's frequency, so it is low by at most
|X''| h^2 / 8 (X'' the curvature of |X1| in frequency there, estimated from the grid's second difference at the
largest point); the tolerances below are that bound with a margin of 1.5 for the curvature's own variation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.linear_optimum import band_peak, nishihara_asami
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem
from vibroimpact.simulation.attractors import MOTION_CLASSES
from vibroimpact.simulation.band_attractors import AttractorSweep, attractor_labels, attractor_starts, band_attractors
from vibroimpact.simulation.harmonics import gaps, linear_state

pytestmark = pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")


def paper(clearance: float, restitution: float) -> ImpactProblem:
    """The paper's layout (m1 = 1 kg, m2 = 0.1 kg, k1 = 25000, k2 = 4300 N/m, q = 10 N) with its stop on the absorber."""
    return ImpactProblem(PAPER_SYSTEM, RigidStop(clearance, restitution), HarmonicForce(10.0, 25.0))


def grid_bound(sweep: AttractorSweep) -> float:
    """|X''| h^2 / 8 at the grid's largest point [m] (module docstring), X'' from the grid's second difference."""
    largest = sweep.largest()
    k = int(np.nanargmax(largest))
    h = float(sweep.frequency[1] - sweep.frequency[0])
    curvature = (largest[k - 1] - 2.0 * largest[k] + largest[k + 1]) / h**2
    return abs(float(curvature)) * h * h / 8.0


def one_impact_maximum(problem: ImpactProblem, low: float, high: float) -> float:
    """The largest |X1| of the closed-form one-impact orbit (stable root of eq. 16) in [low, high] Hz [m]."""
    found = minimize_scalar(lambda f: -float(np.abs(solve_impact_orbit(problem, frequency=np.array([f]), root="+").harmonics())[0, 0]),
                            bounds=(low, high), method="bounded", options={"xatol": 1e-12})  # fmt: skip
    return -float(found.fun)


# --------------------------------------------------------------------------------------------------------------------
# The default tier: closed forms as references, a few seconds each.
# --------------------------------------------------------------------------------------------------------------------

def test_with_the_stop_out_of_reach_the_maximum_is_the_linear_band_peak() -> None:
    """The H-infinity absorber of mu = 0.1 on the paper's primary, its stop 50 mm away: every run at every frequency
    is contact-free, the engine's measured |X1| is the closed form's (to 1e-9, transients included: the absorber damps
    them within the 100 periods dropped), and the largest is the closed form's band peak (1.8096 mm at 21.32 Hz)
    within the grid's resolution (measured: 2.5e-3 relative low on a 0.5 Hz grid)."""
    tuning, damping = nishihara_asami(0.1)
    w_a = tuning * math.sqrt(25_000.0)
    system = TwoDofSystem(m1=1.0, m2=0.1, k1=25_000.0, k2=0.1 * w_a**2, b1=0.8, b2=2.0 * 0.1 * damping * w_a)
    problem = ImpactProblem(system, RigidStop(0.05, 0.5), HarmonicForce(10.0, 25.0))
    sweep = band_attractors(problem, (15.0, 40.0), frequencies=51, starts=4, transient=100)
    peak = band_peak(system, 10.0, (15.0, 40.0))
    assert np.all(sweep.regime == MOTION_CLASSES.index("linear"))
    np.testing.assert_allclose(sweep.measured, sweep.amplitude, rtol=1e-9)
    assert sweep.maximum.motion == "contact-free" and sweep.maximum.period == 1
    assert 0.0 <= peak.amplitude - sweep.maximum.amplitude <= 1.5 * grid_bound(sweep)
    assert sweep.maximum.frequency == pytest.approx(peak.frequency, abs=0.25)  # within h / 2
    assert sweep.maximum.peak == pytest.approx(sweep.maximum.amplitude, rel=1e-4)  # a harmonic motion: its peak is |X1|


def test_the_paper_design_peaks_on_the_one_impact_orbit() -> None:
    """Delta = 3 mm, R = 0.2 over 24.5-26 Hz (0.1 Hz grid): every run settles on the one-impact orbit, and the largest
    |X1| is the closed form's maximum (2.7526 mm at 25.1612 Hz) within the grid's resolution."""
    problem = paper(0.003, 0.2)
    sweep = band_attractors(problem, (24.5, 26.0), frequencies=16, starts=3)
    exact = one_impact_maximum(problem, 25.0, 25.3)
    assert sweep.runs == ("up", "down", "linear", "rest", "random 1")
    assert np.all(sweep.regime == MOTION_CLASSES.index("one_impact"))
    top = sweep.maximum
    assert top.motion == "period 1, 1 impact" and top.impacts == pytest.approx(1.0)
    assert 0.0 <= exact - top.amplitude <= 1.5 * grid_bound(sweep)
    assert top.peak > top.amplitude  # the impact's harmonics add to the fundamental's peak


def test_the_starts_lie_inside_the_stops_and_are_seeded() -> None:
    """At 22.5 Hz the paper's linear motion is beyond the 3 mm stop at t = 0: the linear start is that state shrunk
    about rest (here the origin) to just inside the stop; rest; random states, the same for the same seed."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(0.003, 0.2), HarmonicForce(10.0, 22.5))
    starts = attractor_starts(problem, 5, np.random.default_rng(7))
    again = attractor_starts(problem, 5, np.random.default_rng(7))
    other = attractor_starts(problem, 5, np.random.default_rng(8))
    assert [label for label, _ in starts] == list(attractor_labels(5)) == ["linear", "rest", "random 1", "random 2", "random 3"]
    assert all(np.all(gaps(problem, state) > 0.0) for _, state in starts)
    full = linear_state(problem).state(problem.omega)
    assert gaps(problem, full)[0] < 0.0
    ratio = starts[0][1] / full
    assert 0.0 < ratio[0] < 1.0 and np.allclose(ratio, ratio[0], rtol=1e-12)
    assert gaps(problem, starts[0][1])[0] == pytest.approx(0.001 * 0.003, rel=1e-9)  # INSIDE of the way to the stop
    assert np.all(starts[1][1] == 0.0)  # exact: the paper's rest state
    assert all(np.array_equal(a, b) for (_, a), (_, b) in zip(starts, again))
    assert not np.allclose(starts[2][1], other[2][1])


def test_arguments_and_shapes_are_checked() -> None:
    problem = paper(0.003, 0.2)
    for band, frequencies, starts in (((25.0, 24.0), 11, 2), ((0.0, 25.0), 11, 2), ((24.0, 25.0), 1, 2), ((24.0, 25.0), 11, -1)):
        with pytest.raises(ValueError, match="expected 0 < low < high"):
            band_attractors(problem, band, frequencies=frequencies, starts=starts)
    with pytest.raises(ValueError, match="16 strobes"):
        band_attractors(problem, (25.0, 25.2), strobes=8)
    sweep = band_attractors(problem, (25.0, 25.2), frequencies=2, starts=0, transient=20, strobes=16)
    assert sweep.runs == ("up", "down") and sweep.state.shape == (2, 2, 4)
    with pytest.raises(ValueError, match="amplitude: expected shape"):
        AttractorSweep(sweep.frequency, sweep.runs, sweep.amplitude[:1], sweep.measured, sweep.regime, sweep.period, sweep.impacts, sweep.lyapunov, sweep.state, sweep.maximum)


# --------------------------------------------------------------------------------------------------------------------
# The slow tier: the dense brute force against worst_response over the paper's band, 15-45 Hz.
# --------------------------------------------------------------------------------------------------------------------

#: Grid of the validation: 301 frequencies over 15-45 Hz, h = 0.1 Hz; two sweeps and four starts at each.
BAND, GRID = (15.0, 45.0), 301


@pytest.mark.slow
@pytest.mark.parametrize(("clearance", "restitution"), [(0.003, 0.2), (0.004, 0.5)])
def test_brute_force_agrees_with_the_worst_case_where_the_one_impact_orbit_sets_it(clearance: float, restitution: float) -> None:
    """Designs where contact-free and one-impact motions coexist (and, at R = 0.2, non-periodic and period-k
    attractors): the largest stable |X1| over every attractor found is the one-impact orbit's, the continuation's
    maximum to within the grid's resolution (measured: Delta = 3 mm, R = 0.2: 2.752335 mm at 25.2 Hz against
    2.752613 mm at 25.1612 Hz, 1.0e-4 low; Delta = 4 mm, R = 0.5: 3.874702 mm at 26.2 Hz against 3.876266 mm at
    26.2408 Hz, 4.0e-4 low), never above it."""
    from vibroimpact.orbits.worst_case import worst_response

    problem = paper(clearance, restitution)
    worst = worst_response(problem, BAND)
    sweep = band_attractors(problem, BAND, frequencies=GRID)
    top = sweep.maximum
    assert worst.motion.startswith("1 impact per period") and top.motion == "period 1, 1 impact"
    assert 0.0 <= worst.amplitude - top.amplitude <= 1.5 * grid_bound(sweep) + 1e-6 * worst.amplitude
    assert top.frequency == pytest.approx(worst.frequency, abs=0.1)  # the largest grid point: within h of the peak
    coexisting = [{MOTION_CLASSES[int(c)] for c in row} for row in sweep.regime]
    assert sum({"linear", "one_impact"} <= kinds for kinds in coexisting) >= 5  # the brute force saw both motions


@pytest.mark.slow
def test_brute_force_finds_a_larger_two_impact_orbit_than_the_worst_case_searches() -> None:
    """Delta = 3 mm, R = 0.8: worst_response's largest is the one-impact orbit's 7.1636 mm at 27.65 Hz, but a stable
    period-1 orbit with two impacts a period (not continued from any closed-form start) reaches 9.4014 mm on the grid
    at 25.8 Hz (its branch's exact maximum: 9.4162 mm at 25.7766 Hz, an interior maximum just below its fold at
    25.9326 Hz). The grid's orbit is a stable fixed point of the exact map: shot from the sweep's end state, it is
    the same orbit (|X1| to 1e-6) with every multiplier inside the unit circle."""
    from vibroimpact.orbits.maps import ImpactMap
    from vibroimpact.orbits.orbit_measures import orbit_measures
    from vibroimpact.orbits.shooting import shoot
    from vibroimpact.orbits.worst_case import worst_response
    from vibroimpact.simulation.attractors import at_frequency

    problem = paper(0.003, 0.8)
    worst = worst_response(problem, BAND)
    sweep = band_attractors(problem, BAND, frequencies=GRID)
    top = sweep.maximum
    assert worst.motion.startswith("1 impact per period") and worst.amplitude == pytest.approx(7.1636e-3, rel=1e-4)
    assert top.motion == "period 1, 2 impacts" and top.regime == "other_periodic"
    assert 25.6 <= top.frequency <= 26.0 and top.amplitude > 1.25 * worst.amplitude
    system = ImpactMap(at_frequency(problem, top.frequency), top.period)
    orbit = shoot(system, np.array(top.state), system.parameters)
    measures = orbit_measures(system, orbit)
    assert orbit.stable and measures.impulses.size == 2
    assert measures.amplitudes[0] == pytest.approx(top.amplitude, rel=1e-6)
