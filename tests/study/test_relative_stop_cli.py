"""``run-study`` on general scenes: a relative-stop scene end to end, bad matrices refused before any work, the
shipped general example and its estimate."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from vibroimpact import cli
from vibroimpact.analysis.stability import Regime
from vibroimpact.runs.run import read_dataset
from vibroimpact.scene import load_scene, shipped_studies_dir

SCENE: dict[str, Any] = {
    "name": "relative_cli",
    "system": {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]]},
    "excitation": {"amplitude": 10.0, "on": "x1"},
    "stops": [
        {"between": ["x2", "x1"], "side": "upper", "clearance": 0.003, "restitution": 0.2},
        {"between": ["x2", "x1"], "side": "lower", "clearance": 0.003, "restitution": 0.2},
    ],
    "sweep": {"frequency": {"start": 20.0, "stop": 40.0, "step": 0.5}},
    "solutions": ["linear", "pgf", "momentary"],
    "simulation": {"frequency": [22.5, 30.0], "start": "pgf", "max_periods": 100, "lyapunov_periods": 0, "irregular_measure_periods": 16},
    "report": False,
}


def write(path: Path, document: dict[str, Any]) -> Path:
    path.write_text(yaml.safe_dump(document, sort_keys=False), encoding="utf-8")
    return path


def test_relative_stop_scene_end_to_end(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The dataset has per-coordinate amplitudes and per-stop impulses; the simulation finds the closed form's
    symmetric orbit where it is stable (22.5 Hz: both impulses, two impacts per period, to 1e-6; measured 2e-8)."""
    out = tmp_path / "out"
    assert cli.main([str(write(tmp_path / "scene.yaml", copy.deepcopy(SCENE))), "--out", str(out), "--jobs", "1"]) == 0
    dataset = read_dataset(out / "relative_cli.nc")  # the file's groups joined: every solution on every frequency
    assert dataset["impulse"].dims == ("solution", "stop", "frequency")
    assert list(dataset["stop_description"].values) == ["x2 - x1 <= 3 mm, R = 0.2", "x2 - x1 >= -3 mm, R = 0.2"]
    at = dataset.sel(frequency=22.5)
    pgf, simulated = at.sel(solution="pgf"), at.sel(solution="momentary")
    assert int(pgf["regime"]) == Regime.ONE_IMPACT and int(pgf["stable"]) == 1
    assert float(simulated["impacts_per_period"]) == pytest.approx(2.0, abs=0)
    assert int(simulated["regime"]) == Regime.ONE_IMPACT  # on a two-sided stop: one impact per period on each side
    np.testing.assert_allclose(simulated["impulse"].values, pgf["impulse"].values, rtol=1e-6)
    np.testing.assert_allclose(simulated["x1_amplitude"].values, pgf["x1_amplitude"].values, rtol=1e-6)
    assert int(dataset["regime"].sel(solution="momentary", frequency=30.0)) == Regime.LINEAR
    assert "wrote" in capsys.readouterr().out


def test_bad_matrix_is_refused_before_any_work(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An asymmetric stiffness matrix and an unknown coordinate: exit 2, both named, nothing written."""
    document = copy.deepcopy(SCENE)
    document["system"]["stiffness"] = [[29300.0, -4300.0], [-4000.0, 4300.0]]
    document["stops"][0]["between"] = ["x2", "x3"]
    out = tmp_path / "out"
    assert cli.main([str(write(tmp_path / "bad.yaml", document)), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "system.stiffness: must be symmetric" in err and "stops[0].between[1]: 'x3' is not a coordinate" in err
    assert not out.exists()


def test_shipped_relative_stop_scene_and_its_estimate(capsys: pytest.CaptureFixture[str]) -> None:
    """The shipped general example loads, is general, and --estimate predicts without running."""
    scene = load_scene(shipped_studies_dir() / "relative_stop.yaml")
    assert scene.layout.paper_view() is None and len(scene.layout.stops) == 2
    assert cli.main(["relative_stop.yaml", "--estimate", "--jobs", "2"]) == 0
    assert "predicted wall time" in capsys.readouterr().out
