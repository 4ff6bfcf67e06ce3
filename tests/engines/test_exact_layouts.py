"""The exact engines on general layouts: any N-dof structure, absolute and relative stops on either side, preloads,
static loads and rigid-body modes (a free mass), checked against the paper's named form, invariants of the impact
map, a mirror symmetry, the pure-Python engine, finite differences and published closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.engines.base import MODE_STUCK
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.engines.exact_python import PythonExactEngine
from vibroimpact.engines.momentary import MomentaryEngine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.branch import MapEvaluation
from vibroimpact.orbits.shooting import shoot
from vibroimpact.simulation.steady import start_state

ENGINE = ExactEngine()
PYTHON = PythonExactEngine()
GRAVITY = 9.81


def _scaled_difference(a: np.ndarray, b: np.ndarray, scale: np.ndarray) -> float:
    return float(np.max(np.abs(a - b) / scale))


@pytest.mark.parametrize(("frequency", "restitution", "start"), [(25.0, 0.2, "pgf"), (26.0, 0.6, "pgf"), (40.0, 0.2, "pgf"), (24.0, 0.5, "rest")])
def test_the_paper_written_as_a_general_structure_is_the_named_form(frequency: float, restitution: float, start: str) -> None:
    """The paper's layout as matrices and a tuple of one Stop runs the general flows (real eigen-decomposition, the
    held flow built on the stop's surface, the holding force from contact_holding); the named form runs the formulas
    the engine always used. Same strobes, impact times and impulses to 1e-12 (measured: 6e-14) on stable motions; in
    a chatter round-off grows by 1 / R per bounce, so those are left to the compiled-against-Python tests."""
    clearance = 0.003
    named = ImpactProblem(PAPER_SYSTEM, RigidStop(clearance, restitution), HarmonicForce(10.0, frequency, 0.3))
    general = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(clearance, restitution), 1),), HarmonicForce(10.0, frequency, 0.3))
    t, y = start_state(named, start)
    a = ENGINE.integrate(named, y, t, 40, moments=True)
    b = ENGINE.integrate(general, y, t, 40, moments=True)
    assert a.impact_times.size == b.impact_times.size > 5 and a.stats == b.stats
    scale = np.max(np.abs(a.strobe_states), axis=0) + clearance * np.array([1.0, 1.0, named.omega, named.omega])
    assert _scaled_difference(a.strobe_states, b.strobe_states, scale) <= 1e-12
    np.testing.assert_allclose(b.impact_times, a.impact_times, rtol=0, atol=1e-12 * named.period)
    np.testing.assert_allclose(b.impulses, a.impulses, rtol=1e-12)
    np.testing.assert_allclose(b.moments, a.moments, rtol=0, atol=1e-12 * np.max(np.abs(a.moments)))


def test_relative_stop_conserves_momentum_and_restitutes_the_relative_velocity() -> None:
    """Ormondroyd & Den Hartog's stop between absorber and primary (x2 - x1 <= 2 mm): at every impact the momentum
    m1 x1' + m2 x2' is the same before and after (1e-12 of m2 |x2'|; measured 1e-15), n.x'(t+) = -R n.x'(t-) (1e-12),
    the recorded approach speed is n.x'(t-), the impulse m_eff (1 + R) v with m_eff = m1 m2 / (m1 + m2), and both
    bodies sit exactly at the stop's gap."""
    restitution, clearance = 0.4, 0.002
    problem = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(clearance, restitution), 1, other=0),), HarmonicForce(10.0, 30.0))
    run = ENGINE.integrate(problem, np.zeros(4), 0.0, 40)
    assert run.impact_times.size >= 10
    before = ENGINE.dense(run, run.impact_times, side="left")
    after = ENGINE.dense(run, run.impact_times, side="right")
    m1, m2 = PAPER_SYSTEM.m1, PAPER_SYSTEM.m2
    momentum_before, momentum_after = m1 * before[:, 2] + m2 * before[:, 3], m1 * after[:, 2] + m2 * after[:, 3]
    np.testing.assert_allclose(momentum_after, momentum_before, rtol=0, atol=1e-12 * np.max(np.abs(m2 * before[:, 3])))
    approach_before, approach_after = before[:, 3] - before[:, 2], after[:, 3] - after[:, 2]
    np.testing.assert_allclose(approach_before, run.impact_velocities, rtol=1e-12)
    np.testing.assert_allclose(approach_after, -restitution * approach_before, rtol=0, atol=1e-12 * np.max(approach_before))
    np.testing.assert_allclose(run.impulses, m1 * m2 / (m1 + m2) * (1 + restitution) * run.impact_velocities, rtol=1e-12)
    np.testing.assert_allclose(after[:, 1] - after[:, 0], clearance, rtol=0, atol=1e-15)


