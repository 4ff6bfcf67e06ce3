"""The one-impact branch of the paper's system by continuation, against the closed form (issue 11, item 7).

PAPER_SYSTEM, Delta = 3 mm, q = 10 N, R = 0.2, 15-45 Hz: each band's branch is continued both ways from the closed-form
orbit, around the fold at the band's end and down the unstable root of eq. 16 to the grazing points at both ends,
where the impact velocity vanishes (q |H12| = Delta). Every point must be the closed-form orbit (eqs. 15-18, either
root), its multipliers those of :mod:`vibroimpact.analysis.stability`, the folds the zeros of the discriminant of
eq. 16, the Neimark-Sacker points the crossings of the Floquet modulus through 1.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.analysis.stability import floquet_multipliers
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.engines.registry import make_engine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.bifurcations import switch_period_doubling
from vibroimpact.orbits.branch import Iterated
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap, closed_form_state, section_phase, with_impulse
from vibroimpact.orbits.orbit_measures import orbit_measures
from vibroimpact.orbits.shooting import shoot

pytestmark = [pytest.mark.slow, pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")]

DELTA, Q, R = 3e-3, 10.0, 0.2
BANDS = {"low": ((19.0, 29.0), 24.0), "high": ((33.0, 45.0), 37.0)}


def _problem(frequency: float, band: tuple[float, float], delta: float = DELTA, restitution: float = R) -> ImpactProblem:
    base = ImpactProblem(PAPER_SYSTEM, RigidStop(delta, restitution), HarmonicForce(Q, frequency))
    phase = section_phase(base, np.linspace(*band, 400))  # the strobe away from every impact of the band
    return ImpactProblem(PAPER_SYSTEM, RigidStop(delta, restitution), HarmonicForce(Q, frequency, phase))


def _roots(f: float | np.ndarray, delta: float = DELTA, restitution: float = R):
    """Both roots of the paper's eq. 16 (corrected) and its discriminant at frequency f [Hz], with the general closed
    form's orbit there (:func:`solve_impact_orbit`, into which :func:`with_impulse` puts either root): the paper's
    formula checks the general path."""
    omega = 2.0 * np.pi * np.asarray(f, dtype=float)
    sol = solve_one_impact(PAPER_SYSTEM, omega=omega, clearance=delta, restitution=restitution, amplitude=Q)
    c = (1.0 / (PAPER_SYSTEM.m2 * (1.0 + restitution)) + sol.chi_rate_before) / sol.omega
    a = Q * np.abs(PAPER_SYSTEM.receptances(sol.omega).h12)
    quad_a, quad_b = c**2 + sol.chi0**2, delta * sol.chi0
    disc = quad_a * a**2 - (c * delta) ** 2
    root = np.sqrt(np.maximum(disc, 0.0))
    orbit = solve_impact_orbit(ImpactProblem(PAPER_SYSTEM, RigidStop(delta, restitution), HarmonicForce(Q, float(np.ravel(f)[0]))), omega=omega, clearance=delta, restitution=restitution, amplitude=Q)
    return orbit, (-quad_b + root) / quad_a, (-quad_b - root) / quad_a, disc


@pytest.fixture(scope="module")
def branches():
    out = {}
    for name, (band, f0) in BANDS.items():
        problem = _problem(f0, band)
        system = ImpactMap(problem)
        orbit = shoot(system, closed_form_state(problem), system.parameters)
        out[name] = (system, continue_branch(system, orbit, "frequency", ContinuationSettings(lower=15.0, upper=45.0, stop_at_grazing=True)))
    return out


def test_each_band_runs_from_grazing_around_the_fold_to_grazing(branches) -> None:
    for system, branch in branches.values():
        assert branch.end == "grazing, grazing"
        assert set(branch.impacts) == {1}
        kinds = [s.kind for s in branch.special_points]
        assert kinds[0] == "grazing" and kinds[-1] == "grazing" and kinds.count("fold") == 1
        assert branch.stable.any() and (~branch.stable).any()


@pytest.fixture(scope="module")
def strobe_at_zero():
    """The first band's branch from 25 Hz with default settings and the force's phase 0: the strobe no one chose, which
    an impact crosses near 22.96 Hz (the map jumps there; the continuation must move its strobe to go on)."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(DELTA, R), HarmonicForce(Q, 25.0))
    system = ImpactMap(problem)
    return system, continue_branch(system, shoot(system, closed_form_state(problem), system.parameters), "frequency")


