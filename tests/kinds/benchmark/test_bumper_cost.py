"""The bumper in the engine-cost benchmark: ``compliant_exact`` (closed form) beside ``compliant_ida`` in one run, so
that their costs per period are read as a ratio of the same run. No assertion on how fast anything is: speed targets
live in the benchmark's output only (measured on a loaded 2-core machine: 22 us per period against IDA's 3.1 ms at
rtol 1e-6 and 9.5 ms at 1e-10, 140-440x)."""

from __future__ import annotations

import functools

import numpy as np
import xarray as xr

from vibroimpact.kinds.benchmark.scene import BenchmarkCase, BenchmarkSettings
from vibroimpact.kinds.benchmark.study import TOLERANCE_FREE, run_benchmark
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

PERIODS = 12


@functools.cache
def _bumper(system: TwoDofSystem) -> xr.Dataset:
    """The paper's 25 Hz case from rest with a 250 Hz bumper of R = 0.2: the exact bumper and IDA at two tolerances."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    bumper = (Stop(KelvinVoigtBumper(PAPER_CLEARANCE, 250.0, loss_factor_from_restitution(0.2)), coordinate=1),)
    settings = BenchmarkSettings(methods=("compliant_exact", "compliant_ida"), tolerances=(1e-6, 1e-8), repeats=1)
    return run_benchmark([BenchmarkCase("bumper", problem, "rest", PERIODS, bumper=bumper)], settings, progress=False)


def test_the_exact_bumper_runs_once_beside_ida_and_is_the_compliant_reference(system: TwoDofSystem) -> None:
    """compliant_exact has no tolerance: one run, stored at every rtol; it is the compliant reference of a stepped case
    (its contacts are the reference's, its X1 error 0) and IDA is measured against it. Both engines have a cost per
    period in the same dataset (their ratio is the benchmark's reading)."""
    data = _bumper(system)
    assert "compliant_exact" in TOLERANCE_FREE and data.attrs["tolerance_free_engines"] == "compliant_exact"
    line = data.sel(case="bumper", engine="compliant_exact")
    for name in ("wall_time", "x1_error", "impacts"):
        values = line[name].values
        np.testing.assert_array_equal(values, np.full_like(values, values[0]))  # one run, copied
    assert int(line["impacts"].values[0]) == int(data["reference_impacts"].sel(case="bumper", reference="compliant_exact")) >= PERIODS - 2
    assert np.isnan(float(data["reference_impacts"].sel(case="bumper", reference="compliant_cvode_adams")))  # no integrator as reference
    assert int(line["missed_impacts"].values[0]) == 0 and float(line["x1_error"].values[0]) < 1e-15
    costs = data["time_per_period"].sel(case="bumper")
    assert np.all(np.isfinite(costs.values) & (costs.values > 0.0))
    assert float(data["x1_error"].sel(case="bumper", engine="compliant_ida", rtol=1e-8)) < 1e-6  # IDA near the reference at its tolerance
