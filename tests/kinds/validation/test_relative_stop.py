"""The relative stop (a stop between two bodies) against Newton's impact law, impact by impact
(studies/validation/relative_stop.yaml)."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.kinds.validation.scene import relative_stop_problem
from vibroimpact.kinds.validation.settings import RelativeStopCase
from vibroimpact.kinds.validation.study import free_flight, run_relative_stop


def test_free_flight_is_the_linear_flow() -> None:
    """The independent propagation (matrix exponential of the forced flow) against the steady state of the linear
    structure: a linear steady state returns to itself after a period, to 1e-12 of its size."""
    case = RelativeStopCase()
    problem = relative_stop_problem(case)
    harmonic, _ = problem.load()
    x = problem.structure.receptance_matrix(problem.omega) @ harmonic
    shifted = np.concatenate([(x * np.exp(1j * problem.omega * 0.3)).real, (1j * problem.omega * x * np.exp(1j * problem.omega * 0.3)).real])
    assert free_flight(problem, shifted, 0.3, 0.3 + problem.period) == pytest.approx(shifted, abs=1e-12 * np.max(np.abs(shifted)))


def test_every_impact_keeps_momentum_and_restitutes_the_relative_velocity() -> None:
    """Newton's law on a stop between two bodies (Ormondroyd & Den Hartog's layout): the impulse acts on both with
    opposite signs, so m1 x1' + m2 x2' is kept, and n.x'(t+) = -R n.x'(t-). Over 2000 periods (about 4000 impacts)
    every impact of the exact engine agrees to 1e-8 with the state propagated independently to it."""
    case = RelativeStopCase()
    outcome = run_relative_stop(case)
    count = outcome.data.sizes["impact"]
    assert count > 3000
    failed = [c for c in outcome.checks if not c.informative and not c.passed]
    assert not failed, failed
    assert float(np.nanmax(outcome.data["momentum_error"].values)) < 1e-8
    assert float(np.nanmax(outcome.data["restitution_error"].values)) < 1e-8