def test_a_lower_stop_is_the_mirror_image_of_an_upper_stop() -> None:
    """x -> -x, force -> -force, upper stop -> lower stop: the same motion mirrored (1e-12 of the motion; the
    impact times and impulses equal)."""
    structure, law = PAPER_SYSTEM.structure, RigidStop(0.003, 0.3)
    upper = ImpactProblem(structure, (Stop(law, 1, side="upper"),), HarmonicForce(10.0, 26.0, 0.4, weights=(1.0, 0.0)))
    lower = ImpactProblem(structure, (Stop(law, 1, side="lower"),), HarmonicForce(10.0, 26.0, 0.4, weights=(-1.0, 0.0)))
    start = np.array([1e-3, -2e-3, 0.05, 0.1])
    a = ENGINE.integrate(upper, start, 0.0, 30, moments=True)
    b = ENGINE.integrate(lower, -start, 0.0, 30, moments=True)
    assert a.impact_times.size == b.impact_times.size > 20
    scale = np.max(np.abs(a.strobe_states), axis=0)
    assert _scaled_difference(b.strobe_states, -a.strobe_states, scale) <= 1e-12
    np.testing.assert_allclose(b.impact_times, a.impact_times, rtol=0, atol=1e-12 * upper.period)
    np.testing.assert_allclose(b.impulses, a.impulses, rtol=1e-12)
    # coordinates and squares mirror as x and x^2; the stop's contact force keeps its sign (it pushes)
    np.testing.assert_allclose(b.moments, a.moments * np.array([-1, -1, 1, 1, 1]), rtol=0, atol=1e-12 * np.max(np.abs(a.moments)))


