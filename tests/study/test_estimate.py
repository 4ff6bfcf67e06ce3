"""``run-study --estimate``: what it predicts, checked against what a run does."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from vibroimpact import cli
from vibroimpact.model.contact import RigidStop
from vibroimpact.runs.estimate import default_costs
from vibroimpact.runs.estimate import SPEED_FACTOR_RANGE, estimate_scene, speed_factor
from vibroimpact.kinds.stepped.study import expected_periods
from vibroimpact.scene import load_scene, parse_scene, shipped_studies_dir
from vibroimpact.kinds.stepped.cases import SimulationCase, run_case
from vibroimpact.runs.run import run_study

from tests.scene.test_scene import PAPER_SYSTEM_SPEC


def small_scene() -> dict:
    return {
        "name": "small",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003, "restitution": 0.2},
        "sweep": {"frequency": {"start": 18.0, "stop": 30.0, "step": 1.0}},
        "solutions": ["linear", "pgf", "momentary"],
        "simulation": {"rtol": 1e-8, "atol": 1e-12, "max_periods": 100},
        "report": False,
    }


def test_predicted_integration_matches_what_the_run_does() -> None:
    """Points predicted to need no integration are exactly those the run answers without integrating."""
    scene = parse_scene(small_scene())
    assert scene.settings.simulation is not None
    periods, scale = expected_periods(scene)
    assert scale == 1.0  # exact: no subsampling: factor set to 1
    predicted = periods[0, 0]
    case = SimulationCase("momentary", scene.layout.structure, scene.amplitude, RigidStop(0.003, 0.2), tuple(scene.settings.simulation.frequency), "pgf", scene.settings.simulation.engine, scene.settings.simulation.steady)
    used = run_case(case)["periods_used"]
    np.testing.assert_array_equal(predicted == 0, used == 0)
    assert np.all(predicted[used > 0] >= 48)  # a settling transient plus the measurement, or the irregular budget


def test_costs_grow_as_tolerances_tighten() -> None:
    costs = default_costs()
    for engine in ("momentary_adams", "compliant_ida"):
        assert costs.per_period_cost(engine, 1e-12) > costs.per_period_cost(engine, 1e-4)
    assert costs.per_period_cost("exact", 1e-3) == costs.per_period_cost("exact", 1e-12)


def test_memory_estimate_grows_with_the_dataset_read_by_the_report_and_the_workers() -> None:
    """A stepped study streams its blocks into the store and exports them chunk by chunk: without a report its main
    process does not grow with the grid; the report reads the dataset whole."""
    costs = default_costs()
    scene = parse_scene(small_scene())
    reported = parse_scene(small_scene() | {"report": True})
    one = estimate_scene(scene, jobs=1)
    dataset = run_study(scene, progress=None)
    assert one.memory == costs.main_process_memory  # exact: no report, no workers, blocks only
    assert estimate_scene(reported, jobs=1).memory >= costs.main_process_memory + dataset.nbytes
    assert estimate_scene(scene, jobs=2).memory == one.memory + costs.worker_process_memory * min(2, __import__("os").cpu_count() or 1) or (__import__("os").cpu_count() or 1) == 1
    big = small_scene() | {"sweep": {"restitution": [0.1, 0.2, 0.3], "frequency": {"start": 18.0, "stop": 30.0, "step": 0.001}}}
    big["stop"] = {"clearance": 0.003}
    assert estimate_scene(parse_scene(big), jobs=1).memory == one.memory  # exact: bounded, the same sum
    assert estimate_scene(parse_scene(big | {"report": True}), jobs=1).memory > one.memory + 2 * dataset.nbytes
    assert "momentary" in one.parts and "integrated" in one.points["momentary"]


def test_start_modes_are_predicted_as_they_run() -> None:
    """rest: every point integrates for the whole budget; stepped sweeps: linear-fitting points answered at once."""
    document = small_scene()
    document["simulation"] = {"rtol": 1e-8, "max_periods": 100, "start": "rest"}
    rest, _ = expected_periods(parse_scene(document))
    assert np.all(rest == 100 + 1024 + 64)  # marching, the Lyapunov run of a motion that did not repeat, the measurement
    document["simulation"]["start"] = "sweep_up"
    scene = parse_scene(document)
    swept, _ = expected_periods(scene)
    case = SimulationCase("momentary", scene.layout.structure, scene.amplitude, RigidStop(0.003, 0.2), tuple(scene.settings.simulation.frequency), "sweep_up", scene.settings.simulation.engine, scene.settings.simulation.steady)  # type: ignore[union-attr]
    used = run_case(case)["periods_used"]
    np.testing.assert_array_equal(swept[0, 0] == 0, used == 0)


def test_large_grids_are_subsampled() -> None:
    document = small_scene()
    document["sweep"] = {"frequency": {"start": 15.0, "stop": 45.0, "step": 0.0005}}
    scene = parse_scene(document)
    periods, scale = expected_periods(scene)
    assert periods.shape[-1] <= 20_000 and scale * periods.shape[-1] == pytest.approx(scene.settings.simulation.frequency.size)  # type: ignore[union-attr]


def test_cli_estimate_runs_nothing(tmp_path: Path, capsys: object) -> None:
    path = tmp_path / "small.yaml"
    path.write_text(yaml.safe_dump(small_scene()))
    out = tmp_path / "out"
    assert cli.main([str(path), "--estimate", "--out", str(out)]) == 0
    assert not out.exists()
    text = capsys.readouterr().out  # type: ignore[attr-defined]
    assert "predicted wall time" in text and "peak memory" in text


def test_every_shipped_study_has_an_estimate() -> None:
    for path in sorted(shipped_studies_dir().glob("*.yaml")):
        estimate = estimate_scene(load_scene(path), jobs=2, speed=1.0)
        assert 1.0 < estimate.wall_time < 3600.0, path.name


def test_a_slower_machine_gets_a_longer_prediction() -> None:
    """The prediction scales with the measured machine speed; the probe's own factor is a bounded positive number."""
    scene = parse_scene(small_scene())
    calibration, slower = estimate_scene(scene, jobs=1, speed=1.0), estimate_scene(scene, jobs=1, speed=2.5)
    assert slower.wall_time == pytest.approx(2.5 * calibration.wall_time)
    assert all(slower.parts[name] == pytest.approx(2.5 * seconds) for name, seconds in calibration.parts.items())
    assert slower.memory == calibration.memory and "2.50 x" in slower.text()
    assert SPEED_FACTOR_RANGE[0] <= speed_factor() <= SPEED_FACTOR_RANGE[1]


