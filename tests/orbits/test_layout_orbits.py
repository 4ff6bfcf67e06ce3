"""Shooting, continuation and bifurcations on general structures and stop layouts (issue 12, item 2), against the
closed forms of vibroimpact.analysis and published results:

* a relative stop (Ormondroyd & Den Hartog's 1928 layout) and a symmetric two-sided stop: the fixed points of the
  exact stroboscopic map are the closed-form orbits (states 1e-9, multipliers 1e-8);
* the grazing boundary of a forced linear oscillator x'' + c x' + k x = A cos(w t) (unit mass) with a stop at d: the
  impacting orbit is born at A = d sqrt((k - w^2)^2 + (c w)^2) (its impact speed vanishes there), located by
  continuation in A to 1e-8;
* Budd & Dux (Phil. Trans. R. Soc. A 347 (1994) 365), x'' + x = cos(w t), x <= sigma, x' -> -r x': the period-one
  orbit continued in sigma (negative included) has its impact velocity on the ellipse
  (sigma + c V / 2)^2 + ((1 - r) V / (2 w))^2 = gamma^2 at every point (1e-8), and its period doubling is where the
  impact map's trace is -(1 + r^2) (tests/analysis/test_budd_dux_closed_form.py derives sigma_pd), to 1e-8.

The engine-free parts (stop selection, scales, section phases, the Lyapunov start) always run; the rest needs the
exact engine on general problems and is skipped until it has it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.stability import floquet_multipliers
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.bifurcations import switch_period_doubling
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.lyapunov import _inside, state_scales
from vibroimpact.orbits.maps import ImpactMap, closed_form_state, section_phase
from vibroimpact.orbits.orbit_measures import orbit_measures
from vibroimpact.orbits.shooting import shoot


def _general_engine() -> bool:
    """Does the exact engine take a structure given by matrices (N = 1, one stop)?"""
    problem = ImpactProblem(LinearStructure([[1.0]], [[1.0]], [[0.1]]), (Stop(RigidStop(1.0, 0.5), 0),), HarmonicForce(0.1, 0.2, weights=(1.0,)))
    try:
        ExactEngine().strobe_map(problem, np.array([0.0, 0.0]), 0.0, 1)
    except Exception:  # noqa: BLE001 - any failure means: not there yet
        return False
    return True


needs_engine = pytest.mark.skipif(not _general_engine(), reason="needs the exact engine on general structures and stops")

OSCILLATOR = LinearStructure([[1.0]], [[1.0]], [[0.0]], ("x",))


def relative(frequency: float, phase: float = 0.3) -> ImpactProblem:
    return ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.6), 1, other=0),), HarmonicForce(10.0, frequency, phase))


def two_sided(frequency: float, phase: float = 0.3) -> ImpactProblem:
    stops = (Stop(RigidStop(3e-3, 0.6), 1), Stop(RigidStop(3e-3, 0.6), 1, side="lower"))
    return ImpactProblem(PAPER_SYSTEM.structure, stops, HarmonicForce(10.0, frequency, phase))


def budd_dux(sigma: float, w: float = 2.8, r: float = 0.8, phase: float = 0.0) -> ImpactProblem:
    return ImpactProblem(OSCILLATOR, (Stop(RigidStop(sigma, r), 0),), HarmonicForce(1.0, w / (2 * math.pi), phase))


# ------------------------------------------------------------------------------------------------ engine-free
def test_stop_selection_and_scales() -> None:
    """Parameters set every stop of a symmetric pair ('all' by default), or the one chosen; differing stops need a
    choice; the map's state is 2N wide; a chosen stop's clearance changes that stop only."""
    pair = ImpactMap(two_sided(25.0))
    assert pair.stops == (0, 1) and pair.dimension == 4 and pair.state_scale.shape == (4,)
    moved = pair.problem_at(pair.parameters + np.array([0.0, 0.0, 1e-3, 0.0, 0.0]))
    assert moved.clearances() == pytest.approx([4e-3, 4e-3])
    mixed = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.6), 1), Stop(RigidStop(2e-3, 0.6), 0, side="lower")), HarmonicForce(10.0, 25.0))
    with pytest.raises(ValueError, match="choose"):
        ImpactMap(mixed)
    with pytest.raises(ValueError, match="out of range"):
        ImpactMap(mixed, stop=2)
    second = ImpactMap(mixed, stop=1)
    assert second.parameters[2] == pytest.approx(2e-3)
    changed = second.problem_at(second.parameters + np.array([0.0, 0.0, 1e-3, 0.0, 0.0]))
    assert changed.clearances() == pytest.approx([3e-3, 3e-3])
    weighted = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.6), 1),), HarmonicForce(10.0, 25.0, 0.4, weights=(0.5, 1.0), static=(1.0, 0.0)))
    kept = ImpactMap(weighted).problem_at(np.array([30.0, 0.5, 2e-3, 7.0, weighted.phase])).harmonic
    assert (kept.weights, kept.static, kept.phase, kept.amplitude, kept.frequency) == ((0.5, 1.0), (1.0, 0.0), 0.4, 7.0, 30.0)
    one = ImpactMap(budd_dux(0.05))
    assert one.dimension == 2 and state_scales(budd_dux(0.05)).shape == (2,)


def test_evaluation_refuses_a_start_inside_any_stop() -> None:
    """A state through the lower stop of a pair has no image (NaN), without calling the engine."""
    mapping = ImpactMap(two_sided(25.0))
    out = mapping.evaluate(np.array([0.0, -4e-3, 0.0, 0.0]), mapping.parameters)
    assert out.image.shape == (4,) and np.all(np.isnan(out.image)) and out.hybrid is None


def test_lyapunov_perturbation_is_mirrored_off_a_relative_stop() -> None:
    """Next to the relative stop (x2 - x1 = Delta - 1e-12), a perturbation that would close the gap is mirrored in the
    stop's plane: it opens the gap by as much."""
    problem = relative(25.0)
    scale = state_scales(problem)
    y = np.array([0.0, 3e-3 - 1e-12, 0.0, 0.0])
    d = np.array([-1e-6, 1e-6, 0.0, 0.0])
    n = problem.normals()[0]
    turned = _inside(problem, y, d, scale)
    assert n @ (turned[:2] * scale[:2]) == pytest.approx(-(n @ (d[:2] * scale[:2])))
    assert 3e-3 - n @ (y[:2] + turned[:2] * scale[:2]) > 0.0