def _chain(frequency: float) -> ImpactProblem:
    """Three masses in a chain (ground - m1 - m2 - m3), force on m1; stop 0: x3 <= 2 mm (R = 0.6), stop 1:
    x2 - x1 >= -1.5 mm (relative, lower side, R = 0.5)."""
    k1, k2, k3 = 2e4, 8e3, 3e3
    stiffness = np.array([[k1 + k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])
    mass = np.diag([1.0, 0.5, 0.2])
    structure = LinearStructure(mass, stiffness, 2e-5 * stiffness + 0.3 * mass)
    stops = (Stop(RigidStop(0.002, 0.6), 2), Stop(RigidStop(0.0015, 0.5), 1, other=0, side="lower"))
    return ImpactProblem(structure, stops, HarmonicForce(10.0, frequency, 0.2))


@pytest.mark.parametrize("frequency", [14.0, 30.0])
def test_chain_with_two_stops_compiled_equals_python(frequency: float) -> None:
    """Both stops hit; the compiled core (closed-form moments) and the pure-Python loop (Gauss-Legendre moments) agree:
    impact times to 1e-8 of a period, strobes to 1e-9 of the motion, moments to 1e-9 (measured 2e-13, 8e-13)."""
    problem = _chain(frequency)
    compiled = ENGINE.integrate(problem, np.zeros(6), 0.0, 30, moments=True)
    python = PYTHON.integrate(problem, np.zeros(6), 0.0, 30, moments=True)
    assert compiled.impact_times.size == python.impact_times.size
    assert np.all(np.bincount(compiled.impact_stops, minlength=2) >= 4)
    np.testing.assert_array_equal(compiled.impact_stops, python.impact_stops)
    np.testing.assert_allclose(compiled.impact_times, python.impact_times, rtol=0, atol=1e-8 * problem.period)
    np.testing.assert_allclose(compiled.impulses, python.impulses, rtol=1e-9)
    scale = np.max(np.abs(python.strobe_states), axis=0)
    assert _scaled_difference(compiled.strobe_states, python.strobe_states, scale) <= 1e-9
    assert compiled.moments.shape == (30, 2 * 3 + 2)
    np.testing.assert_allclose(compiled.moments, python.moments, rtol=0, atol=1e-9 * np.max(np.abs(python.moments)))


def _finite_difference(problem: ImpactProblem, state: np.ndarray, t: float, scale: np.ndarray) -> np.ndarray:
    columns = []
    for j in range(state.size):
        step = np.zeros(state.size)
        step[j] = 1e-7 * scale[j]
        ahead, behind = ENGINE.strobe_map(problem, state + step, t).state, ENGINE.strobe_map(problem, state - step, t).state
        columns.append((ahead - behind) / (2.0 * step[j]))
    return np.column_stack(columns)


@pytest.mark.parametrize("frequency", [14.0, 30.0])
def test_chain_jacobians_equal_finite_differences(frequency: float) -> None:
    """Saltation matrices for an absolute and a relative lower stop: the Jacobian of the one-period map equals central
    differences to 1e-6 of its largest entry in state-scaled units (measured 1e-8 to 3e-8)."""
    problem = _chain(frequency)
    run = ENGINE.integrate(problem, np.zeros(6), 0.0, 12, jacobians=True)
    scale = 0.004 * np.array([1.0, 1.0, 1.0, problem.omega, problem.omega, problem.omega])
    hit = np.zeros(2, dtype=int)
    for k in range(6, 12):
        state, time = run.strobe_states[k], run.strobe_times[k]
        image = ENGINE.strobe_map(problem, state, time)
        hit += np.bincount(image.impact_stops, minlength=2)
        jacobian = run.strobe_jacobians[k] * scale[None, :] / scale[:, None]
        difference = _finite_difference(problem, state, time, scale) * scale[None, :] / scale[:, None]
        assert np.max(np.abs(difference - jacobian)) <= 1e-6 * np.max(np.abs(jacobian))
    assert np.all(hit >= 1)


def _ball(restitution: float, amplitude: float, frequency: float) -> ImpactProblem:
    """A free unit mass under gravity above a table (lower stop at 0), with a harmonic force of ``amplitude`` [N]."""
    return ImpactProblem(LinearStructure([[1.0]], [[0.0]]), (Stop(RigidStop(0.0, restitution), 0, side="lower"),), HarmonicForce(amplitude, frequency, static=(-GRAVITY,)))


@pytest.mark.parametrize("restitution", [0.3, 0.5, 0.8])
def test_a_dropped_ball_sticks_at_the_zeno_time_and_rests(restitution: float) -> None:
    """A ball dropped from h = 1 m on a fixed table: impact n arrives at v0 e^(n-1), v0 = sqrt(2 g h), and the bounces
    accumulate at t_Z = sqrt(2 h / g) (1 + e) / (1 - e). The engine sticks at the first arrival v <= v_s (the sticking
    velocity) instead of bouncing on: it leaves out the remaining flights, sum_{m >= n} 2 e^m v0 / g
    = 2 e v / (g (1 - e)), so 0 <= t_Z - t_stick <= 2 e v_s / (g (1 - e)) (< 2 v_s / (g (1 - e))). Then it rests on the
    table (no release), the impulses sum to m g t_stick (momentum from rest to rest), and the table holds it with
    m g: the stuck part of the period's force moment is int m g e^{-jwt} dt (1e-9)."""
    height, frequency = 1.0, 1.0
    problem = _ball(restitution, 0.0, frequency)
    zeno = math.sqrt(2.0 * height / GRAVITY) * (1.0 + restitution) / (1.0 - restitution)
    periods = int(zeno * frequency) + 3
    run = ENGINE.integrate(problem, np.array([height, 0.0]), 0.0, periods, moments=True)
    stuck = run.segments[run.segments[:, 2] == MODE_STUCK]
    assert run.stats["sticks"] == 1 and run.stats["releases"] == 0 and stuck.shape[0] == 1
    t_stick = stuck[0, 0]
    sticking_velocity = ENGINE.settings.sticking_velocity * problem.velocity_scale()
    assert 0.0 <= zeno - t_stick <= 2.0 * restitution * sticking_velocity / (GRAVITY * (1.0 - restitution)) * (1.0 + 1e-9)
    np.testing.assert_allclose(run.impact_times[0], math.sqrt(2.0 * height / GRAVITY), rtol=1e-14)
    np.testing.assert_allclose(run.strobe_states[-1], 0.0, atol=1e-15)
    np.testing.assert_allclose(np.sum(run.impulses), GRAVITY * t_stick, rtol=1e-12)
    row = int(t_stick * frequency)
    omega, end = problem.omega, (row + 1) / frequency
    in_row = (run.impact_times >= row / frequency) & (run.impact_times < end)
    impulses = np.sum(run.impulses[in_row] * np.exp(-1j * omega * run.impact_times[in_row]))
    holding = GRAVITY * (np.exp(-1j * omega * end) - np.exp(-1j * omega * t_stick)) / (-1j * omega)
    np.testing.assert_allclose(run.moments[row, 1], impulses + holding, rtol=1e-9)
    np.testing.assert_allclose(run.moments[-1, 1], 0.0, atol=1e-12)  # resting all period: m g integrates to zero
    python = PYTHON.integrate(problem, np.array([height, 0.0]), 0.0, periods, moments=True)
    np.testing.assert_allclose(python.impact_times, run.impact_times, rtol=0, atol=1e-12)
    np.testing.assert_allclose(python.moments, run.moments, rtol=0, atol=1e-9 * np.max(np.abs(run.moments)))


def test_bouncing_ball_on_a_vibrating_table_jacobian() -> None:
    """A free mass under gravity and a harmonic force (the table's vibration in its frame, Gamma = 1.3: Holmes's
    period-one orbit, stable between pi (1 - e)/(1 + e) = 1.05 and 1.53 for e = 0.5): the flight is a polynomial plus
    a harmonic, the transition matrix [[1, tau], [0, 1]], and each impact's saltation has determinant e^2, so the
    one-period Jacobian has det = e^2 (1e-12) and equals central differences (1e-5, measured 4e-7)."""
    restitution, frequency, gamma = 0.5, 2.0, 1.3
    problem = _ball(restitution, gamma * GRAVITY, frequency)
    run = ENGINE.integrate(problem, np.array([0.0, GRAVITY / (2.0 * frequency)]), 0.125 / frequency, 100)
    assert run.stats["sticks"] == 0 and np.sum(run.impact_times > run.strobe_times[-11]) >= 9
    state, time = run.strobe_states[-1], run.strobe_times[-1]
    image = ENGINE.strobe_map(problem, state, time)
    assert image.impact_times.size == 1
    np.testing.assert_allclose(np.linalg.det(image.jacobian), restitution**2, rtol=1e-12)
    difference = _finite_difference(problem, state, time, np.array([0.1, 1.0]))
    assert np.max(np.abs(difference - image.jacobian)) <= 1e-5 * np.max(np.abs(image.jacobian))
    np.testing.assert_allclose(image.state, state, rtol=0, atol=1e-9)  # the period-one orbit


def test_a_preloaded_stop_holds_until_the_force_pulls_harder() -> None:
    """x'' + x k = 20 cos(w t), x <= -1 mm (a negative clearance: the spring presses the mass on the stop with
    k * 1 mm = 10 N). Started at rest on the stop it is held while 20 cos(w t) + 10 > 0 and leaves at w t = 2 pi / 3
    (1e-12 of a period); it never passes the stop, and the Python engine agrees."""
    problem = ImpactProblem(LinearStructure([[1.0]], [[1e4]], [[2.0]]), (Stop(RigidStop(-1e-3, 0.5), 0),), HarmonicForce(20.0, 5.0))
    run = ENGINE.integrate(problem, np.array([-1e-3, 0.0]), 0.0, 6)
    assert run.segments[0, 2] == MODE_STUCK  # exact: a mode stored as float
    np.testing.assert_allclose(run.segments[0, 1], 1.0 / 3.0 / 5.0, rtol=0, atol=1e-12 * problem.period)
    assert run.stats["releases"] >= 6
    dense = ENGINE.dense(run, np.linspace(0.0, run.strobe_times[-1], 4001))
    assert dense[:, 0].max() <= -1e-3 + 1e-15
    python = PYTHON.integrate(problem, np.array([-1e-3, 0.0]), 0.0, 6)
    np.testing.assert_allclose(python.segments, run.segments, rtol=0, atol=1e-8 * problem.period)


@pytest.mark.parametrize("engine", [ENGINE, PYTHON], ids=["compiled", "python"])
def test_a_ball_on_a_table_at_gamma_one_stays_on_it(engine: ExactEngine | PythonExactEngine) -> None:
    """A ball at rest on a table vibrating at exactly Gamma = A w^2 / g = 1 (table coordinates, 10 Hz): the holding
    force m g (1 + sin(w t)) touches zero at w t = 3 pi / 2 every period without turning negative, and the free
    flight's acceleration -(1 + sin(w t)) g is never positive, so the ball stays on the table. The engine may let go
    within round-off of the touch, but it lands at once: over 20 periods no impact faster than 1e-12 m/s, |z| <= 1e-15
    m and |z'| <= 1e-12 m/s everywhere (measured 2e-20 m, 4e-16 m/s), held but for 1e-6 of the time (measured 1.2e-8),
    at most one release per period, and the holding force's Fourier moment is its closed form
    int m g sin(w t) e^{-jwt} dt = -j m g T / 2 (1e-12 of m g T). (It ran out of events, 'no progress', at the fifth
    touch: the held search stopped where the force was within round-off of zero, still falling, and the stop, asked
    if it pushed, answered from that fall that it did not, while the flight went into it.)"""
    problem = ImpactProblem(LinearStructure([[1.0]], [[0.0]]), (Stop(RigidStop(0.0, 0.5), 0, side="lower"),), HarmonicForce(GRAVITY, 10.0, 0.5 * math.pi, static=(-GRAVITY,)))
    periods = 20
    run = engine.integrate(problem, np.zeros(2), 0.0, periods, moments=True)
    assert np.all(run.impact_velocities <= 1e-12)
    assert run.stats["releases"] <= periods and run.stats["sticks"] <= periods
    dense = engine.dense(run, np.linspace(0.0, run.strobe_times[-1], 20001))
    assert np.max(np.abs(dense[:, 0])) <= 1e-15 and np.max(np.abs(dense[:, 1])) <= 1e-12
    np.testing.assert_allclose(run.strobe_states, 0.0, atol=1e-15)
    assert run.stuck_time >= (1.0 - 1e-6) * periods * problem.period
    np.testing.assert_allclose(run.moments[:, 1], -0.5j * GRAVITY * problem.period, rtol=0, atol=1e-12 * GRAVITY * problem.period)


def _sticking_chain() -> ImpactProblem:
    """Three masses in a chain on the ground (1, 0.3, 0.1 kg; 30, 6, 2 kN/m, lightly damped) at 15 Hz under 10 N,
    R = 0 on a relative stop x3 - x2 <= 0.5 mm and on a lower stop x1 >= -0.2 mm (test_layouts_momentary's case)."""
    stiffness = np.array([[36e3, -6e3, 0.0], [-6e3, 8e3, -2e3], [0.0, -2e3, 2e3]])
    structure = LinearStructure(np.diag([1.0, 0.3, 0.1]), stiffness, 1e-4 * stiffness + 0.1 * np.eye(3))
    stops = (Stop(RigidStop(0.5e-3, 0.0), 2, other=1), Stop(RigidStop(0.2e-3, 0.0), 0, side="lower"))
    return ImpactProblem(structure, stops, HarmonicForce(10.0, 15.0))


@pytest.mark.parametrize("engine", [ENGINE, PYTHON], ids=["compiled", "python"])
def test_an_impact_on_one_stop_leaves_the_other_held(engine: ExactEngine | PythonExactEngine) -> None:
    """The chain sticks on each stop in turn, and x1 hits its stop while x3 - x2 is held: M is diagonal, so the
    impulse along M^-1 n = e1 leaves x2' and x3' alone and the relative stop, still closed, at rest and pushed,
    holds on. So no impact is slower than 1e-6 m/s (there were 28 at ~1e-14 m/s: the held stop let go and was taken
    back by an impact at round-off speed), each of the >= 20 impacts on x1 during a hold on x3 - x2 is followed by
    the same hold, and the run has CVODE's impacts (same count, stops, times within 1e-8 s), sticks and releases
    (118, 59, 59; there were 146 impacts and 87 sticks). The Jacobian of a period with such impacts equals central
    differences to 1e-6 of its largest entry (measured 2e-8 with steps of 1e-5 of the state scale)."""
    problem = _sticking_chain()
    run = engine.integrate(problem, np.zeros(6), 0.0, 30)
    assert np.all(run.impact_velocities > 1e-6)
    segment = np.searchsorted(run.segments[:, 0], run.impact_times, side="left") - 1  # the segment each impact ends
    through = (run.segments[segment, 2] == MODE_STUCK) & (run.segment_stops[segment] == 0) & (run.impact_stops == 1)
    assert np.count_nonzero(through) >= 20
    after = segment[through] + 1
    assert np.all(run.segments[after, 2] == MODE_STUCK) and np.all(run.segment_stops[after] == 0)
    reference = MomentaryEngine(EngineSettings(rtol=1e-10, atol=1e-14)).integrate(problem, np.zeros(6), 0.0, 30)
    np.testing.assert_array_equal(run.impact_stops, reference.impact_stops)
    np.testing.assert_allclose(run.impact_times, reference.impact_times, rtol=0, atol=1e-8)
    assert (run.stats["sticks"], run.stats["releases"]) == (reference.stats["sticks"], reference.stats["releases"])
    if engine is ENGINE:
        k = int(run.impact_times[np.flatnonzero(through)[-1]] / problem.period)
        state, time = run.strobe_states[k], run.strobe_times[k]
        image = ENGINE.strobe_map(problem, state, time)
        assert np.any(image.impact_stops == 1) and np.all(np.isfinite(image.jacobian))
        scale = 2e-4 * np.array([1.0, 1.0, 1.0, problem.omega, problem.omega, problem.omega])
        jacobian = image.jacobian * scale[None, :] / scale[:, None]
        difference = _finite_difference(problem, state, time, 100.0 * scale) * scale[None, :] / scale[:, None]
        assert np.max(np.abs(difference - jacobian)) <= 1e-6 * np.max(np.abs(jacobian))


class _OscillatorMap:
    """The one-period stroboscopic map of an impact oscillator at t = 0, as :func:`shoot` wants it."""

    dimension = 2
    parameter_names = ("clearance",)
    parameter_scale = np.array([0.1])

    def __init__(self, problem: ImpactProblem) -> None:
        self.problem = problem
        self.state_scale = np.array([1.0, problem.omega])

    def evaluate(self, y: np.ndarray, p: np.ndarray) -> MapEvaluation:
        image = ENGINE.strobe_map(self.problem, np.asarray(y, dtype=float), 0.0)
        return MapEvaluation(image.state, image.jacobian)


@pytest.mark.parametrize(("w", "r", "sigma"), [(2.5, 0.8, 0.0), (2.5, 0.8, -0.1), (2.2, 0.9, 0.0), (2.5, 0.5, 0.05)])
def test_budd_dux_period_one_impact_velocity(w: float, r: float, sigma: float) -> None:
    """Budd & Dux (Phil. Trans. R. Soc. A 347 (1994) 365): x'' + x = cos(w t), x <= sigma, x' -> -r x'. The impact
    velocity V of a period-one orbit lies on (sigma + c V / 2)^2 + ((1 - r) V / (2 w))^2 = gamma^2 with
    gamma = 1 / (1 - w^2), c = (1 + r) sin T / (1 - cos T), T = 2 pi / w (undamped: Re(lambda) = 0). The orbit is
    found by shooting on the engine's map (after settling onto it); V equals the ellipse's positive root to 1e-9
    (measured 4e-13). The flow keeps areas (no damping) and an impact's saltation matrix has determinant r^2, so
    det of the monodromy matrix = r^2 (1e-10)."""
    problem = ImpactProblem(LinearStructure([[1.0]], [[1.0]]), (Stop(RigidStop(sigma, r), 0),), HarmonicForce(1.0, w / (2.0 * math.pi)))
    settled = ENGINE.integrate(problem, np.array([min(sigma, 0.0) - 0.1, 0.0]), 0.0, 400).strobe_states[-1]
    orbit = shoot(_OscillatorMap(problem), settled, [sigma])
    image = ENGINE.strobe_map(problem, orbit.state, 0.0)
    assert image.impact_velocities.size == 1
    period = 2.0 * math.pi / w
    c = (1.0 + r) * math.sin(period) / (1.0 - math.cos(period))
    gamma = 1.0 / (1.0 - w * w)
    roots = np.roots([c * c / 4.0 + (1.0 - r) ** 2 / (4.0 * w * w), sigma * c, sigma * sigma - gamma * gamma])
    velocity = float(image.impact_velocities[0])
    assert np.min(np.abs(roots - velocity)) <= 1e-9 * velocity
    np.testing.assert_allclose(np.linalg.det(orbit.monodromy), r * r, rtol=1e-10)


def test_refusals_name_the_cause() -> None:
    """A harmonic load at an undamped natural frequency has no bounded (or well-conditioned) response; two stops pushed at once are not
    held (NotImplementedError naming both); a state of the wrong size is refused."""
    resonant = ImpactProblem(LinearStructure([[1.0]], [[(2.0 * math.pi) ** 2]]), (Stop(RigidStop(0.1, 0.5), 0),), HarmonicForce(1.0, 1.0))
    with pytest.raises(ValueError, match=r"\(relative\) from the natural frequency 1 Hz of an undamped mode: the harmonic response there is ill-conditioned"):
        ENGINE.integrate(resonant, np.zeros(2), 0.0, 1)
    tables = (Stop(RigidStop(0.0, 0.5), 0, side="lower"), Stop(RigidStop(0.0, 0.5), 1, side="lower"))
    two = ImpactProblem(LinearStructure(np.eye(2), np.zeros((2, 2))), tables, HarmonicForce(0.0, 1.0, static=(-GRAVITY, -GRAVITY)))
    with pytest.raises(NotImplementedError, match=r"two stops at once \(stop 0: x1 >= .*stop 1: x2 >= "):
        ENGINE.integrate(two, np.zeros(4), 0.0, 1)
    with pytest.raises(ValueError, match="state: expected 4 values"):
        ENGINE.integrate(two, np.zeros(3), 0.0, 1)


def test_a_free_free_pair_held_together_by_a_relative_stop() -> None:
    """Two masses joined by a spring and nothing else (a rigid-body mode), with a stop between them and R = 0: held
    on the stop they move as one free body, whose reduced stiffness T^T K T is round-off alone (1e-29 N/m here). The
    held flow must treat it as the rigid-body mode it is (it was refused as 'a zero eigenvalue ... not a rigid-body
    mode'). Impulses between the two conserve momentum, so over whole periods of the force the momentum returns to
    its start, 0, to round-off; the compiled and the Python engines agree."""
    structure = LinearStructure([[1.0, 0.0], [0.0, 0.2]], [[1000.0, -1000.0], [-1000.0, 1000.0]], coordinates=("a", "b"))
    problem = ImpactProblem(structure, (Stop(RigidStop(0.001, 0.0), 1, other=0),), HarmonicForce(20.0, 12.0, weights=(0.0, 1.0)))
    runs = [engine(EngineSettings()).integrate(problem, np.zeros(4), 0.0, 20) for engine in (ExactEngine, PythonExactEngine)]
    for run in runs:
        assert run.stats["sticks"] > 0
        momentum = run.strobe_states[:, 2] + 0.2 * run.strobe_states[:, 3]
        assert np.max(np.abs(momentum)) <= 1e-12 * 20.0 / problem.omega  # the force's impulse over a quarter period [N s]
    scale = float(np.max(np.abs(runs[1].strobe_states[:, :2])))  # the strobes' displacements [m]
    np.testing.assert_allclose(runs[0].strobe_states[:, :2], runs[1].strobe_states[:, :2], rtol=0.0, atol=1e-9 * scale)
