"""Steady states of the time-domain engines: against the PGF closed form, sweeps, cache and processes."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.engines.exact import ExactEngine

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.momentary import MomentaryEngine
from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.simulation.steady import steady_state
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.model.system import TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE
from tests.engine_cases import orbit_force


def pgf_values(system: TwoDofSystem, frequency: float, restitution: float) -> dict[str, float]:
    orbit = solve_one_impact(system, omega=np.array([2 * np.pi * frequency]), clearance=PAPER_CLEARANCE, restitution=restitution, amplitude=PAPER_AMPLITUDE)
    return {
        "x1": abs(orbit.harmonics()[0, 0]),
        "x2": abs(orbit.harmonics()[0, 1]),
        "force": abs(orbit_force(system, orbit)[0]),
        "impulse": float(orbit.impulse[0]),
    }


@pytest.mark.parametrize(("frequency", "restitution"), [(25.0, 0.2), (26.0, 0.6), (40.0, 0.2), (22.0, 0.0)])
def test_exact_steady_state_equals_pgf(system: TwoDofSystem, frequency: float, restitution: float) -> None:
    """At stable points the exact engine's measured steady state is the closed-form solution to ~1e-9."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, restitution), HarmonicForce(PAPER_AMPLITUDE, frequency))
    result = steady_state(ExactEngine(), problem, "pgf", SteadySettings(tolerance=1e-11, max_periods=3000))
    expected = pgf_values(system, frequency, restitution)
    m = result.measures
    assert result.converged and result.multiplicity == 1 and m.impacts_per_period == 1.0  # exact: a count per period
    assert abs(m.x1) == pytest.approx(expected["x1"], rel=1e-9)
    assert abs(m.x2) == pytest.approx(expected["x2"], rel=1e-9)
    assert abs(m.force) == pytest.approx(expected["force"], rel=1e-9)
    assert m.mean_impulse == pytest.approx(expected["impulse"], rel=1e-9)


def test_momentary_steady_state_equals_pgf_to_its_tolerance(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    result = steady_state(MomentaryEngine(EngineSettings(rtol=1e-10, atol=1e-14)), problem, "pgf", SteadySettings(tolerance=1e-9))
    expected = pgf_values(system, 25.0, 0.2)
    assert result.converged
    assert abs(result.measures.x1) == pytest.approx(expected["x1"], rel=1e-7)
    assert result.measures.mean_impulse == pytest.approx(expected["impulse"], rel=1e-7)


def test_linear_point_is_answered_without_integrating(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 30.0))
    result = steady_state(ExactEngine(), problem, "linear")
    assert not result.integrated and result.periods_used == 0
    assert abs(result.measures.x1) == pytest.approx(abs(paper_linear_response(system, omega=problem.omega, amplitude=PAPER_AMPLITUDE).x1), rel=1e-15)


def test_measured_linear_motion_has_exact_harmonics_and_rms(system: TwoDofSystem) -> None:
    """Integrating the linear steady state (no contact) measures its amplitude and RMS = amplitude / sqrt 2 exactly."""
    problem = ImpactProblem(system, RigidStop(1.0, 0.2), HarmonicForce(PAPER_AMPLITUDE, 30.0))
    response = paper_linear_response(system, omega=problem.omega, amplitude=PAPER_AMPLITUDE)
    state = np.array([response.x1.real, response.x2.real, (1j * problem.omega * response.x1).real, (1j * problem.omega * response.x2).real])
    result = steady_state(ExactEngine(), problem, (0.0, state), SteadySettings(tolerance=1e-10))
    m = result.measures
    assert result.integrated and m.impacts_per_period == 0.0  # exact: a count per period
    assert m.x1 == pytest.approx(complex(response.x1), rel=1e-11)
    assert m.x2_rms == pytest.approx(abs(response.x2) / np.sqrt(2), rel=1e-11)
    assert abs(m.force) == pytest.approx(abs(response.force), rel=1e-11)


@pytest.mark.parametrize("engine", [ExactEngine(), MomentaryEngine()])
def test_unstable_pgf_orbit_is_left(system: TwoDofSystem, engine: object) -> None:
    """At 38 Hz (R = 0.2, Floquet modulus 1.108) a start next to the orbit does not stay on it."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 38.0))
    result = steady_state(engine, problem, "pgf", SteadySettings(max_periods=300))  # type: ignore[arg-type]
    expected = pgf_values(system, 38.0, 0.2)
    assert not (result.converged and abs(abs(result.measures.x1) - expected["x1"]) < 1e-3 * expected["x1"])


def test_a_preloaded_stop_on_the_named_system_converges(system: TwoDofSystem) -> None:
    """A negative clearance (the stop preloads the absorber by 1 mm) on the paper's named system: the repeat test's
    scale is the general one, |Delta| + q |n . H|, positive; the paper's own Delta + q |H12| was negative at 40 Hz
    (-0.14 mm), so the strobes could never repeat and every such point was reported not converged."""
    from vibroimpact.simulation.steady import motion_scale

    problem = ImpactProblem(system, RigidStop(-0.001, 0.5), HarmonicForce(PAPER_AMPLITUDE, 40.0))
    assert np.all(motion_scale(problem) > 0.0)
    # the stop holds the absorber (no impact): the primary mass's transient decays at xi ~ 0.0026, slowly
    result = steady_state(ExactEngine(), problem, "rest", SteadySettings(lyapunov_periods=0, max_periods=3000))
    assert result.converged and result.multiplicity == 1  # exact: a count
    assert result.measures.impacts_per_period == 0.0 and abs(result.measures.x2) < 1e-15  # exact: held, no impact
    # held, the primary mass moves as the linear system with the absorber fixed: X1 = q / (k1 + k2 - m1 w^2 + j w (b1 + b2))
    omega = problem.omega
    held = PAPER_AMPLITUDE / (system.k1 + system.k2 - system.m1 * omega**2 + 1j * omega * (system.b1 + system.b2))
    assert abs(result.measures.x1) == pytest.approx(abs(held), rel=1e-6)