@pytest.mark.parametrize("make", [relative, two_sided])
def test_section_phase_keeps_the_strobe_clear_of_the_impacts(make) -> None:
    """The phase section_phase returns puts every closed-form impact (both roots, both stops) of the band at least
    a few percent of the period away from t = 0 (mod T)."""
    band = np.linspace(22.0, 24.5, 60)
    phase = section_phase(make(23.0), band)
    moved = make(23.0, phase)
    fractions = []
    for root in ("+", "-"):
        orbit = solve_impact_orbit(moved, omega=2 * np.pi * band, root=root)
        f = (orbit.impact_time / orbit.period)[orbit.exists]
        fractions += [f, (f + 0.5) % 1.0] if orbit.two_sided else [f]
    f = np.concatenate(fractions)
    assert f.size > 0 and np.min(np.minimum(f, 1.0 - f)) > 0.02


def test_closed_form_state_is_the_orbit_at_the_problems_time_zero() -> None:
    """closed_form_state on a general layout is the closed-form orbit's state at t = 0 (its impact time shifted)."""
    problem = relative(42.0)
    orbit = solve_impact_orbit(problem)
    state = closed_form_state(problem)
    np.testing.assert_allclose(state, orbit.state(np.array([(-orbit.impact_time) % orbit.period]))[0], rtol=1e-13, atol=1e-18)
    assert np.all(np.isnan(closed_form_state(budd_dux(10.0))))  # sigma beyond |gamma|: no impacting orbit


# ------------------------------------------------------------------------------------------------ with the engine
@needs_engine
@pytest.mark.parametrize(("make", "frequency"), [(relative, 42.0), (two_sided, 25.0), (two_sided, 40.0)])
def test_fixed_points_are_the_closed_form_orbits(make, frequency: float) -> None:
    """Shooting on the exact map from the closed-form state converges at once to it (1e-9 of the state scale); the
    map's multipliers are the closed form's (1e-8 of the largest); the impulses are the closed form's (1e-9)."""
    problem = make(frequency)
    mapping = ImpactMap(problem)
    start = closed_form_state(problem)
    orbit = shoot(mapping, start, mapping.parameters)
    assert np.max(np.abs(orbit.state - start) / mapping.state_scale) < 1e-9
    expected = floquet_multipliers(solve_impact_orbit(problem))
    nearest = np.min(np.abs(orbit.multipliers[:, None] - expected[None, :]), axis=-1)
    assert np.max(nearest) < 1e-8 * max(1.0, float(np.max(np.abs(expected))))
    measures = orbit_measures(mapping, orbit)
    assert measures.impulses == pytest.approx(np.full(measures.impulses.size, float(solve_impact_orbit(problem).impulse)), rel=1e-9)


