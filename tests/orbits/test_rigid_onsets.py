"""A rigid stop's contact onsets passed both ways by the default continuation (issue 31, item 2): the paper's system
(Delta = 3 mm, q = 10 N, R = 0.2) from the contact-free orbit at 33 Hz, between its two impacting bands, and from the
impacting orbit at 37 Hz. At each onset the linear orbit touches the stop (q |H12| = Delta), the one-impact orbit born
there has an impulse that grows linearly from 0 (a simple root of eq. 16), and its largest multiplier grows like one
over the impact speed: the branch reaches and leaves the onset on closed-form orbits 1.6e-5 ... 1e-3 from grazing.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.bifurcations import grazing_margin
from vibroimpact.orbits.continuation import continue_branch
from vibroimpact.orbits.maps import ImpactMap, closed_form_state
from vibroimpact.orbits.shooting import shoot

pytestmark = [pytest.mark.slow, pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")]

DELTA, Q = 3e-3, 10.0


def _branch(frequency: float):
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(DELTA, 0.2), HarmonicForce(Q, frequency))
    system = ImpactMap(problem)
    closed = closed_form_state(problem)
    start = closed if np.all(np.isfinite(closed)) else system.linear_orbit(system.parameters)[0]
    return system, continue_branch(system, shoot(system, start, system.parameters), "frequency")


@pytest.fixture(scope="module")
def branches():
    return {f: _branch(f) for f in (33.0, 37.0)}


def _onsets() -> list[float]:
    """Where q |H12(f)| = Delta between 15 and 45 Hz [Hz] (the linear orbit touches the stop)."""
    gap = lambda f: Q * abs(PAPER_SYSTEM.receptances(2.0 * np.pi * f).h12) - DELTA  # noqa: E731
    grid = np.linspace(15.0, 45.0, 3001)
    values = np.array([gap(f) for f in grid])
    return [brentq(gap, grid[k], grid[k + 1], xtol=1e-14, rtol=1e-15) for k in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))]


def test_one_call_from_between_the_bands_traces_both_bands(branches) -> None:
    """From the contact-free orbit at 33 Hz: up through the onset at 33.97 Hz onto the second band, around its fold
    and down its other root to the onset at 37.50 Hz; down through the onset at 26.03 Hz (a nonsmooth fold) onto the
    first band's unstable root, around its fold to the onset at 20.62 Hz; contact-free beyond both ends."""
    _, branch = branches[33.0]
    assert branch.end == "clear, clear"
    kinds = [(point.kind, round(point.value, 6)) for point in branch.special_points]
    assert kinds == [
        ("grazing", 20.617668), ("neimark_sacker", 21.205174), ("fold", 26.702663), ("period_doubling", 26.583637),
        ("grazing", 26.026487), ("grazing", 33.972218), ("neimark_sacker", 39.025572), ("fold", 40.1717),
        ("neimark_sacker", 39.563454), ("neimark_sacker", 37.574128), ("grazing", 37.498585),
    ]  # fmt: skip
    assert set(branch.impacts) == {0, 1}


def test_both_starts_give_the_same_special_points(branches) -> None:
    """The branch from 37 Hz (impacting) and from 33 Hz (contact-free): the same points, to 1e-9 Hz."""
    (_, first), (_, second) = branches[33.0], branches[37.0]
    one = sorted((p.kind, p.value) for p in first.special_points)
    other = sorted((p.kind, p.value) for p in second.special_points)
    assert [k for k, _ in one] == [k for k, _ in other]
    np.testing.assert_allclose([v for _, v in one], [v for _, v in other], rtol=0.0, atol=1e-9)


def test_onsets_are_the_closed_form_tangencies(branches) -> None:
    """Each grazing point is a root of q |H12| = Delta to 1e-12 relative, and says which way the branch goes on."""
    roots = _onsets()
    _, branch = branches[33.0]
    grazing = [point for point in branch.special_points if point.kind == "grazing"]
    assert len(grazing) == 4
    for point in grazing:
        assert min(abs(point.value - root) for root in roots) <= 1e-12 * point.value
        assert point.continues
    notes = {round(point.value, 3): point.note for point in grazing}
    assert "a free flight touches the stop; the branch continues with 1 impact per period" in notes[33.972]
    assert "the branch turns back here: a nonsmooth fold" in notes[26.026]
    assert "a real multiplier through +1" in notes[37.499] and "a real multiplier through +1" in notes[20.618]


