"""The event-loop template (engines/event_loop.py) through its engines: the contact law at every impact, sticking
and release, strobes at period boundaries, and the same sticking decisions as the exact engine."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.engines.base import MODE_FREE, MODE_STUCK, Trajectory
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

TIGHT = EngineSettings(rtol=1e-10, atol=1e-14)
EVENT_LOOP_ENGINES = ("momentary_adams", "momentary_bdf", "solve_ivp_DOP853")


def _states_after(trajectory: Trajectory, times: np.ndarray) -> np.ndarray:
    """The segment state that starts at each of ``times`` (the state just after the event there)."""
    index = np.searchsorted(trajectory.segments[:, 0], times)
    return trajectory.segment_states[index]


@pytest.mark.timeout(60)
@pytest.mark.parametrize("engine", EVENT_LOOP_ENGINES)
def test_restitution_law_at_every_impact(engine: str) -> None:
    """25 Hz, R = 0.4, from rest: every impact leaves at X2 = Delta with X2' = -R v and impulse M2 (1 + R) v."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.4), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    trajectory = make_engine(engine, TIGHT).integrate(problem, np.zeros(4), 0.0, 15)
    assert trajectory.impact_times.size >= 10 and trajectory.stats["sticks"] == 0
    assert np.all(trajectory.impact_velocities > 0.0)
    after = _states_after(trajectory, trajectory.impact_times)
    np.testing.assert_allclose(after[:, 1], PAPER_CLEARANCE, rtol=1e-14)
    np.testing.assert_allclose(after[:, 3], -0.4 * trajectory.impact_velocities, rtol=1e-14)
    np.testing.assert_allclose(trajectory.impulses, PAPER_SYSTEM.m2 * 1.4 * trajectory.impact_velocities, rtol=1e-14)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("engine", EVENT_LOOP_ENGINES)
def test_sticking_at_zero_restitution_and_release(engine: str) -> None:
    """R = 0, the stop 0.1 mm away at 10 Hz: every impact ends in sticking (impulse M2 v), held while the holding force
    B2 X1' + K2 (X1 - Delta) is positive, released where it falls to zero (to the tolerance), then free flight."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(1e-4, 0.0), HarmonicForce(PAPER_AMPLITUDE, 10.0))
    trajectory = make_engine(engine, TIGHT).integrate(problem, np.zeros(4), 0.0, 10)
    stuck = trajectory.segments[:, 2] == MODE_STUCK
    assert trajectory.stats["sticks"] >= 9 and trajectory.stats["releases"] >= 9
    np.testing.assert_allclose(trajectory.impulses, PAPER_SYSTEM.m2 * trajectory.impact_velocities, rtol=1e-14)
    starts = trajectory.segment_states[stuck]
    assert np.all(starts[:, 3] == 0.0)  # exact: the law sets X2' = 0 when the absorber sticks
    assert np.all(problem.holding_force(starts[:, 0], starts[:, 2]) >= 0.0)
    # the free segment after each stuck one starts where the holding force has fallen to zero
    released = np.flatnonzero(stuck[:-1] & (trajectory.segments[1:, 2] == MODE_FREE)) + 1
    assert released.size >= 9
    leaving = trajectory.segment_states[released]
    scale = PAPER_SYSTEM.k2 * 1e-4 + PAPER_SYSTEM.b2 * problem.velocity_scale()
    np.testing.assert_allclose(problem.holding_force(leaving[:, 0], leaving[:, 2]), 0.0, atol=1e-6 * scale)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("engine", EVENT_LOOP_ENGINES)
def test_strobes_at_period_boundaries(engine: str) -> None:
    """Strobe k is at t_start + k T to the last bit (impacts in between or not)."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.4), HarmonicForce(PAPER_AMPLITUDE, 25.0, 0.3))
    t_start = 0.0123
    trajectory = make_engine(engine, TIGHT).integrate(problem, np.zeros(4), t_start, 12)
    expected = t_start + np.arange(13) * problem.period
    np.testing.assert_allclose(trajectory.strobe_times, expected, rtol=0.0, atol=4 * np.spacing(expected.max()))


@pytest.mark.timeout(60)
def test_exact_and_event_loop_make_the_same_sticking_decisions() -> None:
    """One chattering case (R = 0.3, 0.1 mm at 10 Hz): the shared contact law sticks the absorber at the same
    impacts in exact and in the event loop, and releases it at the same times."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(1e-4, 0.3), HarmonicForce(PAPER_AMPLITUDE, 10.0))
    reference = ExactEngine().integrate(problem, np.zeros(4), 0.0, 8)
    trial = make_engine("momentary_adams", TIGHT).integrate(problem, np.zeros(4), 0.0, 8)
    assert trial.stats["sticks"] == reference.stats["sticks"] >= 7
    assert trial.stats["releases"] == reference.stats["releases"]
    stuck = [t.segments[t.segments[:, 2] == MODE_STUCK, :2] for t in (reference, trial)]
    np.testing.assert_allclose(stuck[1], stuck[0], atol=1e-6 * problem.period)


@pytest.mark.parametrize("engine", ["exact", "momentary_adams", "solve_ivp_DOP853"])
def test_rigid_engines_refuse_a_bumper(engine: str) -> None:
    problem = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(PAPER_CLEARANCE, 250.0, 0.3), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    with pytest.raises(TypeError, match=f"engine '{engine.split('_')[0] if engine.startswith('momentary') else engine}' solves a RigidStop"):
        make_engine(engine).integrate(problem, np.zeros(4), 0.0, 1)


@pytest.mark.parametrize("engine", ["exact", "momentary"])
def test_a_negative_period_count_is_refused(engine: str) -> None:
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.4), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    with pytest.raises(ValueError, match="periods = -1"):
        make_engine(engine).integrate(problem, np.zeros(4), 0.0, -1)


def test_a_start_beyond_the_stop_is_refused() -> None:
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.4), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    with pytest.raises(ValueError, match=r"penetrates stop 0 \(x2 <= "):
        make_engine("momentary").integrate(problem, np.array([0.0, 2 * PAPER_CLEARANCE, 0.0, 0.0]), 0.0, 1)


def test_swept_sine_is_refused_by_a_stepping_engine() -> None:
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.4), SweptSine(PAPER_AMPLITUDE, 24.0, 25.0, 0.1))
    with pytest.raises(TypeError, match="not a HarmonicForce"):
        make_engine("momentary").integrate(problem, np.zeros(4), 0.0, 1)
    assert math.isfinite(problem.amplitude)
