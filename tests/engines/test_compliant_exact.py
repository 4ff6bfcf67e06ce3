"""Engine ``compliant_exact`` (the Kelvin-Voigt bumper in closed form): against the independent integration of
tests/engines/bumper_reference.py (DOP853, rtol 1e-12, explicit mode switching), the textbook collision, switches
however tangent, the exact Jacobian of its stroboscopic map, and the ``compliant`` (IDA) engine at its tolerance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.engines.compliant.model import MODE_CONTACT
from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import KelvinVoigtBumper, Stop, loss_factor_from_restitution, peak_acceleration_factor, release_time, restitution_from_loss_factor
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE
from tests.engines.bumper_reference import reference_run
from tests.engines.test_layouts_momentary import chain

ENGINE = make_engine("compliant_exact")


def paper(frequency: float, bumper: float, restitution: float | None = None, loss_factor: float | None = None, amplitude: float = PAPER_AMPLITUDE) -> ImpactProblem:
    """The paper's system and stop (Delta = 3 mm) with a bumper of ``bumper`` Hz."""
    xi = loss_factor_from_restitution(restitution) if loss_factor is None else loss_factor
    return ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(PAPER_CLEARANCE, bumper, xi), HarmonicForce(amplitude, frequency))


def two_sided() -> ImpactProblem:
    """The paper's masses with an upper bumper x2 <= 2 mm (1 kHz, R = 0.3) and a lower one x2 >= -1.5 mm (400 Hz,
    xi_b = 0.2), at 24 Hz: one contact on each per period."""
    stops = (Stop(KelvinVoigtBumper(2e-3, 1000.0, loss_factor_from_restitution(0.3)), coordinate=1), Stop(KelvinVoigtBumper(1.5e-3, 400.0, 0.2), coordinate=1, side="lower"))
    return ImpactProblem(PAPER_SYSTEM, stops, HarmonicForce(PAPER_AMPLITUDE, 24.0))


def chain_bumpers() -> ImpactProblem:
    """Three masses, a relative bumper x3 - x2 <= 3 mm and a lower one x1 >= -1 mm (500 Hz, xi_b = 0.2), at 32 Hz."""
    stops = (Stop(KelvinVoigtBumper(3e-3, 500.0, 0.2), coordinate=2, other=1), Stop(KelvinVoigtBumper(1e-3, 500.0, 0.2), coordinate=0, side="lower"))
    return ImpactProblem(chain(), stops, HarmonicForce(10.0, 32.0))


def steady(problem: ImpactProblem, periods: int = 800) -> np.ndarray:
    """The engine's steady state from rest: its last strobe, repeating to 1e-10 of the motion's scale."""
    run = ENGINE.integrate(problem, np.zeros(2 * problem.size), 0.0, periods)
    scale = np.abs(run.strobe_states[-50:]).max(axis=0)
    assert np.all(np.abs(run.strobe_states[-1] - run.strobe_states[-2]) <= 1e-10 * scale), "not settled"
    return run.final_state


#: Steady states: Omega_b / 2 pi from 100 Hz to 5 kHz, R from 0.05 to 0.95, the paper's layout and two bumpers.
STEADY_CASES = {
    "100Hz-R0.05": lambda: paper(24.0, 100.0, 0.05),
    "250Hz-R0.2": lambda: paper(25.0, 250.0, 0.2),
    "1kHz-R0.5": lambda: paper(27.0, 1000.0, 0.5),
    "2kHz-R0.8": lambda: paper(25.0, 2000.0, 0.8),
    "5kHz-R0.95": lambda: paper(26.0, 5000.0, 0.95),
    "recontact": lambda: paper(21.0, 100.0, loss_factor=2.0, amplitude=40.0),
    "two-sided": two_sided,
    "chain": chain_bumpers,
}


