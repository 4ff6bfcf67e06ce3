"""Engine ``momentary`` (CVODE with contact events) against the exact engine and physical invariants."""

from __future__ import annotations


import numpy as np
import pytest

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.engines.base import MODE_STUCK

from vibroimpact.engines.exact import ExactEngine

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.event_loop import Model
from vibroimpact.engines.momentary import COMPILED_EVENTS, COMPILED_JACOBIAN, COMPILED_RHS, MomentaryEngine, compiled_parameters
from vibroimpact.engines.sundae import evaluate_compiled
from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.model.system import TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE
from tests.engine_cases import energy_budget, linear_state

TIGHT = EngineSettings(rtol=1e-10, atol=1e-14)


@pytest.mark.slow
@pytest.mark.timeout(60)
@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("method", ["adams", "bdf"])
@pytest.mark.parametrize(("frequency", "restitution"), [(25.0, 0.2), (38.0, 0.0)])
def test_agrees_with_exact_over_20_seconds(system: TwoDofSystem, method: str, frequency: float, restitution: float, compiled: bool) -> None:
    """From rest, 20 s: same number of impacts, impact times within 1e-9 s, strobe states within 1e-7 of their scale.

    (At 38 Hz with R = 0.2 the one-impact orbit is unstable and the motion sensitive to round-off: any two
    integrators part after a hundred impacts, so R = 0, whose orbit is stable, is used there.)"""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, restitution), HarmonicForce(PAPER_AMPLITUDE, frequency))
    periods = int(20 * frequency)
    reference = ExactEngine().integrate(problem, np.zeros(4), 0.0, periods)
    trial = MomentaryEngine(EngineSettings(rtol=1e-10, atol=1e-14, method=method), compiled=compiled).integrate(problem, np.zeros(4), 0.0, periods)
    assert trial.impact_times.size == reference.impact_times.size > 0.9 * periods
    np.testing.assert_allclose(trial.impact_times, reference.impact_times, rtol=0, atol=1e-9)
    np.testing.assert_allclose(trial.impulses, reference.impulses, rtol=1e-6)
    scale = np.abs(reference.strobe_states).max(axis=0)
    assert np.all(np.abs(trial.strobe_states - reference.strobe_states) <= 1e-7 * scale)


def test_error_follows_the_tolerance(system: TwoDofSystem) -> None:
    """Tighter rtol, smaller error against exact: impact-time error drops by > 30x from rtol 1e-6 to 1e-9."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    reference = ExactEngine().integrate(problem, np.zeros(4), 0.0, 100)
    errors = []
    for rtol in (1e-6, 1e-9):
        trial = MomentaryEngine(EngineSettings(rtol=rtol, atol=rtol * 1e-4)).integrate(problem, np.zeros(4), 0.0, 100)
        assert trial.impact_times.size == reference.impact_times.size
        errors.append(np.abs(trial.impact_times - reference.impact_times).max())
    assert errors[1] < errors[0] / 30


def _grazing_problems(system: TwoDofSystem, margin: float) -> list[ImpactProblem]:
    frequency = 30.0
    amplitude_x2 = PAPER_AMPLITUDE * abs(paper_linear_response(system, omega=2 * np.pi * frequency, amplitude=1.0).x2)
    return [ImpactProblem(system, RigidStop(amplitude_x2 + margin, 0.9), HarmonicForce(PAPER_AMPLITUDE, frequency, phase=phase)) for phase in np.linspace(0, 2 * np.pi, 24, endpoint=False)]


@pytest.mark.timeout(60)
@pytest.mark.parametrize("compiled", [True, False])
def test_grazing_contact_penetrating_half_a_nanometre_is_found(system: TwoDofSystem, compiled: bool) -> None:
    """The linear orbit overshoots the stop by 5e-10 m: every phase of the step grid finds the touch (exact does)."""
    for problem in _grazing_problems(system, -5e-10):
        trajectory = MomentaryEngine(compiled=compiled).integrate(problem, linear_state(problem), 0.0, 1)
        assert trajectory.impact_times.size == 1
        assert ExactEngine().integrate(problem, linear_state(problem), 0.0, 1).impact_times.size == 1


def test_grazing_contact_is_missed_without_the_guard(system: TwoDofSystem) -> None:
    """Proof that the guard is needed: plain CVODE root finding misses most of those touches."""
    found = sum(
        MomentaryEngine(grazing_guard=False).integrate(p, linear_state(p), 0.0, 1).impact_times.size for p in _grazing_problems(system, -5e-10)
    )
    assert found < 12


def test_grazing_without_contact_gives_none(system: TwoDofSystem) -> None:
    for problem in _grazing_problems(system, 5e-10)[:6]:
        assert MomentaryEngine().integrate(problem, linear_state(problem), 0.0, 2).impact_times.size == 0


@pytest.mark.timeout(60)
@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("restitution", [0.0, 0.05, 0.3])
def test_chattering_sticks_and_releases_like_exact(system: TwoDofSystem, restitution: float, compiled: bool) -> None:
    """Quasi-static case (10 Hz, Delta = 0.1 mm): stick and release every period; stuck time as the exact engine's."""
    problem = ImpactProblem(system, RigidStop(1e-4, restitution), HarmonicForce(PAPER_AMPLITUDE, 10.0))
    trial = MomentaryEngine(TIGHT, compiled=compiled).integrate(problem, np.zeros(4), 0.0, 30)
    reference = ExactEngine().integrate(problem, np.zeros(4), 0.0, 30)
    assert trial.stats["sticks"] == reference.stats["sticks"] >= 29
    assert trial.stats["releases"] == reference.stats["releases"]
    assert trial.stuck_time == pytest.approx(reference.stuck_time, rel=1e-6)
    stuck = trial.segments[:, 2] == MODE_STUCK
    assert np.all(trial.segment_states[stuck, 1] == problem.clearance)
    assert np.all(trial.strobe_states[:, 1] <= problem.clearance)


