"""Engine ``exact``: closed-form propagation with guaranteed contact detection."""

from __future__ import annotations


import numpy as np
import pytest

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.engines.base import MODE_STUCK

from vibroimpact.engines.exact import ExactEngine

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.model.system import TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE
from tests.engine_cases import energy_budget, linear_state, mechanical_energy, pgf_start

ENGINE = ExactEngine()


@pytest.mark.parametrize(("frequency", "restitution"), [(25.0, 0.2), (24.0, 0.0), (40.0, 0.2), (26.0, 0.6)])
def test_stays_on_stable_pgf_orbit(frequency: float, restitution: float) -> None:
    """Started on a stable one-impact orbit, it impacts once per period at t = k T with the PGF impulse, to ~1e-12."""
    problem, state, t0, orbit = pgf_start(frequency, restitution)
    trajectory = ENGINE.integrate(problem, state, t0, 200)
    assert trajectory.impulses.size == 200
    np.testing.assert_allclose(trajectory.impulses, orbit.impulse[0], rtol=1e-10)
    phases = (trajectory.impact_times * frequency + 0.5) % 1.0 - 0.5
    np.testing.assert_allclose(phases, 0.0, atol=1e-10)
    np.testing.assert_allclose(trajectory.strobe_states[-1], state, rtol=0, atol=1e-11 * np.abs(state).max())


def test_leaves_unstable_pgf_orbit() -> None:
    """At 38 Hz (R = 0.2) the orbit's Floquet modulus is 1.108: round-off grows until the motion is elsewhere."""
    problem, state, t0, _orbit = pgf_start(38.0, 0.2)
    trajectory = ENGINE.integrate(problem, state, t0, 1000)
    assert np.abs(trajectory.strobe_states[-1] - state).max() > 1e-3 * np.abs(state).max()


@pytest.mark.timeout(60)
def test_far_clearance_is_the_linear_solution() -> None:
    """No contact ever: the strobe states are the linear steady state's, to round-off."""
    problem = ImpactProblem(TwoDofSystem(m1=1.0, m2=0.1, k1=25_000.0, k2=4_300.0, b1=0.8, b2=0.08), RigidStop(1.0, 0.2), HarmonicForce(PAPER_AMPLITUDE, 23.0))
    start = linear_state(problem)
    trajectory = ENGINE.integrate(problem, start, 0.0, 100)
    assert trajectory.impulses.size == 0 and trajectory.stats["events"] == 0
    np.testing.assert_allclose(trajectory.strobe_states, np.broadcast_to(start, trajectory.strobe_states.shape), atol=1e-12 * np.abs(start).max())


@pytest.mark.timeout(60)
@pytest.mark.parametrize("margin", [-5e-10, 5e-10])
def test_grazing_contact_is_never_missed(margin: float, system: TwoDofSystem) -> None:
    """The linear orbit's maximum X2 lies 0.5 nm beyond (or short of) the stop: one impact (or none) per period."""
    frequency = 30.0
    amplitude_x2 = PAPER_AMPLITUDE * abs(paper_linear_response(system, omega=2 * np.pi * frequency, amplitude=1.0).x2)
    problem = ImpactProblem(system, RigidStop(amplitude_x2 + margin, 0.9), HarmonicForce(PAPER_AMPLITUDE, frequency))
    trajectory = ENGINE.integrate(problem, linear_state(problem), 0.0, 3)
    if margin < 0:
        assert trajectory.impulses.size >= 1
        assert trajectory.impact_velocities[0] < 1e-3  # a near-tangent touch
    else:
        assert trajectory.impulses.size == 0


@pytest.mark.parametrize(("frequency", "restitution"), [(25.0, 0.2), (38.0, 0.2), (22.0, 0.8)])
def test_energy_balance(frequency: float, restitution: float) -> None:
    """Energy change = input work - viscous dissipation - impact loss M2 (1 - R^2) v^2 / 2, over 20 periods."""
    problem, state, t0, _orbit = pgf_start(frequency, restitution)
    perturbed = state + np.array([1e-5, -1e-5, 0.0, 0.0])
    budget = energy_budget(ENGINE.integrate(problem, perturbed, t0, 20))
    assert budget["impact_loss"] > 0.01 * budget["work"]
    balance = budget["work"] - budget["dissipation"] - budget["impact_loss"]
    assert budget["change"] == pytest.approx(balance, abs=1e-9 * budget["work"])


