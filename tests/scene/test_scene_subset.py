"""``simulation.subset``: a time-domain solution on part of the simulation grid; what is accepted, what each mistake
reports, and that a stepped study computes that solution there only."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from vibroimpact.analysis.stability import Regime
from vibroimpact.kinds.stepped.cases import general_simulated_values
from vibroimpact.grids.grid import StudyGrid
from vibroimpact.runs.runner import Runner
from vibroimpact.scene import parse_scene

from tests.scene.test_scene import problems_of, scene_with


def subset_scene(subset: Any, **simulation: Any) -> dict[str, Any]:
    """Two R, 20-26 Hz; both bumper engines, ``compliant`` (IDA) on ``subset``."""
    document = scene_with()
    document["stop"] = {"clearance": 0.003}
    document["sweep"]["restitution"] = [0.2, 0.6]
    document["bumper"] = {"frequency": 250.0}
    document["solutions"] = ["pgf", "compliant_exact", "compliant"]
    document["simulation"] = {"frequency": [22.0, 24.0, 26.0], "subset": subset, **simulation}
    return document


def test_subset_keeps_the_named_values_snapped_onto_their_grids() -> None:
    scene = parse_scene(subset_scene({"compliant": {"frequency": [24.0000000000001], "restitution": [0.6]}}))
    assert scene.settings.simulation is not None
    kept = scene.settings.simulation.subset
    assert set(kept) == {"compliant"} and kept["compliant"]["frequency"].tolist() == [24.0] and kept["compliant"]["restitution"].tolist() == [0.6]


@pytest.mark.parametrize(
    ("subset", "simulation", "expected"),
    [
        ({"exact": {"frequency": [22.0]}}, {}, "simulation.subset.exact: 'exact' is not a time-domain solution of this scene: use one of compliant_exact, compliant"),
        ({"compliant": {"frequency": [23.0]}}, {}, "simulation.subset.compliant.frequency: 23 not on the simulated frequencies (simulation.frequency, else sweep.frequency): allowed one of 22, 24, 26 [Hz]"),
        ({"compliant": {"clearance": [0.003]}}, {}, "simulation.subset.compliant.clearance: clearance is not swept in this scene"),
        ({"compliant": {"restitution": [0.3]}}, {}, "simulation.subset.compliant.restitution: 0.3 not on the grid of sweep.restitution: allowed one of 0.2, 0.6 [-]"),
        ({"compliant": {"phase": [1.0]}}, {}, "simulation.subset.compliant.phase: unknown key"),
        ({"compliant": {}}, {}, "simulation.subset.compliant: empty: name at least one axis of frequency, restitution"),
        ([22.0], {}, "simulation.subset: expected a mapping, got [22.0] (list): {solution: {axis: [values]}}"),
        ({"compliant": {"frequency": [22.0]}}, {"start": "sweep_up"}, "simulation.subset.compliant.frequency: a stepped sweep (start: sweep_up) follows every simulated frequency"),
    ],
)
def test_each_subset_mistake_names_its_key_and_what_is_allowed(subset: Any, simulation: dict[str, Any], expected: str) -> None:
    problems = problems_of(subset_scene(subset, **simulation))
    assert any(p.startswith(expected) for p in problems), problems


def test_the_subset_solution_is_computed_on_its_points_only() -> None:
    """IDA at (R = 0.6, 24 Hz) only; the closed-form bumper everywhere, agreeing with it there."""
    scene = parse_scene(subset_scene({"compliant": {"frequency": [24.0], "restitution": [0.6]}}, max_periods=60, lyapunov_periods=8, irregular_measure_periods=8))
    grid = StudyGrid.of(scene)
    with Runner(jobs=1) as runner:
        ida = general_simulated_values(scene, "compliant", grid.full, runner)
        exact = general_simulated_values(scene, "compliant_exact", grid.full, runner)
    f = grid.frequency
    computed = ida["regime"][:, 0, 0, 0, :] != Regime.NOT_COMPUTED
    assert computed.sum() == 1 and computed[1, np.flatnonzero(f == 24.0)[0]]  # exact: a parsed grid value
    simulated = np.isin(f, [22.0, 24.0, 26.0])
    assert np.all((exact["regime"][:, 0, 0, 0, :] != Regime.NOT_COMPUTED) == simulated[None, :])
    at = (1, 0, 0, 0, np.flatnonzero(f == 24.0)[0])  # exact: a parsed grid value
    assert ida["x1_amplitude"][at] == pytest.approx(exact["x1_amplitude"][at], rel=1e-4)
