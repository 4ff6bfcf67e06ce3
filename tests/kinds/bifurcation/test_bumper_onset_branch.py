"""A bumper's contact branch is found from the contact-free orbit's onset, with no rigid stop involved (issue 52):
NLvib's two-mass chain with a unilateral spring (Krack & Gross, *Harmonic Balance for Nonlinear Vibration Problems*,
2019, example 03: masses 1, springs 0-1-1, dampers 0.03 times the springs, 0.1 on the second mass, a spring of 100
on the first beyond a gap of 1), at stiffness ratios 3 to 1000. Its orbits are held to an independent shooting of
the same model in this file: scipy's DOP853 with the contact as an event, and Newton with finite differences."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vibroimpact import HarmonicForce, ImpactProblem, KelvinVoigtBumper, LinearStructure, Stop
from vibroimpact.kinds.bifurcation.branches import find_branches
from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS

MASS = np.eye(2)
STIFFNESS = np.array([[1.0, -1.0], [-1.0, 2.0]])
DAMPING = 0.03 * STIFFNESS
FORCE, GAP = 0.1, 1.0
LOW, HIGH = 0.5 / (2.0 * math.pi), 0.8 / (2.0 * math.pi)  # NLvib's 0.5-0.8 rad/s, in Hz


def chain(ratio: float) -> ImpactProblem:
    """The chain with a lossless bumper of stiffness ``ratio`` (the chain's springs are 1) on x1 beyond GAP."""
    structure = LinearStructure(mass=tuple(map(tuple, MASS)), stiffness=tuple(map(tuple, STIFFNESS)), damping=tuple(map(tuple, DAMPING)), coordinates=("x1", "x2"))
    bumper = KelvinVoigtBumper(GAP, math.sqrt(ratio) / (2.0 * math.pi), 0.0)  # m_eff = 1: Omega_b^2 = K_b
    return ImpactProblem(structure, (Stop(bumper, "x1"),), HarmonicForce(FORCE, LOW, weights=(0.0, 1.0)))


def period_map(y: np.ndarray, frequency: float, ratio: float) -> np.ndarray:
    """The state one period after ``y`` at t = 0, by DOP853 (rtol 1e-12) restarted at every contact event."""
    omega = 2.0 * math.pi * frequency

    def rhs(t: float, z: np.ndarray) -> np.ndarray:
        x, v = z[:2], z[2:]
        force = np.array([0.0, FORCE * math.cos(omega * t)])
        force[0] -= ratio * max(x[0] - GAP, 0.0)
        return np.concatenate([v, np.linalg.solve(MASS, force - STIFFNESS @ x - DAMPING @ v)])

    def contact(t: float, z: np.ndarray) -> float:
        return z[0] - GAP

    t, z, end = 0.0, np.array(y, dtype=float), 1.0 / frequency
    while t < end:
        run = solve_ivp(rhs, (t, end), z, method="DOP853", rtol=1e-12, atol=1e-13, events=contact)
        t, z = float(run.t[-1]), run.y[:, -1]
        if run.status == 1:  # past the event: the next piece starts just after it
            t, z = float(run.t_events[0][0]), run.y_events[0][0]
            step = solve_ivp(rhs, (t, min(t + 1e-9, end)), z, method="DOP853", rtol=1e-12, atol=1e-13)
            t, z = float(step.t[-1]), step.y[:, -1]
    return z


def newton(y: np.ndarray, frequency: float, ratio: float) -> np.ndarray:
    """The fixed point of :func:`period_map` near ``y``: Newton with a central-difference Jacobian."""
    for _ in range(8):
        residual = period_map(y, frequency, ratio) - y
        jacobian = np.empty((4, 4))
        for k in range(4):
            h = 1e-6 * max(1.0, abs(y[k]))
            e = np.zeros(4)
            e[k] = h
            jacobian[:, k] = (period_map(y + e, frequency, ratio) - period_map(y - e, frequency, ratio)) / (2.0 * h) - e / h
        step = np.linalg.solve(jacobian, -residual)
        y = y + step
        if np.max(np.abs(step)) <= 1e-11:
            break
    return y


def onsets() -> tuple[float, float]:
    """The frequencies [Hz] where the contact-free orbit's x1 reaches GAP, by bisection on the receptance here."""

    def reach(f: float) -> float:
        w = 2.0 * math.pi * f
        return abs(np.linalg.solve(STIFFNESS - w * w * MASS + 1j * w * DAMPING, [0.0, FORCE])[0]) - GAP

    grid = np.linspace(LOW, HIGH, 2001)
    signs = np.sign([reach(f) for f in grid])
    found = []
    for k in np.flatnonzero(np.diff(signs)):
        a, b = grid[k], grid[k + 1]
        for _ in range(80):
            middle = 0.5 * (a + b)
            a, b = (middle, b) if np.sign(reach(middle)) == signs[k] else (a, middle)
        found.append(0.5 * (a + b))
    return tuple(found)  # type: ignore[return-value]


@pytest.mark.parametrize("ratio", [3.0, 10.0, 100.0, 1000.0])
def test_the_contact_branch_its_folds_and_both_onsets_are_found_by_default(ratio: float) -> None:
    """By default (find_branches as the bifurcation kind calls it, the rigid twin's start off): one contact branch
    joins both onsets of the contact-free orbit (each a grazing point within 1e-9 of the receptance's root here), it
    turns back at a fold above both (the hardening spring bends it right), and its orbits at a quarter, a half and
    three quarters of the way along are periodic orbits of the independent shooting to 1e-6 of the gap (Newton from
    the branch's state moves it by no more); its fold's orbit is one too, with an independent multiplier at +1 to
    1e-4."""
    found = find_branches(chain(ratio), LOW, HIGH, one_impact=False, period_doubling=False)
    assert not found.failures
    grazing = [p["frequency"] for p in found.specials if p["kind"] == SPECIAL_POINT_KINDS.index("grazing")]
    folds = [p["frequency"] for p in found.specials if p["kind"] == SPECIAL_POINT_KINDS.index("fold")]
    expected = onsets()
    assert len(expected) == 2
    for onset in expected:
        assert min(abs(g - onset) for g in grazing) <= 1e-9 * onset
    def ends_at_both(branch) -> bool:
        ends = [point.value for point in branch.special("grazing")]
        return all(any(abs(g - onset) <= 1e-9 * onset for g in ends) for onset in expected)

    joined = [branch for _, branch in found.maps if ends_at_both(branch)]
    assert joined, "no contact branch joins the two onsets"
    branch = joined[0]
    fold = max(branch.special("fold"), key=lambda point: point.value)
    assert fold.value > expected[1] and fold.value == pytest.approx(max(folds), rel=1e-12)
    assert fold.value >= branch.values.max()  # located beyond the last step that turned back
    for k in [len(branch.orbits) * k // 4 for k in (1, 2, 3)]:
        orbit = branch.orbits[k]
        frequency = orbit.parameter("frequency")
        assert orbit.impacts > 0
        assert np.max(np.abs(period_map(orbit.state, frequency, ratio) - orbit.state)) <= 1e-6 * GAP
        assert np.max(np.abs(newton(orbit.state, frequency, ratio) - orbit.state)) <= 1e-6 * GAP
    # the fold: a periodic orbit of the independent map whose finite-difference monodromy has a multiplier at +1
    y = fold.orbit.state
    assert np.max(np.abs(period_map(y, fold.value, ratio) - y)) <= 1e-6 * GAP
    monodromy = np.empty((4, 4))
    for k in range(4):
        e = np.zeros(4)
        e[k] = 1e-6
        monodromy[:, k] = (period_map(y + e, fold.value, ratio) - period_map(y - e, fold.value, ratio)) / 2e-6
    assert np.min(np.abs(np.linalg.eigvals(monodromy) - 1.0)) <= 1e-4


def test_the_rigid_stops_orbit_softened_in_log_steps_reaches_the_bumper() -> None:
    """The other start: the rigid twin's closed-form orbit at 0.11 Hz (both roots), shot on a bumper 64 times
    stiffer and softened to the chain's (100: Omega_b / 2 pi = 1.59 Hz) in stages of log T_b. With one scale for all of
    T_b it stalled at 10.1 Hz ('it ended: max_steps'); now it arrives, on an orbit of the independent shooting."""
    from vibroimpact.analysis.impact_orbit import solve_impact_orbit
    from vibroimpact.kinds.bifurcation.branches import map_bounds, problem_at, rigid_twin
    from vibroimpact.kinds.bifurcation.bumper_start import bumper_start
    from vibroimpact.orbits.maps import ImpactMap, closed_form_state
    from vibroimpact.orbits.shooting import shoot

    problem, f0 = chain(100.0), 0.11
    reached = []
    for root in ("+", "-"):
        twin = ImpactMap(problem_at(rigid_twin(problem), f0), bounds=map_bounds(LOW, HIGH))
        rigid = shoot(twin, closed_form_state(twin.problem, solve_impact_orbit(twin.problem, root=root)), twin.parameters)
        begun = bumper_start(ImpactMap(problem_at(problem, f0), bounds=map_bounds(LOW, HIGH)), rigid)
        assert begun.orbit is not None, begun.why
        assert begun.softest == pytest.approx(math.sqrt(100.0) / (2.0 * math.pi), rel=1e-12)
        assert np.max(np.abs(period_map(begun.orbit.state, f0, 100.0) - begun.orbit.state)) <= 1e-6 * GAP
        reached.append(begun.orbit.state)
    assert np.max(np.abs(reached[0] - reached[1])) > 1e-3  # two orbits, not one found twice


def test_a_bumpers_brute_force_orbits_are_continued(tmp_path) -> None:
    """``continuation: {brute_force: true}`` continues the bumper's own brute-force attractors (before: only a rigid
    stop's were seeded; a bumper diagram dropped them): between the chain's Neimark-Sacker points the sweeps lock onto
    orbits of several periods that no branch from an onset or the closed form reaches, each continued on the
    bumper's map with its contacts, none failing."""
    from vibroimpact.runs.run import run_study
    from vibroimpact.scene.reader import parse_scene

    scene = parse_scene({
        "name": "chain_seeds", "description": "NLvib's chain, a bumper's seeds",
        "system": {"mass": MASS.tolist(), "stiffness": STIFFNESS.tolist(), "damping": DAMPING.tolist(), "coordinates": ["x1", "x2"]},
        "excitation": {"amplitude": FORCE, "on": "x2"},
        "stops": [{"coordinate": "x1", "side": "upper", "clearance": GAP}],
        "bifurcation": {"frequency": {"start": 0.093, "stop": 0.0955}, "restitution": [1.0], "bumper": {"stiffness": [100.0]},
                        "brute_force": {"step": 0.0005, "transient_periods": 200, "strobes": 64, "directions": ["up", "down"]},
                        "continuation": {"brute_force": True, "one_impact": False, "period_doubling": False}},
    })  # fmt: skip
    data = run_study(scene, progress=None)
    seeded = data["branch_origin"].values == list(data["branch_origin"].attrs["flag_meanings"].split()).index("brute_force")
    assert seeded.any() and np.all(data["impacts_per_period"].values[seeded] > 0)
    assert np.any(data["period_multiplicity"].values[seeded] > 1)
    import re

    tally = re.search(r"brute-force seeds: (\d+), (\d+) new branches, .*, (\d+) failed", str(data.attrs["continuation_notes"]))
    assert tally is not None and int(tally.group(2)) > 0 and tally.group(3) == "0"


@pytest.mark.parametrize("bumper", [100.0, 4000.0])
def test_a_soft_or_stiff_bumper_on_the_paper_layout_answers_every_start(bumper: float) -> None:
    """The paper's layout with a 100 Hz bumper (R = 0.2): the rigid branch over 18.25-18.71 Hz has no counterpart for
    bumpers softer than its fold in T_b; its starts at 18.27 and 18.70 Hz did not converge on a 6.4 kHz bumper ('no
    convergence in 40 Newton iterations', 'the line search failed'). Shot on a stiffer one, each is an answer: a fold
    in T_b (over 18-19 Hz: at 4.72 kHz, 15.1 kHz and 937 Hz), none a failure. A 4 kHz bumper (the shipped study's
    stiffest) reaches its orbits from a 256 kHz one; there the stages in log T_b stalled next to the rigid limit
    ('reached only 1.988e+05 Hz of 4000 Hz (it ended: step_too_small)'), and one 1 ms unit takes it on."""
    from vibroimpact import PAPER_SYSTEM
    from vibroimpact.model.collision import loss_factor_from_restitution

    problem = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(0.003, bumper, loss_factor_from_restitution(0.2)), HarmonicForce(10.0, 25.0))
    found = find_branches(problem, 18.0, 19.0, period_doubling=False, grazing=False)
    assert found.failures == [] and found.attempts.get("closed_form", 0) >= 2
    turns = [float(line.split("turns back at Omega_b / 2 pi = ")[1].split(" Hz")[0]) for line in found.absent if "turns back" in line]
    assert all(t > bumper for t in turns) and any(t == pytest.approx(1.508e4, rel=1e-3) for t in turns)  # 18.70 Hz: 15.1 kHz
    assert len(found.absent) + len(found.maps) >= found.attempts["closed_form"]  # every start an orbit or an answer


def test_a_branch_goes_on_where_a_free_flight_of_a_seeded_orbit_touches_the_stop() -> None:
    """Issue 52: a rigid stop's branch through an onset to another contact count. On the golden diagram (the paper's
    layout, R = 0.2) the branch seeded from the brute force at 38.5 Hz (period 10) meets a grazing point at 38.488 Hz
    where a free flight touches the stop and an orbit with 6 impacts continues; before, the grazing points of
    seeded branches were never visited and that branch ended there. Now a branch born there (origin 'grazing') passes
    through the same grazing point, on the other side of it."""
    import xarray as xr

    from tests.golden.golden import DATA

    with xr.open_dataset(DATA / "bifurcation.nc") as data:
        d = data.load()
    kinds = d["special_point_kind"].values
    notes = [str(n) for n in d["special_point_note"].values]
    flights = [k for k in np.flatnonzero(kinds == SPECIAL_POINT_KINDS.index("grazing")) if notes[k].startswith("a free flight touches the stop; the branch continues with")]
    assert flights
    grazing_origin = d["branch_origin"].attrs["flag_meanings"].split().index("grazing")
    born = set(np.unique(d["branch"].values[d["branch_origin"].values == grazing_origin]).tolist())
    continued = [k for k in flights if born & {int(b) for b in str(d["special_point_branches"].values[k]).split()}]
    assert continued, "no branch born at a free flight's grazing point"
    k = continued[0]
    on = {int(b) for b in str(d["special_point_branches"].values[k]).split()}
    counts = {float(d["impacts_per_period"].values[np.flatnonzero(d["branch"].values == b)].max()) for b in on}
    assert len(on) >= 2 and len(counts) >= 2  # the same point on two branches with different contact counts
