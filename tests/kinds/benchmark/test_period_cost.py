"""Costs per period in the engine-cost benchmark: exact, its compiled kernel alone (the floor), engines without a
tolerance run once. No assertion on how fast anything is: speed targets live in the benchmark's output only."""

from __future__ import annotations

import functools

import numpy as np
import xarray as xr

from vibroimpact.kinds.benchmark.study import TOLERANCE_FREE, exact_kernel, run_benchmark
from vibroimpact.engines import exact_core
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.kinds.benchmark.scene import BenchmarkCase, BenchmarkSettings
from vibroimpact.kinds.benchmark.variables import BENCHMARK_ATTRIBUTES

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

#: The variables of the per-period costs and their dimensions.
PER_PERIOD = {
    "periods": ("case",),
    "time_per_period": ("case", "engine", "rtol"),
    "reference_time_per_period": ("case",),
    "floor_time_per_period": ("case",),
    "floor_no_moments_time_per_period": ("case",),
}
#: Periods of the small case.
PERIODS = 12


@functools.cache
def _small(system: TwoDofSystem) -> xr.Dataset:
    """exact_python and momentary_adams at two tolerances on a short 25 Hz run from rest, one repeat."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    settings = BenchmarkSettings(methods=("exact_python", "momentary_adams"), tolerances=(1e-6, 1e-8), repeats=1)
    return run_benchmark([BenchmarkCase("c", problem, "rest", PERIODS)], settings, progress=False)


def test_per_period_costs_exist_with_units(system: TwoDofSystem) -> None:
    data = _small(system)
    for name, dims in PER_PERIOD.items():
        assert data[name].dims == dims, name
        assert data[name].attrs["units"] == BENCHMARK_ATTRIBUTES[name]["units"] and data[name].attrs["long_name"], name
        values = data[name].values
        assert np.all(np.isfinite(values) & (values > 0)), name
    assert int(data["periods"].sel(case="c")) == PERIODS
    # each per-period cost is its run's wall time over the periods
    np.testing.assert_allclose(data["time_per_period"].values * PERIODS, data["wall_time"].values, rtol=1e-12)
    np.testing.assert_allclose(float(data["reference_time_per_period"].sel(case="c")) * PERIODS, float(data["exact_wall_time"].sel(case="c")), rtol=1e-12)


def test_engine_without_tolerance_runs_once_and_agrees_with_exact(system: TwoDofSystem) -> None:
    """exact_python is measured once and stored at every rtol; being the same algorithm, it finds the reference's
    impacts and its X1 to round-off."""
    data = _small(system)
    assert "exact_python" in TOLERANCE_FREE and data.attrs["tolerance_free_engines"] == "exact_python"
    line = data.sel(case="c", engine="exact_python")
    for name in ("wall_time", "x1_error", "impacts"):
        values = line[name].values
        np.testing.assert_array_equal(values, np.full_like(values, values[0]))  # one run, copied
    assert int(line["impacts"].values[0]) == int(data["reference_impacts"].sel(case="c", reference="exact")) > 0
    assert int(line["missed_impacts"].values[0]) == 0 and float(line["x1_error"].values[0]) < 1e-9
    # momentary is run at each tolerance (different runs)
    assert np.all(np.isfinite(data["wall_time"].sel(case="c", engine="momentary_adams").values))


def test_floor_runs_the_compiled_kernel(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 37.0))
    case = BenchmarkCase("k", problem, "rest", 5)
    for moments in (True, False):
        assert exact_kernel(case, moments)() == exact_core.STATUS_OK


def test_swept_case_has_no_per_period_cost(system: TwoDofSystem) -> None:
    """Only the per-period variables of stepped cases are filled (a swept case has no exact reference)."""
    from vibroimpact.model.contact import KelvinVoigtBumper, loss_factor_from_restitution
    from vibroimpact.model.excitation import SweptSine

    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 24.0))
    swept = BenchmarkCase("s", problem, "rest", 0, bumper=KelvinVoigtBumper(PAPER_CLEARANCE, 250.0, loss_factor_from_restitution(0.2)), sweep=SweptSine(PAPER_AMPLITUDE, 24.0, 24.05, 0.1), sample_rate=1000.0)
    data = run_benchmark([swept], BenchmarkSettings(methods=("compliant_cvode_adams",), tolerances=(1e-6,), repeats=1), progress=False)
    for name in PER_PERIOD:
        assert np.all(np.isnan(data[name].values)), name
