"""The design map is the design kind's grid search (issue 47: one design kind): ``studies/design_map.yaml`` is a design
scene, and a full grid over two variables is drawn as the map it is, one cell per candidate shaded by its own worst
case (nothing interpolated), the cells that break the operating limit hatched. Each cell's value is held to an
independent closed-form worst case of that candidate's problem on a 10x finer scan (the measures floor's
``worst_case``, not the study's screen): to 1e-9 where a stable closed-form motion sets it, to 1e-4 where none is
stable in the band and the value is the screen's guess (which follows its scan; issue 48 replaces the guess)."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from vibroimpact.kinds.design.answer import stage_counts
from vibroimpact.kinds.design.search_map import grid_cells, search_figure
from vibroimpact.kinds.design.study import DesignStudy, design_space
from vibroimpact.measures.worst_case import worst_case
from vibroimpact.runs.runner import Runner
from vibroimpact.scene.checker import SceneError
from vibroimpact.scene.reader import load_scene, parse_scene

import matplotlib.pyplot as plt

ROOT = Path(__file__).resolve().parents[3]

#: The shipped design map, shrunk: a 3 x 3 grid over a band with both period-1 motions and the notch limit.
SCENE = {
    "name": "grid_map",
    "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0},
    "stop": {"clearance": 0.003, "restitution": 0.2},
    "design": {
        "variables": {"restitution": [0.0, 0.9], "clearance": [0.0005, 0.006]},
        "band": {"start": 22.0, "stop": 28.0},
        "objective": "x1_amplitude",
        "constraints": {"operating": {"frequency": 33.0, "x1_amplitude": 0.00005}},
        "compare": "none",
        "search": {"method": "grid", "points": 3},
        "certify": {"candidates": 0},
    },
}


@pytest.fixture(scope="module")
def grid() -> tuple[xr.Dataset, object]:
    scene = parse_scene(copy.deepcopy(SCENE), text=yaml.safe_dump(SCENE, sort_keys=False))
    return DesignStudy().run(scene, None, Runner(jobs=1, progress=False)), scene


def test_the_shipped_design_map_is_a_design_scene_with_a_grid_search() -> None:
    scene = load_scene(ROOT / "studies" / "design_map.yaml")
    assert scene.kind == "design"
    assert scene.settings.search.method == "grid" and scene.settings.search.points == 20
    assert [v.name for v in scene.settings.variables] == ["restitution", "clearance"]


def test_a_stepped_scene_asking_for_the_old_design_map_page_is_sent_to_the_design_kind() -> None:
    document = {"name": "old", "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08}, "excitation": {"amplitude": 10.0},
                "stop": {"clearance": 0.003, "restitution": 0.2}, "sweep": {"frequency": [20.0, 25.0]}, "solutions": ["linear"], "report": "design_map"}  # fmt: skip
    with pytest.raises(SceneError, match="design kind's grid search"):
        parse_scene(document)


def test_each_cell_is_one_candidate_with_its_own_worst_case(grid: tuple[xr.Dataset, object]) -> None:
    dataset, scene = grid
    cells = grid_cells(dataset, ("restitution", "clearance"))
    assert cells is not None
    xs, ys, index = cells
    np.testing.assert_allclose(xs, [0.0, 0.45, 0.9], rtol=0, atol=1e-15)
    np.testing.assert_allclose(ys, [0.0005, 0.00325, 0.006], rtol=1e-12)
    assert sorted(index.ravel()) == sorted(np.flatnonzero(dataset["evaluation_stage"].values == list(stage_counts(dataset)).index("grid")))
    figure = search_figure(dataset)
    ax = figure.figure.axes[0]
    mesh = next(c for c in ax.collections if type(c).__name__ == "QuadMesh")
    np.testing.assert_allclose(np.asarray(mesh.get_array()).reshape(index.shape), np.log10(1e3 * dataset["objective"].values[index]), rtol=1e-14)
    assert not any(type(c).__name__ == "TriContourSet" for c in ax.collections)  # nothing interpolated
    assert "the search's path: best design so far, in evaluation order" not in {line.get_label() for line in ax.get_lines()}
    broken = int(np.sum(dataset["feasible"].values[index] != 1))
    assert 0 < broken < index.size  # the smallest clearance strikes the stop at the notch, the others do not
    assert f"{broken} of the 9 candidates have a |X1| at 33 Hz above the allowed 0.05 mm" in figure.caption
    assert "nothing is interpolated" in figure.caption
    plt.close(figure.figure)
    space = design_space(scene)
    for evaluation in index.ravel():
        design = [float(dataset[f"variable_{n}"].values[evaluation]) for n in ("restitution", "clearance")]
        found = worst_case(space.problem_at(np.array(design)), scene.settings.band, "x1_amplitude", "closed_form", scan=2411).found
        value = float(dataset["objective"].values[evaluation])
        if found.amplitude > 0.0:  # a stable closed-form motion sets it: located exactly, whatever the scan
            assert value == pytest.approx(max(found.amplitude, found.estimate if found.uncovered > 0.0 else 0.0), rel=1e-9), design
        else:  # no stable closed-form motion anywhere in the band: the screen's guess, which follows its scan
            assert found.uncovered == pytest.approx(1.0) and value == pytest.approx(found.estimate, rel=1e-4), design