def test_the_branch_moves_its_strobe_past_an_impact(branches, strobe_at_zero) -> None:
    """Default settings from 25 Hz, strobe at phase 0: the whole first-band branch (20.618-26.703 Hz, its
    Neimark-Sacker point at 21.205 Hz), the strobe moved where the impact crossed it, and on through both grazing
    points onto the contact-free orbit, which ends the branch where it leaves the stop behind (below the band); above
    it, through the second band's onset at 33.972 Hz onto its one-impact orbit (on the closed-form orbits born there),
    around its fold at 40.17 Hz and down to its onset at 37.499 Hz, contact-free beyond."""
    system, branch = strobe_at_zero
    assert branch.end == "clear, clear"
    assert len({round(o.parameter("phase"), 9) for o in branch.orbits}) > 1, "the strobe was moved"
    impacting = branch.values[branch.impacts == 1]
    first, second = impacting[impacting < 30.0], impacting[impacting > 30.0]
    assert first.min() == pytest.approx(20.618, abs=1e-3) and first.max() == pytest.approx(26.703, abs=1e-3)
    assert second.min() == pytest.approx(33.972218, abs=1e-3) and second.max() == pytest.approx(40.1717, abs=1e-3)
    _system, chosen = branches["low"]  # the same band with the strobe chosen over it beforehand
    for kind in ("grazing", "fold", "period_doubling", "neimark_sacker"):
        got = sorted(p.value for p in branch.special(kind) if p.value < 30.0)
        want = sorted(p.value for p in chosen.special(kind))
        assert len(got) == len(want) and np.allclose(got, want, rtol=1e-8, atol=0.0), kind
    assert sorted(round(p.value, 3) for p in branch.special("neimark_sacker")) == [21.205, 37.574, 39.026, 39.563]
    assert sorted(round(p.value, 6) for p in branch.special("grazing") if p.value > 30.0) == [33.972218, 37.498585]  # README
    _check_closed_form(system, branch)


def test_every_point_is_the_closed_form_orbit(branches) -> None:
    for system, branch in branches.values():
        _check_closed_form(system, branch)


def _check_closed_form(system: ImpactMap, branch) -> None:
    """Every point of ``branch`` is the closed-form orbit (either root of eq. 16) at its own strobe: impulse, |X1|,
    |X2|, state and multipliers."""
    if True:
        impulses = []
        for orbit in branch.orbits:
            f = orbit.parameter("frequency")
            if orbit.impacts == 0:  # the contact-free orbit: the linear steady state
                linear = system.linear_orbit(orbit.parameters)
                assert linear[1] >= -1e-9 and np.max(np.abs(orbit.state - linear[0]) / system.state_scale) < 1e-9
                continue
            measures = orbit_measures(system, orbit)
            assert measures.impulses.size == 1
            impulse = measures.impulses[0]
            _sol, plus, minus, _disc = _roots(f)  # the paper's eq. 16
            problem = system.problem_at(orbit.parameters)
            closed = with_impulse(solve_impact_orbit(problem), float(plus if abs(plus - impulse) < abs(minus - impulse) else minus))
            impulses.append((impulse, float(closed.impulse)))
            scale = abs(float(closed.impulse)) + 1e-2 * abs(float(plus))
            # a point within 1e-3 of a grazing point's speed margin (the last one the locator corrected, to the
            # corrector's 1e-11) has its impulse conditioned by one over the margin: 1e-7 there
            near = 100.0 if orbit.hybrid.speed_margin < 1e-3 else max(1.0, 0.1 / orbit.hybrid.speed_margin)  # (and 1 / margin beyond)
            # at the grazing point itself (margin below 1e-7) the impulse grows like the square root of the distance
            # to it: a parameter one rounding error away changes it by about sqrt(eps) of the force's impulse per
            # radian, q / w [N s]; compared to that
            touching = 1e-6 * Q / (2.0 * np.pi * f) if orbit.hybrid.speed_margin < 1e-7 else 0.0
            if touching:  # the grazing orbit: the linear one touching the stop (eq. 16 has a double root there)
                linear = system.linear_orbit(orbit.parameters)
                assert abs(linear[1]) < 1e-6 and np.max(np.abs(orbit.state - linear[0]) / system.state_scale) < 1e-6
                assert impulse < touching
                continue
            # the closed-form orbits born at an onset, 1e-6 ... 1e-3 from grazing: a flight that would reach a depth
            # of margin^2 L beyond the stop, its impact speed measured by re-integration to round-off over that
            depth = 1e-15 / orbit.hybrid.speed_margin**2  # (1e-17 ... 1e-16 measured: a factor 10 over it)
            assert impulse == pytest.approx(float(closed.impulse), rel=1e-9 * near + depth, abs=1e-9 * near * scale + touching)
            x1, x2 = np.abs(closed.harmonics()).reshape(-1)[:2]
            rel = 1e-7 if touching else 1e-9 + depth  # (that impulse's own effect on the motion)
            assert measures.x1_amplitude == pytest.approx(x1, rel=rel)
            assert measures.x2_amplitude == pytest.approx(x2, rel=rel)
            state = closed_form_state(problem, closed)
            assert np.max(np.abs(orbit.state - state) / system.state_scale) < rel
            expected = np.sort_complex(floquet_multipliers(closed).ravel())
            got = np.sort_complex(orbit.multipliers)
            # next to a grazing point the multipliers grow like 1 / J and both computations lose digits with them
            tolerance = (1e-9 * near + depth) * max(1.0, float(np.max(np.abs(got)))) * max(1.0, 1e-2 * abs(float(plus)) / impulse)
            if not touching:  # (there the multipliers grow like one over that impulse)
                assert np.max(np.abs(got - expected)) < tolerance
        impulses = np.array(impulses)
        assert np.max(np.abs(impulses[:, 0] - impulses[:, 1])) < 1e-9 * np.max(impulses[:, 1]) + 1e-6 * Q / (2.0 * np.pi * 15.0)