@pytest.mark.timeout(120)
@pytest.mark.parametrize("name", list(STEADY_CASES))
def test_steady_state_agrees_with_an_independent_integration(name: str) -> None:
    """From the engine's steady state (marched from rest), two periods of DOP853 at rtol 1e-12: the state repeats
    there too (1e-9 of its scale: the independent model's steady state), and the fundamentals |X_i| of every
    coordinate and |F_k| of every bumper force agree to 1e-8 (measured ~5e-12), as do the contacts' onsets (1e-10 s),
    impulses and largest forces (1e-8). The ``recontact`` case (an overdamped bumper, 40 N) has two contacts per
    period, the second a re-contact while the bumper is still compressed (entry speed < 0)."""
    problem = STEADY_CASES[name]()
    state = steady(problem)
    run = ENGINE.integrate(problem, state, 0.0, 2, moments=True)  # cos(w N T) = 1: the orbit, started at t = 0
    reference = reference_run(problem, state, 0.0, 2)
    scale = np.abs(reference.strobes).max(axis=0)
    assert np.all(np.abs(reference.strobes[-1] - reference.strobes[0]) <= 1e-9 * scale)
    assert np.all(np.abs(run.strobe_states - reference.strobes) <= 1e-9 * scale)
    n, count = problem.size, len(problem.stops)
    for mine, theirs in ((run.moments[:, :n], reference.coordinates), (run.moments[:, n : n + count], reference.forces)):
        np.testing.assert_allclose(np.abs(mine), np.abs(theirs), rtol=1e-8, atol=0.0)
        np.testing.assert_allclose(mine, theirs, rtol=0.0, atol=1e-8 * np.abs(theirs).max())
    onsets = np.array([t for t, _ in reference.onsets])
    open_at_start = int(run.segments[0, 2] == MODE_CONTACT)  # a contact under way at t = 0 counts as begun there
    assert run.stats["contacts"] - open_at_start == onsets.size >= 2
    np.testing.assert_allclose(run.impact_times[run.impact_times > 0.0], onsets[: np.sum(run.impact_times > 0.0)], rtol=0.0, atol=1e-10)
    assert set(run.impact_stops) == set(range(count))
    # completed contacts begun inside the run: impulse and largest force
    completed = [(t, k, impulse, peak) for t, k, impulse, peak in reference.contacts if t > 0.0]
    mine = [(t, k, impulse, peak) for t, k, impulse, peak in zip(run.impact_times, run.impact_stops, run.impulses, run.contact_peaks[:, 0]) if t > 0.0]
    assert len(mine) == len(completed) >= 1
    for (t, k, impulse, peak), (t_ref, k_ref, impulse_ref, peak_ref) in zip(mine, completed):
        assert k == k_ref and t == pytest.approx(t_ref, abs=1e-10)
        assert impulse == pytest.approx(impulse_ref, rel=1e-8) and peak == pytest.approx(peak_ref, rel=1e-8)
    if name == "recontact":
        assert np.sum(run.impact_velocities < 0.0) >= 2 and np.all(run.contact_peaks > 0.0)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("name", ["recontact", "chain"])
def test_a_transient_from_rest_agrees_with_an_independent_integration(name: str) -> None:
    """Twelve periods from rest, transient included: the same onsets, one by one (1e-9 s), and final state (1e-9
    of its scale)."""
    problem = STEADY_CASES[name]()
    start = np.zeros(2 * problem.size)
    run = ENGINE.integrate(problem, start, 0.0, 12)
    reference = reference_run(problem, start, 0.0, 12)
    onsets = np.array([t for t, _ in reference.onsets])
    assert run.impact_times.size in (onsets.size, onsets.size - 1) and onsets.size >= 10  # the last may still be open
    np.testing.assert_allclose(run.impact_times, onsets[: run.impact_times.size], rtol=0.0, atol=1e-9)
    np.testing.assert_array_equal(run.impact_stops, [k for _, k in reference.onsets][: run.impact_times.size])
    scale = np.abs(reference.strobes).max(axis=0)
    assert np.all(np.abs(run.strobe_states - reference.strobes) <= 1e-9 * scale)


def _free_mass(xi: float, static: float = 0.0, clearance: float = 1e-3) -> ImpactProblem:
    """A free 0.1 kg mass (no spring) under a constant force ``static`` [N] below a 250 Hz bumper, 10 Hz periods."""
    return ImpactProblem(LinearStructure(mass=[[0.1]], stiffness=[[0.0]]), (Stop(KelvinVoigtBumper(clearance, 250.0, xi), coordinate=0),), HarmonicForce(0.0, 10.0, static=(static,)))