@pytest.mark.timeout(60)
def test_elastic_undamped_conserves_energy() -> None:
    """R = 1 and no damping: the energy change equals the work of the force."""
    undamped = TwoDofSystem(m1=1.0, m2=0.1, k1=25_000.0, k2=4_300.0)
    problem = ImpactProblem(undamped, RigidStop(2e-3, 1.0), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    trajectory = MomentaryEngine(TIGHT).integrate(problem, np.zeros(4), 0.0, 30)
    assert trajectory.impulses.size > 10
    budget = energy_budget(trajectory)
    assert abs(budget["impact_loss"]) < 1e-12 * abs(budget["work"])
    assert budget["change"] == pytest.approx(budget["work"], abs=1e-6 * abs(budget["work"]) + 1e-9)


def test_energy_balance_damped(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.4), HarmonicForce(PAPER_AMPLITUDE, 26.0))
    budget = energy_budget(MomentaryEngine(TIGHT).integrate(problem, np.zeros(4), 0.0, 20))
    balance = budget["work"] - budget["dissipation"] - budget["impact_loss"]
    assert budget["impact_loss"] > 0.01 * budget["work"]
    assert budget["change"] == pytest.approx(balance, abs=1e-6 * budget["work"])


def test_restitution_law_at_every_impact(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.3), HarmonicForce(PAPER_AMPLITUDE, 26.0))
    trajectory = MomentaryEngine().integrate(problem, np.zeros(4), 0.0, 40)
    after = trajectory.segment_states[np.searchsorted(trajectory.segments[:, 0], trajectory.impact_times)]
    np.testing.assert_allclose(after[:, 3], -0.3 * trajectory.impact_velocities, rtol=1e-14)
    np.testing.assert_array_equal(after[:, 1], problem.clearance)