def test_a_clamped_probe_says_it_was_clamped(monkeypatch: pytest.MonkeyPatch) -> None:
    """A probe outside the believable range is clamped, and the estimate says so with the measured factor; a probe
    inside it is printed as measured."""
    from vibroimpact.runs import estimate

    scene = parse_scene(small_scene())
    shipped = estimate.default_costs().speed_probe_seconds
    low, high = SPEED_FACTOR_RANGE
    monkeypatch.setattr(estimate, "_probe_time", lambda: 37.0 * shipped)
    slow = estimate_scene(scene, jobs=1)
    assert slow.speed_factor == pytest.approx(high) and slow.measured_speed_factor == pytest.approx(37.0)
    assert "37.00 x" in slow.text() and "outside the believable range" in slow.text() and f"clamped to {high:.2f} x and may be short" in slow.text()
    monkeypatch.setattr(estimate, "_probe_time", lambda: 0.01 * shipped)
    fast = estimate_scene(scene, jobs=1)
    assert fast.speed_factor == pytest.approx(low) and f"clamped to {low:.2f} x and may be long" in fast.text()
    monkeypatch.setattr(estimate, "_probe_time", lambda: 3.0 * shipped)
    measured = estimate_scene(scene, jobs=1)
    assert measured.measured_speed_factor is None and "a probe took 3.00 x" in measured.text() and "outside" not in measured.text()


def test_the_estimate_needs_no_compiled_core(tmp_path: Path) -> None:
    """``--estimate`` on a fresh install answers without compiling the exact engine's core (30-60 s): in a process with
    an empty numba cache, the probe and the estimate of the main job leave no compiled exact core in the cache."""
    import os
    import subprocess
    import sys

    cache = tmp_path / "numba"
    code = "from vibroimpact.cli import main; raise SystemExit(main(['restitution', '--estimate']))"
    done = subprocess.run([sys.executable, "-c", code], env=os.environ | {"NUMBA_CACHE_DIR": str(cache)}, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "predicted wall time" in done.stdout
    compiled = sorted(path.name for path in cache.rglob("*.nbi"))
    assert not [name for name in compiled if name.startswith(("exact_core.", "exact_loop."))], compiled
