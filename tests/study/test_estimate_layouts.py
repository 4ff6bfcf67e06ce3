"""``--estimate`` for general scenes: the cost per period scaled by (N/2)^2 K, integration predicted from the general
closed form where one applies (and checked against what a run does), a stated guess where none does."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

from vibroimpact.scene import parse_scene
from vibroimpact.kinds.stepped.cases import SimulationCase, run_case
from vibroimpact.runs.estimate import estimate_scene
from vibroimpact.grids.estimate import closed_form_scale
from vibroimpact.kinds.stepped.study import UNKNOWN_WANDERING
from vibroimpact.runs.estimate import engine_scale
from vibroimpact.kinds.stepped.study import SETTLING_PERIODS, expected_periods

SCENE: dict[str, Any] = {
    "name": "relative_estimate",
    "system": {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]]},
    "excitation": {"amplitude": 10.0, "on": "x1"},
    "stops": [
        {"between": ["x2", "x1"], "side": "upper", "clearance": 0.003, "restitution": 0.2},
        {"between": ["x2", "x1"], "side": "lower", "clearance": 0.003, "restitution": 0.2},
    ],
    "sweep": {"frequency": {"start": 20.0, "stop": 26.0, "step": 1.0}},
    "solutions": ["linear", "pgf", "momentary"],
    "simulation": {"start": "pgf", "max_periods": 100, "lyapunov_periods": 0, "irregular_measure_periods": 16},
    "report": False,
}


def test_scales_of_the_cost() -> None:
    """Two stops on two coordinates cost twice the paper's layout per period; a 3-dof chain with one stop 2.25x."""
    scene = parse_scene(copy.deepcopy(SCENE))
    assert engine_scale(scene.layout) == 2.0  # exact: (2/2)^2 x 2
    three = copy.deepcopy(SCENE)
    three.update(system={"mass": [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 0.1]], "stiffness": [[2e4, -1e4, 0], [-1e4, 1.5e4, -5e3], [0, -5e3, 5e3]]}, stops=[SCENE["stops"][0]], solutions=["linear", "momentary"])
    three_scene = parse_scene(three)
    assert engine_scale(three_scene.layout) == 2.25  # exact: (3/2)^2 x 1
    assert closed_form_scale(three_scene, "linear") == closed_form_scale(three_scene, "pgf")


def test_predicted_integration_matches_what_the_run_does() -> None:
    """With the two-sided closed form: points predicted to need no integration are those the run answers at once."""
    scene = parse_scene(copy.deepcopy(SCENE))
    assert scene.settings.simulation is not None
    periods, scale = expected_periods(scene)
    assert scale == 1.0  # exact: no subsampling
    problem = scene.layout.problem(scene.amplitude, 20.0, 0.2, 0.003)
    case = SimulationCase("momentary", scene.layout.structure, scene.amplitude, problem.contact, tuple(scene.settings.simulation.frequency), "pgf", scene.settings.simulation.engine, scene.settings.simulation.steady, load=scene.layout.load)
    used = run_case(case)["periods_used"]
    np.testing.assert_array_equal(periods[0, 0] == 0, used == 0)
    assert np.any(used > 0) and np.any(used == 0)


def test_without_a_closed_form_a_stated_share_is_assumed_to_wander() -> None:
    """Unequal sides have no closed form: an impacting point costs the transient plus a quarter of the full search."""
    document = copy.deepcopy(SCENE)
    document["stops"][1]["clearance"] = 0.002
    document["solutions"] = ["linear", "momentary"]
    scene = parse_scene(document)
    assert scene.settings.simulation is not None
    periods, _ = expected_periods(scene)
    steady = scene.settings.simulation.steady
    settle = SETTLING_PERIODS + steady.measure_periods
    wander = steady.max_periods + steady.lyapunov_periods + steady.irregular_measure_periods
    values = set(np.unique(periods).tolist())
    assert values <= {0.0, settle + UNKNOWN_WANDERING * (wander - settle)} and len(values) == 2
    assert "momentary" in estimate_scene(scene, jobs=1).parts