@pytest.mark.timeout(60)
def test_zero_clearance(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(0.0, 0.5), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    trial = MomentaryEngine(TIGHT).integrate(problem, np.zeros(4), 0.0, 40)
    reference = ExactEngine().integrate(problem, np.zeros(4), 0.0, 40)
    assert trial.impact_times.size == reference.impact_times.size >= 30
    np.testing.assert_allclose(trial.impact_times, reference.impact_times, atol=1e-9)


@pytest.mark.timeout(60)
def test_far_clearance_is_the_linear_solution(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(1.0, 0.2), HarmonicForce(PAPER_AMPLITUDE, 23.0))
    start = linear_state(problem)
    trajectory = MomentaryEngine(TIGHT).integrate(problem, start, 0.0, 50)
    assert trajectory.impact_times.size == 0
    np.testing.assert_allclose(trajectory.strobe_states, np.broadcast_to(start, trajectory.strobe_states.shape), atol=1e-8 * np.abs(start).max())


@pytest.mark.timeout(60)
def test_start_at_the_stop_moving_into_it(system: TwoDofSystem) -> None:
    """CVODE reports no root at its initial time: the engine applies the contact itself, like exact does."""
    problem = ImpactProblem(system, RigidStop(1e-3, 0.5), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    state = np.array([0.0, 1e-3, 0.0, 0.1])
    for engine in (MomentaryEngine(), ExactEngine()):
        trajectory = engine.integrate(problem, state, 0.0, 2)
        assert trajectory.impact_times[0] == pytest.approx(0.0, abs=1e-15)
        assert trajectory.impact_velocities[0] == pytest.approx(0.1, rel=1e-12)
        assert np.all(trajectory.strobe_states[:, 1] <= problem.clearance)


@pytest.mark.timeout(60)
def test_rest_on_the_stop_without_forcing(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(0.0, 0.5), HarmonicForce(0.0, 25.0))
    assert MomentaryEngine().integrate(problem, np.zeros(4), 0.0, 3).impact_times.size == 0


def _finite_difference_jacobian(model: Model, t: float, y: np.ndarray) -> np.ndarray:
    """Central differences of the model's Python right-hand side, column by column."""
    columns = []
    for j in range(y.size):
        step = 1e-6 * max(abs(y[j]), 1e-3)
        ahead, behind = y.copy(), y.copy()
        ahead[j] += step
        behind[j] -= step
        columns.append((model.derivative(t, ahead) - model.derivative(t, behind)) / (2 * step))
    return np.array(columns).T


@pytest.mark.parametrize("moments", [False, True])
@pytest.mark.parametrize("stuck", [False, True])
def test_jacobians_given_to_cvode_are_the_derivative_of_the_rhs(system: TwoDofSystem, stuck: bool, moments: bool) -> None:
    """The Jacobian CVODE gets (compiled, and the Python fallback's) equals a finite difference of the right-hand side;
    the compiled right-hand side and events equal the Python ones (free flight and stuck, with and without moments)."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 27.0, phase=0.4))
    model = Model(problem, moments)
    model.stuck = stuck
    y = np.array([1.3e-3, -0.0 if stuck else -0.7e-3, 0.21, 0.0 if stuck else -0.35, *np.linspace(1e-5, 8e-5, model.size - 4)])
    t = 0.0123
    expected = _finite_difference_jacobian(model, t, y)
    python = np.zeros((model.size, model.size))
    model.jacobian(t, y, model.derivative(t, y), python)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(python, expected, rtol=1e-6, atol=1e-8 * scale)
    rates, compiled, values = evaluate_compiled(COMPILED_RHS, COMPILED_JACOBIAN, COMPILED_EVENTS, Model.NUM_EVENTS, compiled_parameters(model), t, y)
    np.testing.assert_allclose(compiled, expected, rtol=1e-6, atol=1e-8 * scale)
    np.testing.assert_allclose(rates, model.derivative(t, y), rtol=1e-13, atol=1e-13 * np.abs(rates).max())
    python_values = np.zeros(Model.NUM_EVENTS)
    model.events(t, y, python_values)
    np.testing.assert_allclose(values, python_values, rtol=1e-13, atol=1e-12)


def test_compiled_and_python_callbacks_take_the_same_steps(system: TwoDofSystem) -> None:
    """Both ways of calling CVODE run one algorithm: same impacts (to 1e-12 s) and the same right-hand-side count."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    compiled, python = (MomentaryEngine(compiled=flag).integrate(problem, linear_state(problem), 0.0, 10, moments=True) for flag in (True, False))
    assert compiled.impact_times.size == python.impact_times.size > 5
    np.testing.assert_allclose(compiled.impact_times, python.impact_times, rtol=0, atol=1e-12)
    np.testing.assert_allclose(compiled.moments, python.moments, rtol=1e-9)
    assert abs(compiled.stats["rhs_calls"] - python.stats["rhs_calls"]) <= 0.02 * python.stats["rhs_calls"]