@pytest.mark.parametrize("xi", [1e-4, 0.05, 0.3, 0.49, 0.5, 0.7, 1.5, 4.0])
def test_one_collision_gives_the_corrected_restitution_and_peak_force(xi: float) -> None:
    """A free mass entering the bumper at v0 leaves it at -R(xi) v0 with R = exp(-xi (pi - 2 arcsin xi) /
    sqrt(1 - xi^2)) (eq. 26 corrected; overdamped: exp(-xi t_r)) to 1e-12, after t_r(xi) / Omega_b (1e-12); impulse
    m (1 + R) v0 (1e-12); largest force m Gamma(xi) Omega_b v0 and deceleration Gamma Omega_b v0 (section 6.3
    corrected) to 1e-10 (measured ~1e-15)."""
    m, v0, omega = 0.1, 0.5, 2 * math.pi * 250.0
    run = ENGINE.integrate(_free_mass(xi), np.array([1e-3, v0]), 0.0, 1)
    restitution = restitution_from_loss_factor(xi)
    assert run.impact_times.size == 1 and run.stats["contacts"] == 1
    assert -run.final_state[1] / v0 == pytest.approx(restitution, rel=1e-12, abs=0.0)
    contact = run.segments[run.segments[:, 2] == MODE_CONTACT]
    assert contact[0, 1] - contact[0, 0] == pytest.approx(release_time(xi) / omega, rel=1e-12, abs=0.0)
    assert run.impulses[0] == pytest.approx(m * (1 + restitution) * v0, rel=1e-12, abs=0.0)
    gamma = peak_acceleration_factor(xi)
    assert run.contact_peaks[0, 0] == pytest.approx(m * gamma * omega * v0, rel=1e-10, abs=0.0)
    assert run.contact_peaks[0, 1] == pytest.approx(gamma * omega * v0, rel=1e-10, abs=0.0)


@pytest.mark.parametrize("side", ["upper", "lower"])
@pytest.mark.parametrize("xi", [0.05, 1.5])
def test_a_relative_bumper_between_two_free_bodies_is_the_textbook_collision(xi: float, side: str) -> None:
    """Two free masses (0.3, 0.1 kg) closing at 0.5 m/s on a bumper between them (500 Hz) under gravity: flows with
    rigid-body modes in flight and in contact (polynomial terms, Gauss-Legendre moments). The relative velocity
    leaves at -R(xi) v0 and the impulse is m (1 + R) v0 with the reduced mass m (1e-12), the largest deceleration of
    x2 - x1 is Gamma Omega_b v0 (1e-10); the momentum changes by gravity alone (1e-12); the moments of the
    coordinates are the quadrature of samples on panels ending at the switches (1e-10; measured 2e-12)."""
    m1, m2, g, v0 = 0.3, 0.1, 9.81, 0.5
    sign = 1.0 if side == "upper" else -1.0
    stop = Stop(KelvinVoigtBumper(1e-3, 500.0, xi), coordinate=1, other=0, side=side)
    problem = ImpactProblem(LinearStructure(mass=[[m1, 0.0], [0.0, m2]], stiffness=[[0.0, 0.0], [0.0, 0.0]]), (stop,), HarmonicForce(0.0, 10_000.0, static=(-m1 * g, -m2 * g)))
    start = np.array([0.0, sign * 1e-3, -0.25 * sign * v0, 0.75 * sign * v0])  # at the bumper, closing at v0
    run = ENGINE.integrate(problem, start, 0.0, 100, moments=True)  # 10 ms
    restitution, mass = restitution_from_loss_factor(xi), m1 * m2 / (m1 + m2)
    assert run.impact_times.size == 1 and run.stats["contacts"] == 1
    assert sign * (run.final_state[3] - run.final_state[2]) / v0 == pytest.approx(-restitution, rel=1e-12)
    assert run.impulses[0] == pytest.approx(mass * (1 + restitution) * v0, rel=1e-12)
    assert run.contact_peaks[0, 1] == pytest.approx(peak_acceleration_factor(xi) * 2 * math.pi * 500.0 * v0, rel=1e-10)
    momentum = run.strobe_states[:, 2:] @ [m1, m2]
    expected = momentum[0] - (m1 + m2) * g * (run.strobe_times - run.strobe_times[0])
    assert np.all(np.abs(momentum - expected) <= 1e-12 * (np.abs(run.strobe_states[:, 2:]) @ [m1, m2]))
    nodes, weights = np.polynomial.legendre.leggauss(30)
    edges = np.unique(np.concatenate([run.strobe_times, run.segments[:, 0]]))
    times = np.concatenate([0.5 * (a + b) + 0.5 * (b - a) * nodes for a, b in zip(edges[:-1], edges[1:])])
    w = np.tile(0.5 * weights, edges.size - 1) * np.repeat(np.diff(edges), nodes.size)
    _, samples = ENGINE.sample(problem, start, 0.0, 100, times)
    period = np.searchsorted(run.strobe_times, times) - 1
    quadrature = np.array([(w[period == p] * np.exp(-1j * problem.omega * times[period == p])) @ samples[period == p, :2] for p in range(100)])
    np.testing.assert_allclose(quadrature, run.moments[:, :2], rtol=0.0, atol=1e-10 * np.abs(run.moments[:, :2]).max())