@needs_engine
@pytest.mark.parametrize(("make", "frequency"), [(relative, 22.5), (relative, 42.0), (two_sided, 25.0), (two_sided, 23.5)])
def test_exact_engine_stays_on_the_closed_form_orbit_and_is_attracted(make, frequency: float) -> None:
    """The exact engine run from the closed-form state repeats its strobes to 1e-9 of the state scale over 20 periods,
    with the closed form's impulse at each impact (1e-9); these orbits are stable (Floquet modulus mu < 1), and a
    start 1e-3 off returns to within 100 mu^600 1e-3 (or the round-off floor 1e-11) after 600 periods."""
    problem = make(frequency)
    closed = solve_impact_orbit(problem)
    modulus = float(np.max(np.abs(floquet_multipliers(closed))))
    assert closed.admissible() and modulus < 0.99
    engine = ExactEngine()
    start = closed_form_state(problem)
    scale = ImpactMap(problem).state_scale
    run = engine.integrate(problem, start, 0.0, 20)
    assert np.max(np.abs(run.strobe_states - start) / scale) < 1e-9
    assert run.impulses.size == 20 * closed.impacts_per_period
    np.testing.assert_allclose(run.impulses, float(closed.impulse), rtol=1e-9)
    perturbed = engine.integrate(problem, start + 1e-3 * scale * np.array([0.3, -0.5, 0.2, 0.4]), 0.0, 600)
    assert np.max(np.abs(perturbed.final_state - start) / scale) < max(100.0 * modulus**600 * 1e-3, 1e-11)


@needs_engine
def test_grazing_boundary_of_the_forced_oscillator() -> None:
    """x'' + 0.5 x' + 100 x = A cos(8 t), x <= 0.01: the impacting orbit continued down in A ends at a grazing point at
    A = 0.01 sqrt((100 - 64)^2 + (0.5 * 8)^2), to 1e-8 relative."""
    structure = LinearStructure([[1.0]], [[100.0]], [[0.5]], ("x",))
    d, w = 0.01, 8.0
    expected = d * math.hypot(100.0 - w * w, 0.5 * w)
    base = ImpactProblem(structure, (Stop(RigidStop(d, 0.7), 0),), HarmonicForce(1.05 * expected, w / (2 * math.pi)))
    phase = section_phase(base, np.full(50, w / (2 * math.pi)), amplitudes=np.linspace(expected, 1.5 * expected, 50))
    problem = dataclasses.replace(base, excitation=dataclasses.replace(base.harmonic, phase=phase))
    mapping = ImpactMap(problem, parameter_scale=(1.0, 0.1, 1e-3, 0.1 * expected, 1.0))
    orbit = shoot(mapping, closed_form_state(problem), mapping.parameters)
    assert orbit.impacts == 1
    branch = continue_branch(mapping, orbit, "amplitude", ContinuationSettings(lower=0.5 * expected, upper=1.5 * expected, stop_at_grazing=True), direction=-1)
    grazing = branch.special("grazing")
    assert grazing, branch.end
    assert min(abs(point.value - expected) for point in grazing) < 1e-8 * expected


@needs_engine
def test_budd_dux_branch_lies_on_the_ellipse_and_doubles_where_predicted() -> None:
    """w = 2.8, r = 0.8, sigma from -0.15 to 0.12 (both signs): every point's impact velocity on the ellipse (1e-8 of
    gamma^2); the period doubling at sigma_pd = -0.0685756522788 (closed form) to 1e-8 relative."""
    w, r = 2.8, 0.8
    period = 2 * math.pi / w
    gamma, c = 1 / (1 - w * w), (1 + r) * math.sin(period) / (1 - math.cos(period))
    d = 1 + r * r - 2 * r * math.cos(period)
    kappa = (c * (1 - w * w) / 2 + d / ((1 + r) * math.sin(period))) / (w * w)
    sigma_pd = kappa * abs(gamma) / math.hypot(kappa + c / 2, (1 - r) / (2 * w))
    sigmas = np.linspace(-0.15, 0.12, 60)
    phase = section_phase(budd_dux(-0.12), np.full(sigmas.size, w / (2 * math.pi)), clearances=sigmas)
    problem = budd_dux(-0.12, phase=phase)
    mapping = ImpactMap(problem, parameter_scale=(1.0, 0.1, 0.01, 1.0, 1.0))
    orbit = shoot(mapping, closed_form_state(problem), mapping.parameters)
    branch = continue_branch(mapping, orbit, "clearance", ContinuationSettings(lower=-0.15, upper=0.12, stop_at_grazing=True))
    values = branch.values
    assert values.min() < -0.14 and values.max() > 0.11
    for point in branch.orbits:
        sigma = point.parameter("clearance")
        v = point.hybrid.min_impact_velocity
        residual = (sigma + c * v / 2) ** 2 + ((1 - r) * v / (2 * w)) ** 2 - gamma**2
        assert abs(residual) < 1e-8 * gamma**2
    (doubling,) = branch.special("period_doubling")
    assert doubling.value == pytest.approx(sigma_pd, rel=1e-8)
    # the period-two orbit born there: two impacts per period-two, its halves differ
    two = switch_period_doubling(mapping, doubling)
    assert two.period == 2 and two.impacts == 2
