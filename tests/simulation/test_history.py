"""Time histories of every engine (``time_history``, ``SteadyResult.history``): the exact engine against an independent
DOP853 integration between impacts and Newton's restitution law at them, the integrators against exact (rigid stop)
and against a tight run of their own model (bumper), strobe samples against strobe states, and ``steady_state`` by
engine name."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vibroimpact import PAPER_SYSTEM, HarmonicForce, ImpactProblem, KelvinVoigtBumper, RigidStop, Stop, SteadySettings, TimeHistory, steady_state, time_history
from vibroimpact.engines.registry import ENGINES, EngineSettings, make_engine
from vibroimpact.engines.momentary import MomentaryEngine
from vibroimpact.simulation.steady import SteadyResult

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

RESTITUTION = 0.2
#: The paper's stop as a stop on the absorber's coordinate (index 1), 3 mm above it; 10 N at 25 Hz: one impact a period.
RIGID = ImpactProblem(PAPER_SYSTEM, (Stop(RigidStop(PAPER_CLEARANCE, RESTITUTION), coordinate=1),), HarmonicForce(PAPER_AMPLITUDE, 25.0))
#: A stiff bumper (500 Hz, loss factor 0.3) at the same clearance.
BUMPER = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(PAPER_CLEARANCE, 500.0, 0.3), HarmonicForce(PAPER_AMPLITUDE, 25.0))
#: Length and velocity scales of the motion [m, m s-1]: the clearance, and w times it.
LENGTH = PAPER_CLEARANCE
SPEED = RIGID.omega * PAPER_CLEARANCE
PER_PERIOD = 200


@pytest.fixture(scope="module")
def steady() -> SteadyResult:
    """The exact engine's period-one steady state of :data:`RIGID`."""
    result = steady_state("exact", RIGID)
    assert result.converged and result.multiplicity == 1
    return result


def _grid(t_start: float, periods: int, per_period: int = PER_PERIOD) -> np.ndarray:
    return t_start + np.arange(periods * per_period + 1) * (RIGID.period / per_period)


def _free_flight(y0: np.ndarray, t0: float, times: np.ndarray) -> np.ndarray:
    """DOP853 at rtol 1e-13 on the free flight y' = A y + Re(b e^{jwt}) + b0 (the problem's matrices, nothing of the
    engines), states at ``times`` (> t0), rows."""
    a, b, b0 = RIGID.first_order()

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        return a @ y + (b * np.exp(1j * RIGID.omega * t)).real + b0

    solution = solve_ivp(rhs, (t0, float(times[-1])), y0, method="DOP853", rtol=1e-13, atol=1e-16, t_eval=times, dense_output=False)
    assert solution.success
    return solution.y.T


def test_exact_history_is_the_free_flight_between_impacts_and_restitutes_at_them(steady: SteadyResult) -> None:
    """Between two impacts the exact samples are an independent DOP853 integration started from the sample after the
    first (to 1e-9 of the clearance and of w times it); integrated on to the next impact's time, that flight meets the
    stop there (gap within 1e-9 of the clearance) and the sample at the impact's time is the state just after it:
    x2'(t+) = -R x2'(t-) (1e-8 relative), the approach speed recorded as the history's contact velocity."""
    coarse = steady.history(periods=4, samples_per_period=PER_PERIOD)
    assert coarse.engine == "exact" and coarse.contact_times.size == 4 and np.all(coarse.contact_stops == 0)
    # the same run sampled on the grid and at the impacts themselves
    times = np.sort(np.concatenate([coarse.time, coarse.contact_times]))
    history = time_history("exact", RIGID, steady.end_state, steady.end_time, times)
    np.testing.assert_allclose(history.contact_times, coarse.contact_times, rtol=0, atol=1e-12 * RIGID.period)
    at_contact = np.searchsorted(history.time, history.contact_times)
    for first, second, speed in zip(at_contact[:-1], at_contact[1:], history.contact_velocities[1:]):
        # from the state just after the first impact, through the samples, to the second impact
        flight = _free_flight(history.states[first], float(history.time[first]), history.time[first + 1 : second + 1])
        np.testing.assert_allclose(flight[:-1, :2], history.displacement[first + 1 : second], rtol=0, atol=1e-9 * LENGTH)
        np.testing.assert_allclose(flight[:-1, 2:], history.velocity[first + 1 : second], rtol=0, atol=1e-9 * SPEED)
        before = flight[-1]
        assert abs(before[1] - PAPER_CLEARANCE) <= 1e-9 * LENGTH
        assert before[3] == pytest.approx(speed, rel=1e-8)
        after = history.velocity[second]
        assert after[1] == pytest.approx(-RESTITUTION * before[3], rel=1e-8)
        # the impulse acts on the absorber alone: the main mass's velocity goes through
        assert after[0] == pytest.approx(before[2], rel=1e-8, abs=1e-9 * SPEED)
        assert history.displacement[second, 1] == pytest.approx(PAPER_CLEARANCE, rel=1e-12)