def test_a_critically_damped_bumper_on_a_free_mass_is_refused_by_name() -> None:
    """xi_b = 1 on a body nothing else holds has a double eigenvalue: no modal basis; the error says so and names
    the way out (the paper's system with xi_b = 1 is fine: its spring splits the pair)."""
    with pytest.raises(ValueError, match="critically damped bumper, loss factor 1.*'compliant'"):
        ENGINE.integrate(_free_mass(1.0), np.array([1e-3, 0.5]), 0.0, 1)
    assert ENGINE.integrate(paper(25.0, 250.0, loss_factor=1.0), np.zeros(4), 0.0, 3).impact_times.size >= 1


@pytest.mark.parametrize("reach", [1e-12, -1e-12])
def test_a_grazing_onset_is_found_however_tangent(reach: float) -> None:
    """A free mass thrown up at 1 m/s under gravity reaches its apex 1e-12 m beyond the bumper (or short of it): the
    search finds the contact, at speed sqrt(2 g 1e-12) = 4.4 um/s, at the apex time minus sqrt(2e-12 / g) (1e-11 s:
    the positions' round-off, ~1e-17 m, over that speed); short of it there is none."""
    g, v0 = 9.81, 1.0
    apex = v0**2 / (2 * g)
    run = ENGINE.integrate(_free_mass(0.3, static=-0.1 * g, clearance=apex - reach), np.array([0.0, v0]), 0.0, 2)  # the apex at 0.102 s
    if reach < 0.0:
        assert run.stats["contacts"] == 0 and run.impact_times.size == 0
        return
    assert run.stats["contacts"] == run.impact_times.size == 1
    assert run.impact_times[0] == pytest.approx(v0 / g - math.sqrt(2 * reach / g), abs=1e-11)
    assert run.impact_velocities[0] == pytest.approx(math.sqrt(2 * g * reach), rel=1e-3)


def test_the_jacobian_of_the_stroboscopic_map_is_the_finite_difference_one() -> None:
    """On steady states with one contact, two (a re-contact while compressed) and two bumpers: the exact Jacobian
    (transition matrices and the onset's saltation matrix I - B (0, M^-1 n)(n, 0)^T) equals central differences of the
    map (steps 1e-5 of each state's scale) to 2e-6 of its scale (measured ~1e-7: the differences' truncation and
    round-off); the orbits are stable (multipliers inside the unit circle). The strobe Jacobians of a run compose
    to the map's over several periods (1e-12)."""
    for problem in (paper(25.0, 250.0, 0.2), STEADY_CASES["recontact"](), chain_bumpers()):
        state = steady(problem, 500)
        image = ENGINE.strobe_map(problem, state, 0.0, 1)
        scale = np.abs(ENGINE.integrate(problem, state, 0.0, 1).strobe_states).max(axis=0)
        size = state.size
        differences = np.empty((size, size))
        for j in range(size):
            step = 1e-5 * scale[j] * np.eye(size)[j]
            differences[:, j] = (ENGINE.strobe_map(problem, state + step, 0.0, 1).state - ENGINE.strobe_map(problem, state - step, 0.0, 1).state) / (2 * step[j])
        weights = scale[None, :] / scale[:, None]  # d y_i / d y_j in units of the scales
        assert np.max(np.abs(differences - image.jacobian) * weights) <= 2e-6 * np.max(np.abs(image.jacobian) * weights)
        assert np.max(np.abs(np.linalg.eigvals(image.jacobian))) < 1.0
        run = ENGINE.integrate(problem, state, 0.0, 3, jacobians=True)
        product = run.strobe_jacobians[2] @ run.strobe_jacobians[1] @ run.strobe_jacobians[0]
        np.testing.assert_allclose(product, ENGINE.strobe_map(problem, state, 0.0, 3).jacobian, rtol=0.0, atol=1e-12 * np.abs(product).max())


