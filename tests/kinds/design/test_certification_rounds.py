"""The certification's rounds (issue 32): candidates are certified one at a time, best screened first, skipping one
next to a candidate already certified, until no later candidate can beat the best certified one (certification only
raises a worst case) or ``certify.candidates`` are spent; the recommendation is the best certified candidate.

The runner here answers each certification from a table: what is tested is which candidates are certified, in what
batches, and what is recommended."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml

from vibroimpact.kinds.design.search import Evaluations
from vibroimpact.kinds.design.study import DISTINCT, Outcome, _certify, design_space
from vibroimpact.scene.reader import parse_scene

SCENE = {
    "name": "rounds",
    "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0},
    "stop": {"clearance": 0.003, "restitution": 0.2},
    "design": {"variables": {"clearance": [0.001, 0.005], "restitution": [0.0, 0.8]}, "band": {"start": 15.0, "stop": 45.0},
               "certify": {"candidates": 3}},
}  # fmt: skip


class TableRunner:
    """Answers a certification of (clearance, sample) from ``certified`` [m]; keeps each batch's cases."""

    def __init__(self, certified: dict[float, float]) -> None:
        self.certified = certified
        self.batches: list[list[tuple[float, int]]] = []

    def map(self, cases):
        self.batches.append([(case.design[0], case.sample) for case in cases])
        return [{"worst": self.certified[case.design[0]]} for case in cases]


def _outcome(screened: dict[float, float], certified: dict[float, float], candidates: int = 3) -> tuple[Outcome, TableRunner]:
    document = copy.deepcopy(SCENE)
    document["design"]["certify"]["candidates"] = candidates
    scene = parse_scene(document, text=yaml.safe_dump(document))
    space = design_space(scene)
    runner = TableRunner(certified)
    evaluations = Evaluations(space, np.array([[0.001, 0.005], [0.0, 0.8]]), runner)  # type: ignore[arg-type]
    for k, (clearance, value) in enumerate(screened.items()):
        evaluations.designs.append(np.array([clearance, 0.2]))
        evaluations.stages.append(3 if k == 0 else 0)  # the first is the scene's own design
        evaluations.results.append({"worst": np.full(space.samples, value), "uncovered": np.zeros(space.samples), "estimate": np.zeros(space.samples), "operating": np.full(space.samples, np.nan)})
        evaluations.scores.append(value)
    return Outcome(scene.settings, space, evaluations), runner


def test_a_candidate_the_certification_raises_gives_way_to_the_next_distinct_one() -> None:
    # the scene's design (3 mm) screens worst; the best (2 mm) is certified far higher; its neighbour (2.1 mm, within
    # DISTINCT of the range) is skipped; 4 mm holds its screen, and 4.5 mm, screened higher, cannot beat it
    assert 0.1e-3 <= DISTINCT * 4e-3
    screened = {3e-3: 3.0, 2e-3: 1.0, 2.1e-3: 1.01, 4e-3: 1.5, 4.5e-3: 1.6}
    certified = {3e-3: 3.0, 2e-3: 2.0, 2.1e-3: 2.0, 4e-3: 1.5, 4.5e-3: 1.6}
    outcome, runner = _outcome(screened, certified)
    _certify(outcome, runner, lambda message: None)  # type: ignore[arg-type]
    assert runner.batches == [[(2e-3, 0), (3e-3, 0)], [(4e-3, 0)]]  # exact: the designs passed on; the scene's design with the first, nominal only
    assert outcome.recommended == 3
    assert outcome.corrected[1] == pytest.approx(2.0, rel=1e-12) and outcome.corrected[3] == pytest.approx(1.5, rel=1e-12)


def test_a_candidate_that_holds_its_screen_ends_the_rounds() -> None:
    screened = {3e-3: 3.0, 2e-3: 1.0, 4e-3: 1.5}
    outcome, runner = _outcome(screened, {3e-3: 3.0, 2e-3: 1.0, 4e-3: 1.5})
    _certify(outcome, runner, lambda message: None)  # type: ignore[arg-type]
    assert len(runner.batches) == 1 and outcome.recommended == 1