def test_the_branch_leaves_an_onset_on_the_closed_form_orbits_born_there(branches) -> None:
    """Past 33.972218 Hz the first impacting orbits are 1.5625e-5, 3.125e-5, ... 1e-3 from grazing and are the closed
    form (eqs. 15-18) to 1e-12 of the state scale; the largest multiplier falls like one over the margin (2 % up to
    1.3e-4, 13 % at 1e-3: the next order)."""
    system, branch = branches[33.0]
    values = branch.values
    index = next(k for k, orbit in enumerate(branch.orbits) if orbit.hybrid.impacts == 1 and abs(values[k] - 33.972218) < 1e-3)
    ladder = branch.orbits[index : index + 7]
    margins = np.array([grazing_margin(orbit.hybrid) for orbit in ladder])
    np.testing.assert_allclose(margins, 1.5625e-5 * 2.0 ** np.arange(7), rtol=0.05)
    for orbit in ladder:
        state, _margin = system.impact_orbit(orbit.parameters)
        np.testing.assert_allclose(orbit.state / system.state_scale, state / system.state_scale, rtol=0.0, atol=1e-12)
    largest = np.array([np.max(np.abs(orbit.multipliers)) for orbit in ladder[:4]])  # up to 1.3e-4 from grazing
    np.testing.assert_allclose(largest * margins[:4], largest[0] * margins[0], rtol=0.02)


def test_the_closed_form_orbit_is_none_where_none_applies() -> None:
    """:meth:`ImpactMap.impact_orbit` is None, not an exception, where the closed form refuses the problem (it raises
    ValueError saying why: a bumper, two stops that are not a symmetric pair), at a parameter vector that is no
    problem (a negative frequency) and over two periods; on the paper's problem it is a state and a distance to
    grazing."""
    paper = ImpactProblem(PAPER_SYSTEM, RigidStop(DELTA, 0.2), HarmonicForce(Q, 25.0))
    bumper = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(DELTA, 400.0, 0.1), HarmonicForce(Q, 25.0))
    unpaired = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(DELTA, 0.2), 1), Stop(RigidStop(2e-3, 0.2), 0, side="lower")), HarmonicForce(Q, 25.0))
    for problem, why in ((bumper, "need rigid stops"), (unpaired, "do not form a symmetric two-sided stop")):
        with pytest.raises(ValueError, match=why):
            solve_impact_orbit(problem)
        system = ImpactMap(problem, stop=0)
        assert system.impact_orbit(system.parameters) is None
    system = ImpactMap(paper)
    negative = system.parameters.copy()
    negative[0] = -25.0
    assert system.impact_orbit(negative) is None
    assert system.with_periods(2).impact_orbit(system.parameters) is None
    state, margin = system.impact_orbit(system.parameters)
    assert state.shape == (4,) and np.all(np.isfinite(state)) and margin > 0.0


def test_the_ladder_is_empty_where_the_impulse_jumps_at_the_onset() -> None:
    """The paper's system with Delta = 2.3596 mm, R = 0.1893 (design_rigid_stop's recommended design): at the onset near
    33.08 Hz the orbit born there grows from grazing (each rung within 5 % of its margin), while at the one near
    20.007 Hz the closed form's orbit on the far side is 0.105 from grazing however close to the root (the impulse
    jumps there): no rung of its ladder is offered (two of them were one orbit, and the continuation's secant between
    them was 0/0)."""
    from vibroimpact.orbits.onsets import LADDER, contact_free_onset, impacting_ladder

    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(0.0023596441695948873, 0.1892973965404693), HarmonicForce(Q, 20.0))
    system = ImpactMap(problem)
    index = system.parameter_names.index("frequency")
    rungs = {}
    for near in (20.0069, 33.0785):
        p = np.array(system.parameters, dtype=float)
        p[index] = near
        root, _ = contact_free_onset(system, p, index, near, 1e-3)
        rungs[near] = impacting_ladder(system, p, index, root)
    assert rungs[20.0069] == []
    margins = np.array([margin for _, _, margin in rungs[33.0785]])
    assert margins.size == len(LADDER) and np.allclose(margins, LADDER, rtol=0.05, atol=0.0)