@pytest.mark.timeout(60)
@pytest.mark.parametrize("name", ["250Hz-R0.2", "two-sided"])
def test_agrees_with_ida_at_its_tolerance(name: str) -> None:
    """``compliant`` (IDA, rtol 1e-10, atol 1e-14 m) over 15 periods from rest: the same contacts (onsets 1e-8 s),
    strobes and moments to 1e-7 of their scale, impulses and peaks to 1e-6 (IDA's own accuracy at that tolerance,
    measured up to 2.3e-7 on a glancing contact, and its peaks are evaluated at roots it locates)."""
    problem = STEADY_CASES[name]()
    start = np.zeros(2 * problem.size)
    exact = ENGINE.integrate(problem, start, 0.0, 15, moments=True)
    ida = make_engine("compliant", EngineSettings(rtol=1e-10, atol=1e-14)).integrate(problem, start, 0.0, 15, moments=True)
    assert exact.impact_times.size == ida.impact_times.size >= 10 and exact.stats["contacts"] == ida.stats["contacts"]
    np.testing.assert_array_equal(exact.impact_stops, ida.impact_stops)
    np.testing.assert_allclose(exact.impact_times, ida.impact_times, rtol=0.0, atol=1e-8)
    np.testing.assert_allclose(exact.contact_peaks, ida.contact_peaks, rtol=1e-6)
    np.testing.assert_allclose(exact.impulses, ida.impulses, rtol=1e-6)
    for mine, theirs in ((exact.strobe_states, ida.strobe_states), (exact.moments, ida.moments)):
        assert np.all(np.abs(mine - theirs) <= 1e-7 * np.abs(theirs).max(axis=0))


def test_samples_are_the_exact_flow_and_integrate_to_the_moments() -> None:
    """Samples at the strobe times are the strobes (1e-13 of the scale); Gauss-Legendre quadrature of dense samples
    over each period, on panels that end at the contact switches (where the accelerations jump), gives the moments of
    the coordinates (1e-12)."""
    problem = STEADY_CASES["two-sided"]()
    state = steady(problem, 400)
    periods, period = 2, problem.period
    nodes, weights = np.polynomial.legendre.leggauss(40)
    switches = ENGINE.integrate(problem, state, 0.0, periods).segments[:, 0]
    edges = np.unique(np.concatenate([np.linspace(0.0, periods * period, 201), switches]))
    times = np.concatenate([0.5 * (a + b) + 0.5 * (b - a) * nodes for a, b in zip(edges[:-1], edges[1:])])
    run, samples = ENGINE.sample(problem, state, 0.0, periods, np.sort(np.concatenate([times, np.arange(periods + 1) * period])))
    _, at_strobes = ENGINE.sample(problem, state, 0.0, periods, run.strobe_times)
    scale = np.abs(run.strobe_states).max(axis=0)
    assert np.all(np.abs(at_strobes - run.strobe_states) <= 1e-13 * scale)
    moments = ENGINE.integrate(problem, state, 0.0, periods, moments=True).moments
    _, dense = ENGINE.sample(problem, state, 0.0, periods, times)
    w = np.tile(0.5 * weights, edges.size - 1) * np.repeat(np.diff(edges), nodes.size)
    for p in range(periods):
        inside = (times > p * period) & (times < (p + 1) * period)
        quadrature = (w[inside] * np.exp(-1j * problem.omega * times[inside])) @ dense[inside, :2]
        np.testing.assert_allclose(quadrature, moments[p, :2], rtol=0.0, atol=1e-12 * np.abs(moments[p, :2]).max())
    assert samples.shape == (times.size + periods + 1, 4)


def test_a_sweep_is_refused() -> None:
    """A swept sine has no closed-form particular solution (a rigid stop: tests/engines/test_registry.py)."""
    sweep = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(PAPER_CLEARANCE, 250.0, 0.3), SweptSine(PAPER_AMPLITUDE, 24.0, 25.0, 0.1))
    with pytest.raises(TypeError, match="harmonic force"):
        ENGINE.integrate(sweep, np.zeros(4), 0.0, 1)