@pytest.mark.parametrize("engine", ["momentary", "momentary_bdf", "solve_ivp_DOP853", "exact_python", "python_cvode"])
def test_integrator_histories_agree_with_exact(steady: SteadyResult, engine: str) -> None:
    """Four periods of the steady motion from the same state: each rigid-stop engine's samples (its own interpolation,
    rtol 1e-8) within 1e-6 of the clearance and 1e-5 of w times it of the exact engine's (measured: 3e-10 m, 6e-8
    m s-1 at worst, BDF), the same impacts within 1e-6 T."""
    built = MomentaryEngine(compiled=False) if engine == "python_cvode" else make_engine(engine)
    times = _grid(steady.end_time, 4)
    reference = steady.history(periods=4, samples_per_period=PER_PERIOD)
    history = time_history(built, RIGID, steady.end_state, steady.end_time, times)
    np.testing.assert_allclose(history.displacement, reference.displacement, rtol=0, atol=1e-6 * LENGTH)
    np.testing.assert_allclose(history.velocity, reference.velocity, rtol=0, atol=1e-5 * SPEED)
    assert history.contact_times.shape == reference.contact_times.shape
    np.testing.assert_allclose(history.contact_times, reference.contact_times, rtol=0, atol=1e-6 * RIGID.period)
    np.testing.assert_allclose(history.contact_velocities, reference.contact_velocities, rtol=1e-5)


@pytest.mark.parametrize("engine", ["compliant", "compliant_cvode_bdf", "compliant_exact"])
def test_bumper_histories_agree_with_a_tight_run(engine: str) -> None:
    """Ten periods from rest against the stiff bumper: at the default rtol 1e-8 the samples are within 1e-5 of the
    clearance and 1e-4 of w times it of an IDA run at rtol 1e-11 (measured 2e-9 m and 5e-6 m s-1 for IDA, 4.5e-9 m
    and 1.1e-5 m s-1 for CVODE BDF: the velocity swings through a 500 Hz contact; the closed form's samples are
    within IDA's own error), the contact onsets within 1e-6 T; a sample at rest is the start."""
    times = _grid(0.0, 10)
    reference = time_history(make_engine("compliant", EngineSettings(rtol=1e-11, atol=1e-15)), BUMPER, np.zeros(4), 0.0, times)
    history = time_history(engine, BUMPER, np.zeros(4), 0.0, times)
    assert history.contact_times.size >= 8 and history.contact_times.shape == reference.contact_times.shape
    np.testing.assert_allclose(history.displacement, reference.displacement, rtol=0, atol=1e-5 * LENGTH)
    np.testing.assert_allclose(history.velocity, reference.velocity, rtol=0, atol=1e-4 * SPEED)
    np.testing.assert_allclose(history.contact_times, reference.contact_times, rtol=0, atol=1e-6 * RIGID.period)
    assert np.all(np.abs(history.states[0]) <= 0.0)  # exact: the start at rest is given back
    # the bumper is entered: samples beyond the clearance, by less than the rigid stop's rebound would allow
    assert float(history.displacement[:, 1].max()) > PAPER_CLEARANCE


@pytest.mark.parametrize(("engine", "problem"), [("exact", RIGID), ("momentary", RIGID), ("solve_ivp_RK45", RIGID), ("compliant", BUMPER), ("compliant_cvode_adams", BUMPER), ("compliant_exact", BUMPER)])
def test_samples_at_strobe_times_are_the_strobe_states(engine: str, problem: ImpactProblem) -> None:
    """A run sampled at its period boundaries gives its strobe states (to 1e-12 of the motion's scale: the exact
    engine evaluates the piece as its loop does, the integrators return the same state there); the exact engine's
    history at strobe times is also its plain ``integrate``'s strobes."""
    built = make_engine(engine)
    start = np.array([0.0, 0.001, 0.0, 0.0])
    times = _grid(0.0, 6, 7)  # a few samples between boundaries, every 7th a boundary
    trajectory, states = built.sample(problem, start, 0.0, 6, times)
    scale = np.array([LENGTH, LENGTH, SPEED, SPEED])
    np.testing.assert_allclose(states[::7] / scale, trajectory.strobe_states / scale, rtol=0, atol=1e-12)
    if engine == "exact":
        plain = built.integrate(problem, start, 0.0, 6)
        history = time_history(engine, problem, start, 0.0, plain.strobe_times)
        np.testing.assert_allclose(history.states / scale, plain.strobe_states / scale, rtol=0, atol=1e-12)


