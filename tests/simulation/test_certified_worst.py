"""A design's worst case certified by continuation and brute force (issue 32): where the one-impact orbit sets it the
two agree and continuation's exact value stands; where brute force finds a larger stable orbit that no closed form
starts (two impacts a period), its branch is continued from the sweep's state and its maximum located exactly."""

from __future__ import annotations

import pytest

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.simulation.certified_worst import SOURCES, certified_worst, sweep_points_for

pytestmark = [pytest.mark.slow, pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core")]


def paper(clearance: float, restitution: float) -> ImpactProblem:
    return ImpactProblem(PAPER_SYSTEM, RigidStop(clearance, restitution), HarmonicForce(10.0, 25.0))


def test_continuation_stands_where_the_one_impact_orbit_sets_the_worst_case() -> None:
    """Delta = 3 mm, R = 0.2: 2.7526134 mm at 25.1612 Hz by continuation (tests/orbits/test_worst_case.py); brute force
    on 121 frequencies is below it by no more than its grid's bound (0.25 Hz: |X''| h^2 / 8 ~ 1e-3 relative)."""
    found = certified_worst(paper(0.003, 0.2), (15.0, 45.0))
    assert found.source == SOURCES[0]
    assert found.amplitude == pytest.approx(2.7526134e-3, rel=1e-7)
    assert found.attractors.maximum.amplitude == pytest.approx(found.amplitude, rel=2e-3)
    assert found.attractors.maximum.amplitude <= found.amplitude * (1.0 + 1e-9)


def test_a_two_impact_orbit_found_by_brute_force_is_continued_and_located() -> None:
    """Delta = 3 mm, R = 0.8: the one-impact branch peaks at 7.1636 mm, but a stable period-1 orbit with two impacts a
    period reaches 9.4162 mm at 25.7766 Hz (shot from the sweep's state and continued; brute force alone: 9.40 mm on its
    grid). A stepped sweep needs more frequencies for 1e-8 than for 1e-4, by sqrt(1e4) = 100."""
    found = certified_worst(paper(0.003, 0.8), (15.0, 45.0))
    assert found.continuation.amplitude == pytest.approx(7.1636e-3, rel=1e-4)
    assert found.source == SOURCES[2] and "2 impacts" in found.motion
    assert found.amplitude == pytest.approx(9.4162e-3, rel=1e-4) and found.frequency == pytest.approx(25.7766, abs=1e-3)
    assert found.amplitude >= found.attractors.maximum.amplitude
    branch = found.extra[0]
    import numpy as np

    from vibroimpact.orbits.maps import ImpactMap
    from vibroimpact.orbits.orbit_measures import branch_measures

    x = branch_measures(ImpactMap(paper(0.003, 0.8)), branch).amplitude(0)
    stable = np.asarray(branch.stable, dtype=bool)
    coarse, fine = (sweep_points_for(x[stable], np.asarray(branch.values)[stable], a, (15.0, 45.0)) for a in (1e-4, 1e-8))
    assert fine / coarse == pytest.approx(100.0, rel=1e-3)