def test_a_steady_state_started_by_shooting_is_the_bumpers_own() -> None:
    """``shooting`` shoots the rigid stop's orbit to start a bumper's march: an engine with an exact flow measures a
    shot orbit directly only when it is the problem's own (it measured the rigid orbit, |X1| 2.748 mm, as the 250 Hz
    bumper's, 3.007 mm). From every start the bumper's steady state is the same (1e-10) and IDA's to its tolerance."""
    from dataclasses import replace

    from vibroimpact.model.contact import RigidStop
    from vibroimpact.simulation.settings import SteadySettings
    from vibroimpact.simulation.steady import steady_state

    rigid = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    bumper = replace(rigid, contact=KelvinVoigtBumper(PAPER_CLEARANCE, 250.0, loss_factor_from_restitution(0.2)))
    results = [steady_state(ENGINE, bumper, start, SteadySettings(tolerance=1e-9), rigid.rigid_stop) for start in ("shooting", "pgf", "rest")]
    assert all(result.converged for result in results)
    x1 = [abs(result.measures.x1) for result in results]
    np.testing.assert_allclose(x1, x1[0], rtol=1e-10)
    assert x1[0] == pytest.approx(3.0074e-3, rel=1e-4)
    ida = steady_state(make_engine("compliant", EngineSettings(rtol=1e-10, atol=1e-14)), bumper, "pgf", SteadySettings(tolerance=1e-9), rigid.rigid_stop)
    assert abs(ida.measures.x1) == pytest.approx(x1[0], rel=1e-8)



def test_a_new_frequency_keeps_the_contact_modes_and_gives_the_same_flows() -> None:
    """A continuation in frequency makes a new problem at every step: the modes' decompositions (independent of the
    frequency) are kept, only the harmonic particular solution is made again, and the flows equal those made with
    nothing kept (the same operations on the same numbers: to the last bit, as the golden suite holds them against
    the decomposition before it was split)."""
    from vibroimpact.engines.compliant.exact import contact_modes, bumper_flows

    law = KelvinVoigtBumper(PAPER_CLEARANCE, 731.0, loss_factor_from_restitution(0.37))  # a bumper no other test has
    first, second = (ImpactProblem(PAPER_SYSTEM, law, HarmonicForce(PAPER_AMPLITUDE, f)) for f in (24.0, 24.5))
    bumper_flows(first)
    hits = contact_modes.cache_info().hits
    kept, *_ = bumper_flows(second)
    assert contact_modes.cache_info().hits == hits + 1
    contact_modes.cache_clear()
    fresh, *_ = bumper_flows(second)
    assert len(kept) == len(fresh) == 2
    for a, b in zip(kept, fresh):
        for name in ("eigenvalues", "vectors", "inverse", "harmonic", "constant", "projector", "nilpotent", "drift"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name  # exact: the same computation
        assert a.omega == b.omega == second.omega  # exact: copied input


def test_a_new_frequency_s_loop_arguments_equal_those_made_with_nothing_kept() -> None:
    """The engine keeps what does not depend on the frequency (the modes' stack, the contact geometry, the load) and
    makes only the harmonic parts at a new one (a bumper screen and a continuation set up a problem at every step):
    every argument of the compiled loop equals, to the last bit, the one made with every cache cleared."""
    from vibroimpact.engines.compliant.exact import forget_problems, loop_arguments

    law = KelvinVoigtBumper(PAPER_CLEARANCE, 613.0, loss_factor_from_restitution(0.41))
    first, second = (ImpactProblem(PAPER_SYSTEM, law, HarmonicForce(PAPER_AMPLITUDE, f)) for f in (27.0, 27.3))
    loop_arguments(first)
    kept = loop_arguments(second)
    forget_problems()
    fresh = loop_arguments(second)
    assert fresh is not kept
    for name, a, b in zip(fresh._fields, kept, fresh):
        assert np.asarray(a).dtype == np.asarray(b).dtype and np.array_equal(a, b), name  # exact: the same computation


@pytest.mark.parametrize("base_motion", [False, True])
def test_the_loop_s_harmonic_response_is_the_free_flight_s_at_the_problem_s_own_frequency(base_motion: bool) -> None:
    """What is kept across frequencies must not include the load: a base motion's inertial load grows with w^2. The
    free flight's harmonic particular solution in the loop's arguments, after a setup at another frequency, is
    (jw I - A)^-1 b of the problem's own first-order form (an independent path) to 1e-12."""
    from vibroimpact.engines.compliant.exact import loop_arguments

    law = KelvinVoigtBumper(PAPER_CLEARANCE, 437.0, loss_factor_from_restitution(0.52))
    amplitude = 1e-4 if base_motion else PAPER_AMPLITUDE  # [m] of the base, or [N]
    first, second = (ImpactProblem(PAPER_SYSTEM, law, HarmonicForce(amplitude, f, base_motion=base_motion)) for f in (21.0, 33.0))
    loop_arguments(first)
    a, b, _b0 = second.first_order()
    expected = np.linalg.solve(1j * second.omega * np.eye(a.shape[0]) - a, b)
    assert np.max(np.abs(loop_arguments(second).hrms[0] - expected)) <= 1e-12 * np.max(np.abs(expected))