def _leaves(value: object) -> list[np.ndarray]:
    """A result's compared values as numeric arrays (dataclasses field by field; None as an empty array)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return [leaf for f in dataclasses.fields(value) if f.compare for leaf in _leaves(getattr(value, f.name))]
    return [np.zeros(0) if value is None else np.asarray(value)]


@pytest.mark.parametrize("name", ["exact", "momentary"])
def test_steady_state_by_name_is_steady_state_with_the_engine(name: str) -> None:
    """Bit for bit: the name builds the registered engine with default settings."""
    by_name = steady_state(name, RIGID, "pgf", SteadySettings(max_periods=200))
    by_object = steady_state(make_engine(name, EngineSettings()), RIGID, "pgf", SteadySettings(max_periods=200))
    assert by_name.engine is not None and by_name.engine.capabilities == ENGINES[name].capabilities and by_name.problem is RIGID
    mine, theirs = _leaves(by_name), _leaves(by_object)
    assert len(mine) == len(theirs) > 20
    for a, b in zip(mine, theirs):
        np.testing.assert_array_equal(a, b)  # NaN where NaN


def test_an_unknown_engine_name_is_refused_naming_the_registered_ones() -> None:
    with pytest.raises(ValueError, match="engine 'exakt' is unknown: use one of exact, exact_python, momentary.*compliant"):
        steady_state("exakt", RIGID)
    with pytest.raises(ValueError, match="engine 'exakt' is unknown"):
        time_history("exakt", RIGID, np.zeros(4), 0.0, np.array([0.0]))
    with pytest.raises(TypeError, match="neither an engine nor the name"):
        steady_state(3, RIGID)  # type: ignore[arg-type]


def test_a_linear_answer_has_its_closed_form_history() -> None:
    """Where the linear steady state clears the stop (1 N: amplitude well under 3 mm) the answer is not integrated;
    its history x0 + Re(X e^{jwt}) is the exact engine's run from it, which never reaches the stop (1e-10 of the
    amplitude), and periodic."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, RESTITUTION), HarmonicForce(1.0, 25.0))
    result = steady_state("exact", problem)
    assert not result.integrated
    history = result.history(periods=2, samples_per_period=50)
    assert history.engine == "linear" and history.contact_times.size == 0 and history.time.size == 101
    np.testing.assert_allclose(history.states[0], result.end_state, rtol=0, atol=1e-15)
    run = time_history("exact", problem, result.end_state, result.end_time, history.time)
    amplitude = float(np.max(np.abs(history.displacement)))
    assert 0.0 < amplitude < PAPER_CLEARANCE and run.contact_times.size == 0
    np.testing.assert_allclose(run.displacement, history.displacement, rtol=0, atol=1e-10 * amplitude)
    np.testing.assert_allclose(run.velocity, history.velocity, rtol=0, atol=1e-10 * amplitude * problem.omega)
    np.testing.assert_allclose(history.states[-1], history.states[0], rtol=0, atol=1e-12 * amplitude * problem.omega)


def test_history_checks_its_input(steady: SteadyResult) -> None:
    with pytest.raises(ValueError, match="increasing times from t_start"):
        time_history("exact", RIGID, steady.end_state, steady.end_time, np.array([steady.end_time - 1.0]))
    with pytest.raises(ValueError, match="increasing times"):
        time_history("exact", RIGID, steady.end_state, steady.end_time, steady.end_time + np.array([0.02, 0.01]))
    with pytest.raises(ValueError, match="periods = 0 is out of range"):
        steady.history(periods=0)
    with pytest.raises(ValueError, match="no history"):
        dataclasses.replace(steady, engine=None).history()
    with pytest.raises(ValueError, match="displacement: expected shape"):
        TimeHistory(np.zeros(3), np.zeros((2, 2)), np.zeros((3, 2)), np.zeros(0), np.zeros(0, dtype=np.int64), np.zeros(0), ("x1", "x2"), "exact")
    history = steady.history(periods=1, samples_per_period=10)
    np.testing.assert_array_equal(history.coordinate(PAPER_SYSTEM.structure.coordinates[1]), history.displacement[:, 1])
    with pytest.raises(ValueError, match="is not a coordinate"):
        history.coordinate("nope")
    assert not history.displacement.flags.writeable
