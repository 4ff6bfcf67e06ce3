"""The largest response along a branch, located exactly (issue 32, item 2): the paper's one-impact branch against the
closed form's maximum found by a bounded search on eqs. 15-18."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.continuation import continue_branch
from vibroimpact.orbits.maps import ImpactMap, closed_form_state
from vibroimpact.orbits.orbit_measures import branch_measures
from vibroimpact.orbits.shooting import shoot
from vibroimpact.orbits.worst_case import branch_maximum

pytestmark = [pytest.mark.slow, pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")]

PROBLEM = ImpactProblem(PAPER_SYSTEM, RigidStop(0.003, 0.2), HarmonicForce(10.0, 25.0))


@pytest.fixture(scope="module")
def traced():
    system = ImpactMap(PROBLEM)
    return system, continue_branch(system, shoot(system, closed_form_state(PROBLEM), system.parameters), "frequency")


def test_the_stable_maximum_is_the_closed_form_maximum(traced) -> None:
    """Stable |X1| peaks inside the first band: 2.7526 mm at 25.1612 Hz, equal to the closed form's maximum (the
    stable root of eq. 16) to 1e-12 relative, its frequency to 1e-5 Hz (a flat maximum: sqrt(eps) of the band)."""
    system, branch = traced
    found = branch_maximum(system, branch)
    closed = minimize_scalar(lambda f: -float(np.abs(solve_impact_orbit(PROBLEM, frequency=np.array([f]), root="+").harmonics())[0, 0]),
                             bounds=(25.0, 25.3), method="bounded", options={"xatol": 1e-12})  # fmt: skip
    assert found.where == "interior"
    assert found.amplitude == pytest.approx(-closed.fun, rel=1e-12)
    assert found.value == pytest.approx(closed.x, abs=1e-5)
    sampled = branch_measures(system, branch).amplitude(0)[branch.stable]
    assert found.amplitude >= sampled.max()


def test_unstable_orbits_count_only_when_asked(traced) -> None:
    """Over every orbit of the branch the maximum is no smaller than over the stable ones, and is one of its points or
    special points (here the unstable root, beyond the stable maximum)."""
    system, branch = traced
    everything, stable = branch_maximum(system, branch, stable_only=False), branch_maximum(system, branch)
    assert everything.amplitude >= stable.amplitude
    assert everything.amplitude >= branch_measures(system, branch).amplitude(0).max() * (1.0 - 1e-12)


def test_the_worst_case_over_the_band_names_its_motion() -> None:
    """The paper's design over 15-45 Hz: the contact-free orbit where it clears the stop and every branch from the
    closed form (the isolated 18.25-18.71 Hz branch, unstable, and the main one, traced once): the worst stable |X1|
    is the one-impact orbit's 2.7526 mm at 25.16 Hz, the closed form's maximum to 1e-12."""
    from vibroimpact.orbits.worst_case import worst_response

    worst = worst_response(PROBLEM, (15.0, 45.0))
    closed = minimize_scalar(lambda f: -float(np.abs(solve_impact_orbit(PROBLEM, frequency=np.array([f]), root="+").harmonics())[0, 0]),
                             bounds=(25.0, 25.3), method="bounded", options={"xatol": 1e-12})  # fmt: skip
    assert worst.amplitude == pytest.approx(-closed.fun, rel=1e-12)
    assert worst.motion.startswith("1 impact per period") and worst.frequency == pytest.approx(25.1612, abs=1e-4)
    assert len(worst.branches) == 2 and sum(top is None for _b, top in worst.branches) == 1