@pytest.mark.timeout(60)
def test_elastic_impacts_without_damping_conserve_energy() -> None:
    """R = 1, B1 = B2 = 0: energy changes only by the work of the force; impacts lose nothing."""
    undamped = TwoDofSystem(m1=1.0, m2=0.1, k1=25_000.0, k2=4_300.0)
    problem = ImpactProblem(undamped, RigidStop(2e-3, 1.0), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    trajectory = ENGINE.integrate(problem, np.zeros(4), 0.0, 30)
    assert trajectory.impulses.size > 10
    budget = energy_budget(trajectory)
    assert budget["dissipation"] == 0.0 and abs(budget["impact_loss"]) < 1e-12 * abs(budget["work"])  # exact: no dashpot: a sum of zeros
    assert budget["change"] == pytest.approx(budget["work"], abs=1e-10 * mechanical_energy(undamped, trajectory.strobe_states).max())


@pytest.mark.timeout(60)
@pytest.mark.parametrize("restitution", [0.0, 0.05, 0.3])
def test_chattering_ends_in_sticking_and_release(restitution: float, system: TwoDofSystem) -> None:
    """Quasi-static forcing (10 Hz) with Delta = 0.1 mm below the primary mass's 0.47 mm motion: the spring presses
    the absorber on the stop, impacts accumulate (Zeno), it sticks and is released again every period; no hang;
    the stop only pushes (holding force >= 0) while stuck and X2 never exceeds Delta."""
    clearance = 1e-4
    problem = ImpactProblem(system, RigidStop(clearance, restitution), HarmonicForce(PAPER_AMPLITUDE, 10.0))
    trajectory = ENGINE.integrate(problem, np.zeros(4), 0.0, 30)
    assert trajectory.stats["sticks"] >= 29 and trajectory.stats["releases"] >= 29
    stuck = trajectory.segments[trajectory.segments[:, 2] == MODE_STUCK]
    times = np.concatenate([np.linspace(a, b, 7) for a, b, _ in stuck])
    y = ENGINE.dense(trajectory, times)
    assert np.all(problem.holding_force(y[:, 0], y[:, 2]) >= -1e-9)
    everywhere = ENGINE.dense(trajectory, np.linspace(trajectory.strobe_times[0], trajectory.strobe_times[-1], 20001))
    assert everywhere[:, 1].max() <= clearance * (1 + 1e-12)


@pytest.mark.timeout(60)
def test_zero_clearance(system: TwoDofSystem) -> None:
    """Delta = 0: the stop at the static equilibrium; impacts every period, X2 <= 0."""
    problem = ImpactProblem(system, RigidStop(0.0, 0.5), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    trajectory = ENGINE.integrate(problem, np.zeros(4), 0.0, 40)
    assert trajectory.impulses.size >= 30
    y = ENGINE.dense(trajectory, np.linspace(0.0, trajectory.strobe_times[-1], 5001))
    assert y[:, 1].max() <= 1e-15


def test_restitution_law_at_every_impact(system: TwoDofSystem) -> None:
    """Velocity just after each impact (from the next segment's start state) is -R times the velocity before."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.3), HarmonicForce(PAPER_AMPLITUDE, 26.0))
    trajectory = ENGINE.integrate(problem, np.zeros(4), 0.0, 40)
    starts = trajectory.segments[:, 0]
    after = trajectory.segment_states[np.searchsorted(starts, trajectory.impact_times)]
    np.testing.assert_allclose(after[:, 3], -0.3 * trajectory.impact_velocities, rtol=1e-12)
    np.testing.assert_allclose(trajectory.impulses, system.m2 * 1.3 * trajectory.impact_velocities, rtol=1e-14)


def test_rejects_a_start_inside_the_stop(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.3), HarmonicForce(PAPER_AMPLITUDE, 26.0))
    with pytest.raises(ValueError, match=r"penetrates stop 0 \(x2 <= "):
        ENGINE.integrate(problem, np.array([0.0, 0.004, 0.0, 0.0]), 0.0, 1)


def test_problem_validation(system: TwoDofSystem) -> None:
    with pytest.raises(ValueError, match=r"restitution = 1.5 is out of range: allowed \[0, 1\]"):
        ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 1.5), HarmonicForce(PAPER_AMPLITUDE, 26.0))
    with pytest.raises(ValueError, match="method = 'rk4' is not allowed"):
        EngineSettings(method="rk4")


def test_energy_balance_with_sticking(system: TwoDofSystem) -> None:
    """Sticking phases do no work (X2' = 0): the balance still closes, with chatter losses included."""
    problem = ImpactProblem(system, RigidStop(1e-4, 0.3), HarmonicForce(PAPER_AMPLITUDE, 10.0))
    trajectory = ENGINE.integrate(problem, np.zeros(4), 0.0, 10)
    assert trajectory.stats["sticks"] > 5
    budget = energy_budget(trajectory)
    balance = budget["work"] - budget["dissipation"] - budget["impact_loss"]
    assert budget["change"] == pytest.approx(balance, abs=1e-8 * abs(budget["work"]) + 1e-12)


def _start_at_impact(frequency: float, restitution: float) -> tuple[ImpactProblem, np.ndarray]:
    """The PGF orbit just after its impact at t = 0: every later impact falls exactly on a period boundary."""
    from tests.engine_cases import pgf_start

    problem, _state, _t0, orbit = pgf_start(frequency, restitution)
    zero = np.array([[0.0]])
    return problem, orbit.state(zero)[0, 0]


@pytest.mark.timeout(60)
@pytest.mark.parametrize("engine", ["exact", "momentary"])
def test_impacts_on_period_boundaries(engine: str) -> None:
    """One impact per period, each at a strobe time: counted once per period, strobes after the impact, no failure."""
    from vibroimpact.engines.momentary import MomentaryEngine
    from vibroimpact.simulation.steady import steady_state

    problem, state = _start_at_impact(25.0, 0.2)
    solver = ENGINE if engine == "exact" else MomentaryEngine(EngineSettings(rtol=1e-10, atol=1e-14))
    trajectory = solver.integrate(problem, state, 0.0, 30)
    assert np.all(trajectory.strobe_states[:, 1] <= problem.clearance)
    if engine == "exact":
        # exact to round-off: every impact is on a boundary, applied before that boundary's strobe
        assert trajectory.impact_times.size == 30
        np.testing.assert_allclose(trajectory.impact_times * 25.0, np.arange(1, 31), atol=1e-9)
        assert np.all(trajectory.strobe_states[1:, 3] < 0.0)
        assert steady_state(solver, problem, (0.0, state)).measures.impacts_per_period == 1.0  # exact: a count per period
    else:
        # an integrator lands within its error of the boundary, on either side: the last impact may fall after it
        assert trajectory.impact_times.size in (29, 30)
        np.testing.assert_allclose(trajectory.impact_times * 25.0, np.arange(1, trajectory.impact_times.size + 1), atol=1e-6)


@pytest.mark.timeout(60)
def test_rest_on_the_stop_without_forcing_does_not_livelock(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(0.0, 0.5), HarmonicForce(0.0, 25.0))
    trajectory = ENGINE.integrate(problem, np.zeros(4), 0.0, 3)
    assert trajectory.impact_times.size == 0  # and no livelock: the timeout mark bounds the run


def test_impact_ending_in_sticking_transfers_m2_v(system: TwoDofSystem) -> None:
    """The absorber stops dead: the impulse is M2 v (not M2 (1 + R) v) and the balance still closes."""
    problem = ImpactProblem(system, RigidStop(1e-4, 0.3), HarmonicForce(PAPER_AMPLITUDE, 10.0))
    trajectory = ENGINE.integrate(problem, np.zeros(4), 0.0, 5)
    stuck_starts = trajectory.segments[trajectory.segments[:, 2] == MODE_STUCK, 0]
    ending = np.isin(trajectory.impact_times, stuck_starts)
    assert ending.sum() >= 4
    np.testing.assert_allclose(trajectory.impulses[ending], system.m2 * trajectory.impact_velocities[ending], rtol=1e-14)
    np.testing.assert_allclose(trajectory.impulses[~ending], 1.3 * system.m2 * trajectory.impact_velocities[~ending], rtol=1e-14)


@pytest.mark.timeout(60)
def test_resting_on_the_stop_with_round_off_holding_force_does_not_livelock() -> None:
    """Found by the property tests: Delta = 0, R = 1, at rest on the stop, the force just starting to push. The holding
    force evaluates to 5.6e-17 N of round-off; its sign once decided 'not pushed', and zero-speed elastic impacts
    repeated at t = 0 until the event budget ran out. Round-off-sized forces now leave the decision to the
    derivatives: the absorber is held, then released."""
    

    s = TwoDofSystem(m1=0.5, m2=0.34916140783976635, k1=10000.0, k2=10934.225385165902, b1=0.0, b2=0.13323645201253634)
    problem = ImpactProblem(s, RigidStop(0.0, 1.0), HarmonicForce(0.5, 56.38618344739488, phase=0.0004942310000114958))
    trajectory = ExactEngine().integrate(problem, np.zeros(4), 0.0, 3)
    assert trajectory.stats["releases"] >= 1 and trajectory.stats["events"] < 100
    assert np.all(trajectory.strobe_states[:, 1] <= 1e-15)
