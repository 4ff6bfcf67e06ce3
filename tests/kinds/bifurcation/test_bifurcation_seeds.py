"""Branches seeded from the brute force: an attractor no branch from the closed form reaches is found and continued."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.continuation import ContinuationSettings
from vibroimpact.kinds.bifurcation.branches import find_branches
from vibroimpact.kinds.bifurcation.cases import SweepCase
from vibroimpact.kinds.bifurcation.cases import seed_branches, sweep_seeds

pytestmark = pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")

Q, DELTA, R, LOW, HIGH = 10.0, 3e-3, 0.8, 20.4, 22.0
#: The sweep jumps from the linear motion at 20.5 Hz straight to 22 Hz: through the chaotic band between (20.6-21.5 Hz)
#: the end state, and so the attractor reached at 22 Hz, depends on round-off (the engine's paper and general flows
#: reach different ones).
FREQUENCIES = (20.4, 20.5, 22.0)
#: The paper's layout as the general problem the study runs: its matrices, one upper stop on x2, the force on x1.
PROBLEM = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(DELTA, R), coordinate=1),), HarmonicForce(Q, LOW))


@pytest.fixture(scope="module")
def seeded():
    """R = 0.8, sweeping up from the linear motion at 20.4 and 20.5 Hz to 22 Hz: there the sweep settles on an orbit of period 6
    with 6 impacts."""
    sweep = SweepCase(PROBLEM, "up", FREQUENCIES, 300, 64).run()
    seeds = sweep_seeds(np.array(FREQUENCIES), sweep["period"], sweep["impacts"], sweep["state"])
    found = find_branches(PROBLEM, LOW, HIGH)
    before = found.count
    settings = ContinuationSettings(lower=LOW, upper=HIGH, max_step=0.1, stop_at_grazing=True)
    added = seed_branches(found, PROBLEM, LOW, HIGH, seeds, settings)
    again = seed_branches(found, PROBLEM, LOW, HIGH, seeds, settings)
    return sweep, seeds, found, before, added, again


def test_the_sweeps_period_six_attractor_is_continued(seeded) -> None:
    sweep, seeds, found, before, added, again = seeded
    assert [(s.frequency, s.period) for s in seeds] == [(22.0, 6)]
    assert added == 1 and again == 0  # the second time, the seed lies on the branch found the first time
    points = [p for p in found.points if p["branch"] >= before]
    assert {p["origin"] for p in points} == {4} and {(p["period"], p["impacts"]) for p in points} == {(6, 6)}
    f = np.array([p["frequency"] for p in points])
    assert f.min() < 21.7 and f.max() > 21.99  # continued both ways from the seed
    # the same orbit as the brute force's: the impulse per period from its last six impacts (m2 (1 + R) v each)
    k = int(np.flatnonzero(np.isclose(FREQUENCIES, 22.0))[0])
    velocities = sweep["velocity"][k][np.isfinite(sweep["velocity"][k])][-6:]
    impulse = PAPER_SYSTEM.m2 * (1.0 + R) * velocities.sum() / 6.0
    assert found.known(22.0, 6, 6, impulse)
    near = [p for p in points if abs(p["frequency"] - 22.0) < 0.03]
    match = min(near, key=lambda p: abs(p["impulse"] - impulse))
    assert abs(match["impulse"] - impulse) < 0.01 * impulse
    assert match["stable"] == 1 and np.max(np.abs(match["multipliers"])) < 1.0  # stable where the brute force found it


def test_no_closed_form_branch_reaches_it(seeded) -> None:
    _sweep, _seeds, found, before, _added, _again = seeded
    classes = {(p["period"], p["impacts"]) for p in found.points if p["branch"] < before}
    assert (6, 6) not in classes