def test_the_rounds_stop_at_the_budget_and_recommend_the_best_certified() -> None:
    screened = {3e-3: 3.0, 2e-3: 1.0, 4e-3: 1.2, 1.2e-3: 1.3}
    certified = {3e-3: 3.0, 2e-3: 2.0, 4e-3: 2.5, 1.2e-3: 1.4}
    outcome, runner = _outcome(screened, certified, candidates=2)
    _certify(outcome, runner, lambda message: None)  # type: ignore[arg-type]
    assert [batch[0][0] for batch in runner.batches] == [2e-3, 4e-3]  # exact: the designs passed on; 1.2 mm, which would win, is past the budget
    assert outcome.recommended == 1 and math.isclose(outcome.corrected[1], 2.0)
    outcome, runner = _outcome(screened, certified, candidates=0)
    _certify(outcome, runner, lambda message: None)  # type: ignore[arg-type]
    assert runner.batches == [] and outcome.recommended == 1  # none certified: the best screened


def test_the_scene_s_design_is_not_certified_twice() -> None:
    """The scene's design (3 mm), certified at its nominal sample with the first candidate, comes up again in the
    screen's order: only what is left of it is certified (every sample equal here: nothing), no duplicate row."""
    screened = {3e-3: 1.2, 2e-3: 1.0}
    outcome, runner = _outcome(screened, {3e-3: 1.2, 2e-3: 2.0})
    _certify(outcome, runner, lambda message: None)  # type: ignore[arg-type]
    assert runner.batches == [[(2e-3, 0), (3e-3, 0)]]  # exact: the designs passed on
    pairs = [(c["evaluation"], c["sample"]) for c in outcome.certified]
    assert len(pairs) == len(set(pairs)) and outcome.recommended == 0


def test_with_a_quantile_a_certificate_raises_its_sample_not_the_whole_objective() -> None:
    """quantile 0.5 over the nominal and 4 random samples (1.0 ... 1.4 mm screened, the median 1.2 mm at sample 4;
    samples 1 and 2 are the box's corners, 1.6 and 1.7 mm, outside a quantile's statistics): the certified samples
    are the nominal and the one that sets the median (not the worst, whose certificate could not move a median);
    certified 1.35 mm, both rise to 1.35 and the median is 1.35 mm. Had the certificate been 1.25 mm, the median would
    be 1.25: scaling the objective by the largest certificate over it gave the same here, but not in general (a
    certificate of the worst sample alone would move the median not at all)."""
    document = copy.deepcopy(SCENE)
    document["design"]["robust"] = {"clearance": 0.0002, "samples": 4, "quantile": 0.5, "seed": 1}
    document["design"]["certify"]["candidates"] = 1
    scene = parse_scene(document, text=yaml.safe_dump(document))
    space = design_space(scene)
    runner = TableRunner({2e-3: 1.35, 3e-3: 1.5})
    evaluations = Evaluations(space, np.array([[0.001, 0.005], [0.0, 0.8]]), runner, quantile=0.5)  # type: ignore[arg-type]
    assert space.samples == 7 and evaluations.corners == 0  # the corners are samples; Evaluations is told below
    evaluations.corners = 2
    for k, (clearance, values) in enumerate({3e-3: [1.5] * 7, 2e-3: [1.0, 1.6, 1.7, 1.1, 1.2, 1.3, 1.4]}.items()):
        evaluations.designs.append(np.array([clearance, 0.2]))
        evaluations.stages.append(3 if k == 0 else 0)
        result = {"worst": np.array(values), "uncovered": np.zeros(7), "estimate": np.zeros(7), "operating": np.full(7, np.nan)}
        evaluations.results.append(result)
        evaluations.scores.append(evaluations.score(result))
    assert evaluations.scores[1] == pytest.approx(1.2, rel=1e-12)
    outcome = Outcome(scene.settings, space, evaluations)
    _certify(outcome, runner, lambda message: None)  # type: ignore[arg-type]
    assert runner.batches[0][:2] == [(2e-3, 0), (2e-3, 4)]  # exact: the designs and samples passed on
    assert outcome.corrected[1] == pytest.approx(1.35, rel=1e-12) and outcome.recommended == 1
    runner.certified[2e-3] = 1.25  # a smaller certificate: the nominal's 1.0 -> 1.25, the median's 1.2 -> 1.25
    outcome = Outcome(scene.settings, space, evaluations)
    _certify(outcome, runner, lambda message: None)  # type: ignore[arg-type]
    assert outcome.corrected[1] == pytest.approx(1.25, rel=1e-12)
