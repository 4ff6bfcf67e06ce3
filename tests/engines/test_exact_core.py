"""The compiled exact core against its pure-Python copy, and its Jacobians against finite differences."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.engines.exact_python import PythonExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.simulation.steady import start_state

ENGINE = ExactEngine()
#: (frequency [Hz], R, clearance [m], start): one impact per period, chatter and sticking, R = 0 sticking, a transient
CASES = [(25.0, 0.2, 0.003, "pgf"), (10.0, 0.3, 1e-4, "rest"), (10.0, 0.0, 1e-4, "rest"), (24.0, 0.5, 0.003, "rest"), (37.0, 0.8, 0.003, "pgf")]


def _problem(frequency: float, restitution: float, clearance: float) -> ImpactProblem:
    return ImpactProblem(PAPER_SYSTEM, RigidStop(clearance, restitution), HarmonicForce(10.0, frequency, 0.3))


@pytest.mark.parametrize(("frequency", "restitution", "clearance", "start"), CASES)
def test_compiled_core_repeats_the_python_engine(frequency: float, restitution: float, clearance: float, start: str) -> None:
    """Same impacts, sticks, releases, strobes and moments as the pure-Python loop, round-off apart: a chatter
    multiplies round-off by 1 / R at each bounce (impact times of the R = 0.3 chatter differ by up to 2.5e-10 s)."""
    problem = _problem(frequency, restitution, clearance)
    t, y = start_state(problem, start)
    compiled = ENGINE.integrate(problem, y, t, 12, moments=True)
    python = PythonExactEngine().integrate(problem, y, t, 12, moments=True)
    assert compiled.impact_times.size == python.impact_times.size > 0
    for key in ("sticks", "releases"):
        assert compiled.stats[key] == python.stats[key]
    np.testing.assert_allclose(compiled.impact_times, python.impact_times, rtol=0, atol=1e-8 * problem.period)
    np.testing.assert_allclose(compiled.impulses, python.impulses, rtol=0, atol=1e-7 * np.max(python.impulses))
    scale = np.max(np.abs(python.strobe_states), axis=0) + problem.clearance * np.array([1.0, 1.0, problem.omega, problem.omega])
    np.testing.assert_allclose(compiled.strobe_states / scale, python.strobe_states / scale, rtol=0, atol=1e-9)
    np.testing.assert_allclose(compiled.moments, python.moments, rtol=0, atol=1e-9 * np.max(np.abs(python.moments)))
    np.testing.assert_allclose(compiled.segments, python.segments, rtol=0, atol=1e-8 * problem.period)


def _finite_difference(problem: ImpactProblem, state: np.ndarray, t: float) -> np.ndarray:
    """Central differences of the one-period map; a step that would start inside the stop is taken one-sided."""
    scale = np.array([1.0, 1.0, problem.omega, problem.omega]) * (problem.clearance + 1e-3)
    columns = []
    for j in range(4):
        step = np.zeros(4)
        step[j] = 1e-7 * scale[j]
        if j == 1 and state[1] + step[1] > problem.clearance:
            ahead, behind, width = ENGINE.strobe_map(problem, state, t).state, ENGINE.strobe_map(problem, state - step, t).state, step[j]
        else:
            ahead = ENGINE.strobe_map(problem, state + step, t).state
            behind, width = ENGINE.strobe_map(problem, state - step, t).state, 2.0 * step[j]
        columns.append((ahead - behind) / width)
    return np.column_stack(columns)


@pytest.mark.parametrize(("frequency", "restitution", "clearance", "start"), [CASES[0], CASES[2], CASES[3], CASES[4]])
def test_jacobian_of_the_strobe_map_equals_finite_differences(frequency: float, restitution: float, clearance: float, start: str) -> None:
    """Transition matrices times saltation matrices (impacts, sticking, release) = the map's derivative, to the
    finite differences' own error (~1e-7 relative)."""
    problem = _problem(frequency, restitution, clearance)
    t, y = start_state(problem, start)
    run = ENGINE.integrate(problem, y, t, 10, jacobians=True)
    checked_events = 0
    for k in range(5, 10):
        state, time = run.strobe_states[k], run.strobe_times[k]
        jacobian = run.strobe_jacobians[k]
        image = ENGINE.strobe_map(problem, state, time)
        np.testing.assert_allclose(image.jacobian, jacobian, rtol=0, atol=1e-12 * np.max(np.abs(jacobian)))
        # to 1e-12 of the motion's scale (a velocity that passes near zero at the strobe has no relative accuracy)
        scale = np.array([1.0, 1.0, problem.omega, problem.omega]) * (problem.clearance + 1e-3)
        assert np.all(np.abs(image.state - run.strobe_states[k + 1]) <= 1e-12 * scale)
        difference = _finite_difference(problem, state, time)
        # a start stuck on the stop (X2 = Delta, X2' = 0, pushed) is held there: the Jacobian is that of the map on
        # the stop's surface, and a start below the stop (a free flight back onto it) is another, one-sided, branch
        stuck = abs(state[1] - problem.clearance) < 1e-18 and abs(state[3]) < 1e-18
        free = [0, 2] if stuck else [0, 1, 2, 3]
        assert np.max(np.abs(difference - jacobian)[:, free]) <= 2e-6 * np.max(np.abs(jacobian))
        checked_events += image.impact_times.size + image.releases
    assert checked_events > 0  # the periods checked have impacts (and, with R = 0, sticking and release)


def test_r0_case_sticks_and_releases_every_period() -> None:
    """The R = 0 case above exercises the sticking saltation and the release: it sticks and releases every period."""
    problem = _problem(10.0, 0.0, 1e-4)
    run = ENGINE.integrate(problem, np.zeros(4), 0.0, 10, jacobians=True)
    assert run.stats["sticks"] >= 9 and run.stats["releases"] >= 9
    # while stuck, X2 and X2' are held: the Jacobian's rows for them vanish over a period ending stuck or free again
    assert np.all(np.isfinite(run.strobe_jacobians))


def test_closest_approach_finds_a_near_grazing_flight() -> None:
    """A linear motion peaking just below the stop: the closest approach is its peak, found to round-off."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(1.0, 0.5), HarmonicForce(10.0, 20.0))
    t, y = start_state(problem, "linear")
    image = ENGINE.strobe_map(problem, y, t)
    peak = abs(complex(PAPER_SYSTEM.receptances(problem.omega).h12)) * 10.0
    assert image.impact_times.size == 0
    np.testing.assert_allclose(image.closest_approach, peak - 1.0, rtol=0, atol=1e-14)
    # and the Jacobian of an impact-free period is the flow's exp(A T)
    eigenvalues, vectors = np.linalg.eig(PAPER_SYSTEM.state_matrix)
    flow = np.real(vectors @ np.diag(np.exp(eigenvalues * problem.period)) @ np.linalg.inv(vectors))
    np.testing.assert_allclose(image.jacobian, flow, rtol=0, atol=1e-12 * np.max(np.abs(flow)))
