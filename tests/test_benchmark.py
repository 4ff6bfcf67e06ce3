"""The engine-cost benchmark: impact matching, equal-error speed-up, a small run end to end."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from vibroimpact import cli
from vibroimpact.benchmark import BenchmarkCase, BenchmarkSettings, _compare, equal_error_speedup, run_benchmark
from vibroimpact.engines import ExactEngine, ImpactProblem, Trajectory
from vibroimpact.system import TwoDofSystem

from .conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE


def _with_impacts(reference: Trajectory, times: np.ndarray) -> Trajectory:
    """A copy of ``reference`` with other impact times (same impulses where counts match)."""
    impulses = np.resize(reference.impulses, times.size)
    return Trajectory(reference.problem, reference.strobe_times, reference.strobe_states, times, np.resize(reference.impact_velocities, times.size), impulses, reference.segments, reference.segment_states, reference.moments)


def test_impact_matching_counts_missed_and_extra(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, PAPER_CLEARANCE, 0.2, PAPER_AMPLITUDE, 25.0)
    reference = ExactEngine().integrate(problem, np.zeros(4), 0.0, 20)
    times = reference.impact_times
    assert _compare(reference, reference)["missed_impacts"] == 0
    shifted = _with_impacts(reference, times + 1e-9)
    result = _compare(reference, shifted)
    assert result["missed_impacts"] == 0 and result["extra_impacts"] == 0 and result["impact_time_error"] == pytest.approx(1e-9, rel=1e-3)
    fewer = _with_impacts(reference, np.delete(times, [3, 7]))
    assert _compare(reference, fewer)["missed_impacts"] == 2
    more = _with_impacts(reference, np.sort(np.append(times, times[5] + 0.3 / problem.frequency)))
    assert _compare(reference, more)["extra_impacts"] == 1
    assert _compare(reference, _with_impacts(reference, np.array([])))["missed_impacts"] == times.size


def test_equal_error_speedup_interpolates_log_log() -> None:
    wall = np.array([[[1.0, 2.0], [2.0, 8.0]]])  # case x engine x rtol
    error = np.array([[[1e-6, 1e-8], [1e-6, 1e-10]]])
    zeros = np.zeros_like(wall)
    data = xr.Dataset(
        {"wall_time": (("case", "engine", "rtol"), wall), "impact_time_error": (("case", "engine", "rtol"), error), "missed_impacts": (("case", "engine", "rtol"), zeros)},
        coords={"case": ["c"], "engine": ["fast", "slow"], "rtol": [1e-6, 1e-8]},
    )
    ratio, other = equal_error_speedup(data, "c", "fast", 1e-8, ["slow"])
    # slow reaches 1e-8 halfway (in log) between (1e-6, 2 s) and (1e-10, 8 s): 4 s, against fast's 2 s
    assert other == "slow" and ratio == pytest.approx(2.0, rel=1e-12)
    data["missed_impacts"][0, 1, :] = 1
    assert np.isnan(equal_error_speedup(data, "c", "fast", 1e-8, ["slow"])[0])


def test_small_benchmark_runs_every_method(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, PAPER_CLEARANCE, 0.2, PAPER_AMPLITUDE, 25.0)
    cases = [BenchmarkCase("c", problem, "rest", 20)]
    settings = BenchmarkSettings(methods=("momentary_adams", "solve_ivp_DOP853"), tolerances=(1e-6, 1e-9), repeats=1)
    data = run_benchmark(cases, settings, progress=False)
    assert data["wall_time"].dims == ("case", "engine", "rtol")
    assert bool((data["missed_impacts"] == 0).all())
    adams = data.sel(case="c", engine="momentary_adams")["impact_time_error"].values
    assert adams[1] < adams[0] / 10  # tighter tolerance, smaller error
    assert float(data["reference_impacts"].sel(case="c")) == data["impacts"].sel(case="c", engine="momentary_adams", rtol=1e-9).item()


def test_benchmark_scene_end_to_end(tmp_path: Path) -> None:
    scene = {
        "name": "tiny_cost",
        "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
        "excitation": {"amplitude": 10.0},
        "benchmark": {
            "duration": 0.4,
            "methods": ["momentary_adams", "solve_ivp_DOP853"],
            "tolerances": [1e-6],
            "repeats": 1,
            "cases": [{"name": "graze", "frequency": 30.0, "restitution": 0.9, "clearance_below_linear": 5e-10, "start": "linear"}],
        },
    }
    path = tmp_path / "tiny.yaml"
    path.write_text(yaml.safe_dump(scene))
    assert cli.main([str(path), "--out", str(tmp_path / "o")]) == 0
    data = xr.open_dataset(tmp_path / "o" / "tiny_cost.nc")
    assert int(data["reference_impacts"].sel(case="graze")) >= 3
    assert int(data["impacts"].sel(case="graze", engine="solve_ivp_DOP853", rtol=1e-6)) < int(data["impacts"].sel(case="graze", engine="momentary_adams", rtol=1e-6))
    assert (tmp_path / "o" / "report.html").is_file() and (tmp_path / "o" / "work_precision.png").is_file()
