"""Steady states by shooting, and the kind of motion where none is periodic (paper's system, Delta = 3 mm, R = 0.2)."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.analysis.stability import Regime
from vibroimpact.engines.registry import make_engine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.simulation.steady import steady_state

SETTINGS = SteadySettings(max_periods=300, irregular_measure_periods=32)


def _problem(frequency: float, restitution: float = 0.2) -> ImpactProblem:
    return ImpactProblem(PAPER_SYSTEM, RigidStop(0.003, restitution), HarmonicForce(10.0, frequency))


@pytest.mark.parametrize("frequency", [22.0, 25.0, 26.0, 40.0])
def test_shooting_finds_a_stable_orbit_in_at_most_five_periods(frequency: float) -> None:
    """From the closed form, Newton on the exact map converges at once; the measured orbit is the closed form's."""
    problem = _problem(frequency)
    result = steady_state(make_engine("exact"), problem, "shooting", SETTINGS)
    marched = steady_state(make_engine("exact"), problem, "pgf", SETTINGS)
    closed = solve_one_impact(PAPER_SYSTEM, omega=np.array([problem.omega]), clearance=0.003, restitution=0.2, amplitude=10.0)
    assert result.converged and result.multiplicity == 1 and result.search_periods <= 5
    assert marched.search_periods >= 20  # marching needs at least one chunk of periods
    np.testing.assert_allclose(abs(result.measures.x1), np.abs(closed.harmonics()[0, 0]), rtol=1e-9)
    np.testing.assert_allclose(abs(result.measures.x1), abs(marched.measures.x1), rtol=1e-7)
    assert result.measures.impacts_per_period == pytest.approx(1.0)


def test_an_integrator_starting_on_the_shot_orbit_confirms_it_in_a_few_periods() -> None:
    problem = _problem(25.0)
    result = steady_state(make_engine("momentary"), problem, "shooting", SETTINGS)
    reference = steady_state(make_engine("exact"), problem, "shooting", SETTINGS)
    assert result.converged and result.search_periods <= 5
    np.testing.assert_allclose(abs(result.measures.x1), abs(reference.measures.x1), rtol=1e-6)


def test_an_unstable_orbit_falls_back_to_marching() -> None:
    """At 37.5 Hz the one-impact orbit exists but is unstable (past the Neimark-Sacker point near 39 Hz ... the
    band's end): shooting finds it, marching from it does not converge, and the motion is classified."""
    result = steady_state(make_engine("exact"), _problem(37.5), "shooting", SETTINGS)
    assert not result.converged and result.motion is not None
    assert result.search_periods > SETTINGS.max_periods


@pytest.mark.parametrize(("frequency", "kind"), [(21.1, "quasi_periodic"), (37.0, "chaotic"), (37.5, "chaotic")])
def test_the_motion_that_does_not_converge_is_classified_alike_by_two_engines(frequency: float, kind: str) -> None:
    """exact (exponent from its Jacobians) and momentary (exponent from a perturbed copy of its own run) agree on
    the kind; their exponents agree within their errors plus 0.02 per period."""
    problem = _problem(frequency)
    exact = steady_state(make_engine("exact"), problem, "pgf", SETTINGS)
    momentary = steady_state(make_engine("momentary"), problem, "pgf", SETTINGS)
    for result in (exact, momentary):
        assert not result.converged and result.motion is not None
        assert result.motion.kind == kind, result.motion.reason
    assert exact.motion.method == "jacobians" and momentary.motion.method == "estimate"
    assert exact.motion.regime == (Regime.QUASI_PERIODIC if kind == "quasi_periodic" else Regime.CHAOTIC)
    gap = abs(exact.motion.lyapunov_exponent - momentary.motion.lyapunov_exponent)
    assert gap <= 3.0 * (exact.motion.lyapunov_error + momentary.motion.lyapunov_error) + 0.02