def test_folds_are_the_zeros_of_the_discriminant(branches) -> None:
    for system, branch in branches.values():
        (fold,) = branch.special("fold")
        exact = brentq(lambda f: float(_roots(f)[3]), fold.value - 0.05, fold.value + 0.05, xtol=1e-14, rtol=1e-15)
        assert fold.value == pytest.approx(exact, rel=1e-8)
        assert np.min(np.abs(fold.orbit.multipliers - 1.0)) < 1e-6


def test_grazing_points_are_where_the_linear_amplitude_reaches_the_clearance(branches) -> None:
    def gap(f: float) -> float:
        return Q * abs(complex(PAPER_SYSTEM.receptances(2.0 * np.pi * f).h12)) - DELTA

    for system, branch in branches.values():
        for point in branch.special("grazing"):
            exact = brentq(gap, point.value - 0.05, point.value + 0.05, xtol=1e-14, rtol=1e-15)
            assert point.value == pytest.approx(exact, rel=1e-8)
            assert point.continues and point.impacts_after == 0  # the linear orbit carries on


def _complex_pair_crossings(low: float, high: float, root: int) -> list[float]:
    """Frequencies in [low, high] where a complex pair of one root's Floquet multipliers crosses the unit circle."""

    def excess(f: float | np.ndarray) -> np.ndarray:
        sol, plus, minus, _ = _roots(f)
        mu = np.atleast_2d(floquet_multipliers(with_impulse(sol, (plus, minus)[root])))
        pair = np.where(np.abs(mu.imag) > 1e-9, np.abs(mu), -np.inf)
        return np.max(pair, axis=-1) - 1.0

    grid = np.arange(low, high, 1e-3)
    values = excess(grid)
    crossings = []
    for k in np.flatnonzero(np.isfinite(values[:-1]) & np.isfinite(values[1:]) & (np.sign(values[:-1]) * np.sign(values[1:]) < 0)):
        crossings.append(brentq(lambda f: float(excess(f)[0]), grid[k], grid[k + 1], xtol=1e-14, rtol=1e-15))
    return crossings


def test_neimark_sacker_points_are_the_crossings_of_the_floquet_modulus(branches) -> None:
    lost = []
    for system, branch in branches.values():
        fold = branch.special("fold")[0].value
        graze = sorted(p.value for p in branch.special("grazing"))
        on_branch = _complex_pair_crossings(graze[0] + 1e-6, fold - 1e-6, 0) + _complex_pair_crossings(graze[-1] + 1e-6, fold - 1e-6, 1)
        torus = [p.value for p in branch.special("neimark_sacker")]
        assert len(torus) == len(on_branch)
        for value in on_branch:
            assert min(abs(t - value) for t in torus) < 1e-8 * value
        lost += [p.value for p in branch.special("neimark_sacker") if np.sum(np.abs(p.orbit.multipliers) > 1.0 - 1e-6) == 2]
        # where the stable orbit is lost, the largest Floquet modulus of the closed form crosses 1 (fine grid)
        grid = np.arange(graze[0] + 1e-6, fold - 1e-6, 1e-3)
        sol, plus, _minus, _ = _roots(grid)
        modulus = np.max(np.abs(floquet_multipliers(with_impulse(sol, plus))), axis=-1)
        crossing = grid[np.flatnonzero(np.diff(np.sign(modulus - 1.0)))]
        for value in crossing:
            assert min(abs(t - value) for t in torus) < 2e-3
    # the stable orbit loses stability near 21.2 and 39.0 Hz through a torus bifurcation
    assert sorted(round(v, 1) for v in lost) == [21.2, 39.0]


