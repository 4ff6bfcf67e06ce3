"""Brute-force seeds that settle slowly are classified, not reported as failed: the motion from each is run on and
found to be a torus (whose rotation number the Neimark-Sacker multipliers' angle predicts), chaotic (an exponent
positive beyond its error, as two trajectories measure it too), or a long-period orbit that is shot and continued."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.kinds.bifurcation.branches import OrbitSet, find_branches, problem_at
from vibroimpact.kinds.bifurcation.cases import SweepCase, branch_arrays, seed_branches, sweep_seeds
from vibroimpact.kinds.bifurcation.logs import numbered
from vibroimpact.kinds.bifurcation.seed_report import slow_seed_dataset, slow_seed_text
from vibroimpact.kinds.bifurcation.slow_seeds import SEED_OUTCOMES, SeedOutcome, neimark_sacker_angle, settle_seed
from vibroimpact.model.contact import RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.continuation import ContinuationSettings
from vibroimpact.orbits.lyapunov import lyapunov_two_trajectories
from vibroimpact.orbits.motion import rotation_number
from vibroimpact.simulation.attractors import MAX_PERIOD, repeat_scale
from vibroimpact.simulation.harmonics import resting_state

pytestmark = pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")

#: The paper's system with its stop on x2 (3 mm, R = 0.2), 10 N on x1: its one-impact orbit loses stability at a
#: Neimark-Sacker point near 21.2 Hz, and below it the motion settles onto a torus.
PAPER = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.2), coordinate=1),), HarmonicForce(10.0, 21.0))
#: The same masses with Ormondroyd and Den Hartog's relative stops, |x2 - x1| <= 3 mm (bifurcation_relative_stop).
RELATIVE = ImpactProblem(
    PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.2), coordinate=1, other=0, side="upper"), Stop(RigidStop(3e-3, 0.2), coordinate=1, other=0, side="lower")), HarmonicForce(10.0, 38.0)
)  # fmt: skip


def _from_rest(problem: ImpactProblem, frequency: float, periods: int = 300) -> np.ndarray:
    """The state at a strobe after ``periods`` periods from rest on the stops (a brute-force point's end state)."""
    at = problem_at(problem, frequency)
    return ExactEngine().integrate(at, resting_state(at), 0.0, periods).final_state


def _settle(found: OrbitSet, problem: ImpactProblem, frequency: float, period: int) -> SeedOutcome:
    """What the motion from rest reaches at ``frequency``, as a seed of ``period`` that shooting did not converge from."""
    state = _from_rest(problem, frequency)
    return settle_seed(found, problem_at(problem, frequency), frequency, period, state, "residual 0.1 at the start", lambda motion: (-1, "not continued here"), ExactEngine())


@pytest.fixture(scope="module")
def neimark_sacker() -> tuple[OrbitSet, dict]:
    """The branches of the paper's system over 20.9-21.5 Hz and their one Neimark-Sacker point."""
    found = find_branches(PAPER, 20.9, 21.5)
    points = [p for p in found.specials if p["kind"] == 2]  # SPECIAL_POINT_KINDS: fold, period_doubling, neimark_sacker
    assert len(points) == 1 and points[0]["period"] == 1
    return found, points[0]


def test_a_torus_near_a_neimark_sacker_point_rotates_at_its_multipliers_angle(neimark_sacker) -> None:
    """Below the Neimark-Sacker point the seed's motion is a torus (exponent 0 within its error, not periodic); its
    rotation number tends to the critical multipliers' angle / 2 pi as the frequency nears the point, the deficit
    linear in the distance (the normal form: rho(f) = theta(f_NS) / 2 pi + O(f - f_NS))."""
    found, point = neimark_sacker
    angle = neimark_sacker_angle(point["multipliers"])
    mu = point["multipliers"][np.argmin(np.abs(np.abs(point["multipliers"]) - 1.0))]
    assert abs(abs(mu) - 1.0) < 1e-6 and 0.0 < angle < 0.5
    distances, deficits = [], []
    for f in (21.0, 21.1, point["frequency"] - 0.02):
        outcome = _settle(found, PAPER, f, 19)
        assert outcome.outcome == "quasi_periodic", outcome.text
        assert abs(outcome.lyapunov_exponent) < 3.0 * outcome.lyapunov_error + 2e-3
        assert outcome.rotation_period == 1 and outcome.ns_frequency == pytest.approx(point["frequency"], rel=1e-12)
        assert outcome.ns_angle == pytest.approx(angle, rel=1e-12)
        assert f"rotation number {outcome.rotation_number:.4f}" in outcome.text and f"Neimark-Sacker point at {point['frequency']:.4f} Hz" in outcome.text
        distances.append(point["frequency"] - f)
        deficits.append(angle - outcome.rotation_number)
    assert all(d > 0.0 for d in deficits) and deficits[0] > deficits[1] > deficits[2]  # slower away from the point
    assert deficits[2] < 1e-3
    slopes = np.array(deficits) / np.array(distances)
    assert np.ptp(slopes) < 0.2 * slopes.mean()  # linear in the distance


def test_a_chaotic_seed_has_a_positive_exponent_beyond_its_error() -> None:
    """The relative stops at 33.5 Hz: the motion from rest is chaotic by the exact Jacobians' exponent (> 3 errors),
    and two trajectories 1e-6 apart (an estimate with no Jacobian) separate at the same rate within their errors."""
    found = OrbitSet()
    outcome = _settle(found, RELATIVE, 33.5, 13)
    assert outcome.outcome == "chaotic", outcome.text
    assert outcome.lyapunov_exponent > 0.01 and outcome.lyapunov_exponent > 3.0 * outcome.lyapunov_error
    assert math.isnan(outcome.rotation_number) and outcome.orbit_period == 0 and "chaotic" in outcome.text
    at = problem_at(RELATIVE, 33.5)
    state = _from_rest(RELATIVE, 33.5, 300 + outcome.periods_run)
    other = lyapunov_two_trajectories(ExactEngine(), at, state, 0.0, 2000, renormalise_every=4)
    assert other.exponent > 0.01
    assert abs(other.exponent - outcome.lyapunov_exponent) < 4.0 * math.hypot(other.error, outcome.lyapunov_error)


@pytest.fixture(scope="module")
def long_period() -> tuple[OrbitSet, list]:
    """The relative stops swept up from 37 to 38 Hz (100 periods dropped, 32 kept): at 38 Hz the strobes nearly repeat
    after 8 periods and shooting from there does not converge; the seeds are continued over 37.5-38.5 Hz."""
    sweep = SweepCase(RELATIVE, "up", (37.0, 38.0), 100, 32).run()
    seeds = [s for s in sweep_seeds(np.array([37.0, 38.0]), sweep["period"], sweep["impacts"], sweep["state"]) if s.frequency > 37.5]
    found = OrbitSet()
    seed_branches(found, RELATIVE, 37.5, 38.5, seeds, ContinuationSettings(lower=37.5, upper=38.5, max_step=0.1, stop_at_grazing=True))
    return found, seeds


def test_a_long_period_orbit_is_shot_and_continued_once_run_longer(long_period) -> None:
    """The motion from the seed repeats once run longer, with a least period beyond the sweeps' longest; that orbit
    is shot and continued, and an independent integration over its period returns to its state (and not over one
    period); its strobes turn a whole number of times around their centroid in its period (an orbit locked on a
    torus: rotation number j / p)."""
    found, seeds = long_period
    assert len(seeds) == 1 and found.failures == []
    (outcome,) = found.settled
    assert outcome.outcome == "periodic" and outcome.orbit_period > MAX_PERIOD and outcome.branch == 0, outcome.text
    p = outcome.orbit_period
    assert p % seeds[0].period  # not the sweep's period repeated: a period it could not see
    mapping, branch = found.maps[0]
    assert {point["period"] for point in found.points} == {p}
    orbit = min(branch.orbits, key=lambda o: abs(o.parameter("frequency") - 38.0))
    assert abs(orbit.parameter("frequency") - 38.0) < 0.05 and orbit.stable
    at = mapping.problem_at(orbit.parameters)  # its frequency, and the force phase of the strobe it was shot through
    run = ExactEngine().integrate(at, orbit.state, 0.0, 8 * p)
    scale = repeat_scale(at)
    assert np.max(np.abs(run.strobe_states[p] - orbit.state) / scale) < 1e-8
    assert np.max(np.abs(run.strobe_states[1] - orbit.state) / scale) > 1e-3
    turns = rotation_number(run.strobe_states[: 8 * p + 1]).rotation_number * p
    assert abs(turns - round(turns)) < 1e-6 and round(turns) >= 1
    assert f"period {p}, longer than the {MAX_PERIOD} the sweeps look for" in outcome.text and "continued as branch 0" in outcome.text


def test_the_dataset_and_page_say_what_the_seeds_reached(long_period) -> None:
    """The branch case's arrays carry each slowly settling seed (outcome flag, periods, branch) into the dataset's
    ``slow_seed`` variables, numbered across restitutions; the page says what each reached, and nothing failed."""
    found, _seeds = long_period
    result = numbered(branch_arrays(found, 2), 5)
    assert result["ss_branch"].tolist() == [5] and "continued as branch 5" in str(result["ss_text"][0])
    data = slow_seed_dataset([result], (0.2,))
    outcome = data["slow_seed_outcome"]
    assert outcome.attrs["flag_meanings"].split() == list(SEED_OUTCOMES) and outcome.values.tolist() == [SEED_OUTCOMES.index("periodic")]
    assert data["slow_seed_frequency"].attrs["units"] == "Hz" and data["slow_seed_frequency"].values.tolist() == [38.0]
    assert data["slow_seed_orbit_period"].values[0] == found.settled[0].orbit_period and data["slow_seed_branch"].values.tolist() == [5]
    assert np.isnan(data["slow_seed_rotation_number"].values[0]) and data["slow_seed_periods_run"].values[0] >= 2000
    text = slow_seed_text(data)
    assert "R = 0.2: 1 (1 periodic)" in text and "a periodic orbit of period" in text and "failed" not in text
    assert found.notes[-1].endswith("1 settling slowly (1 periodic), 0 failed")


class _Stuck:
    """An engine that makes no progress (endless chattering)."""

    def integrate(self, *args: object, **kwargs: object) -> None:
        raise RuntimeError("no progress at t = 0.5 s: 70 events")


def test_an_engine_that_fails_running_a_seed_on_is_a_failure() -> None:
    """An engine error is said as a failure, with its message; nothing else is."""
    outcome = settle_seed(OrbitSet(), problem_at(PAPER, 21.0), 21.0, 13, np.array([1e-3, 2e-3, 0.0, 0.0]), "residual 0.1 at the start", lambda motion: (-1, ""), _Stuck())
    assert outcome.outcome == "failed" and "running it on failed: RuntimeError: no progress" in outcome.text and outcome.periods_run == 0
    with pytest.raises(ValueError, match="orbit_period"):
        SeedOutcome(21.0, 13, "quasi_periodic", orbit_period=5)
    with pytest.raises(ValueError, match="outcome"):
        SeedOutcome(21.0, 13, "settled")