def test_period_doubling_and_its_period_two_branch_confirmed_by_momentary() -> None:
    # Delta = 1 mm, R = 0.2: the one-impact orbit doubles its period near 17.58 Hz
    band = (15.5, 19.0)
    problem = _problem(17.8, band, delta=1e-3)
    system = ImpactMap(problem)
    branch = continue_branch(system, shoot(system, closed_form_state(problem), system.parameters), "frequency", ContinuationSettings(lower=15.0, upper=20.0, stop_at_grazing=True))
    # the orbit is stable between two period doublings, near 17.576 Hz and just before it grazes near 17.96 Hz
    assert len(branch.special("period_doubling")) == 2
    doubling = min(branch.special("period_doubling"), key=lambda p: p.value)
    assert np.min(np.abs(doubling.orbit.multipliers + 1.0)) < 1e-7
    two = switch_period_doubling(system, doubling)
    second = continue_branch(Iterated(system, 2), two, "frequency", ContinuationSettings(lower=15.0, upper=20.0, max_steps=400, stop_at_grazing=True))
    assert all(o.period == 2 for o in second.orbits)
    # supercritical: the stable period-two orbit lives between its fold and the period doubling, below 17.576 Hz
    stable = [o for o in second.orbits if o.stable and o.impacts == 2]
    assert stable, "a stable period-two orbit with two impacts"
    orbit = min(stable, key=lambda o: o.floquet_modulus)
    assert orbit.parameter("frequency") < doubling.value
    # time simulation with an independent engine from next to the orbit: it settles on the same period-two orbit
    momentary = make_engine("momentary")
    start = orbit.state + 1e-5 * system.state_scale
    run = momentary.integrate(system.problem_at(orbit.parameters), start, 0.0, 200)
    strobes = run.strobe_states[-20:]
    assert np.max(np.abs(strobes[2:] - strobes[:-2]) / system.state_scale) < 1e-6  # period two
    assert np.min(np.max(np.abs(strobes[1:] - strobes[:-1]) / system.state_scale, axis=1)) > 1e-2  # not period one
    other = Iterated(system, 1).evaluate(orbit.state, orbit.parameters).image
    assert min(np.max(np.abs(strobes[-1] - orbit.state) / system.state_scale), np.max(np.abs(strobes[-1] - other) / system.state_scale)) < 1e-6


def test_fold_and_torus_curves_in_frequency_and_clearance(branches) -> None:
    from vibroimpact.orbits.continuation import continue_special_point

    system, branch = branches["low"]
    settings = ContinuationSettings(step=0.05, max_steps=40)
    fold = continue_special_point(system, branch.special("fold")[0], "clearance", settings, bounds={"clearance": (2e-3, 4e-3)})
    assert fold.values("clearance").max() == pytest.approx(4e-3) and fold.values("clearance").min() < 2.5e-3
    for orbit in fold.orbits:  # on the fold curve the discriminant of eq. 16 vanishes at each clearance
        f, delta = orbit.parameter("frequency"), orbit.parameter("clearance")
        sol, plus, _minus, disc = _roots(f, delta=delta)
        c = (1.0 / (PAPER_SYSTEM.m2 * (1.0 + R)) + sol.chi_rate_before) / sol.omega
        assert abs(float(disc)) < 1e-9 * float((c**2 + sol.chi0**2) * sol.linear_amplitude**2)
        assert np.min(np.abs(orbit.multipliers - 1.0)) < 1e-8
    torus = continue_special_point(system, branch.special("neimark_sacker")[0], "clearance", settings, bounds={"clearance": (2e-3, 4e-3)})
    assert len(torus.orbits) > 10
    for orbit in torus.orbits:  # a complex pair on the unit circle all along
        mu = orbit.multipliers
        pair = mu[np.abs(mu.imag) > 1e-9]
        assert pair.size == 2 and np.abs(pair) == pytest.approx([1.0, 1.0], abs=1e-8)
