"""Studies with the compliant bumper: dimensions, the PGF peak-acceleration estimate, and agreement with it."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import xarray as xr

from vibroimpact.model.contact import peak_acceleration_factor, restitution_from_loss_factor
from vibroimpact.scene import parse_scene
from vibroimpact.runs.run import run_study

from tests.scene.test_scene import PAPER_SYSTEM_SPEC

pytestmark = pytest.mark.slow  # a whole study per module: the slow tier (issue 49, measured)


def bumper_scene(**changes: Any) -> dict[str, Any]:
    document: dict[str, Any] = {
        "name": "bumper",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003, "restitution": 0.2},
        "sweep": {"bumper_frequency": [500.0, 4000.0], "frequency": [24.0, 25.0]},
        "solutions": ["pgf", "momentary", "compliant"],
        "simulation": {"rtol": 1e-9, "atol": 1e-13, "tolerance": 1e-8, "max_periods": 300},
        "report": False,
    }
    document.update(changes)
    return document


@pytest.fixture(scope="module")
def stiffness_run() -> xr.Dataset:
    return run_study(parse_scene(bumper_scene()), progress=None)


def test_dimensions_and_coordinates(stiffness_run: xr.Dataset) -> None:
    ds = stiffness_run
    assert ds["x1_amplitude"].dims == ("solution", "bumper_frequency", "frequency")
    assert ds["bumper_frequency"].attrs["units"] == "Hz" and ds["bumper_loss_factor"].attrs["units"] == "1"
    assert restitution_from_loss_factor(float(ds["bumper_loss_factor"])) == pytest.approx(0.2, rel=1e-12)
    for name in ("peak_acceleration", "peak_contact_force", "wall_time"):
        assert ds[name].attrs["units"], name
    # the rigid-stop solutions do not depend on the bumper: one computation, broadcast
    momentary = ds["x1_amplitude"].sel(solution="momentary").values
    np.testing.assert_array_equal(momentary[0], momentary[1])
    assert np.all(np.isnan(ds["peak_acceleration"].sel(solution="momentary").values))  # an impulse has no finite peak
    assert np.all(ds["wall_time"].sel(solution="compliant").values > 0.0)


def test_pgf_peak_estimates(stiffness_run: xr.Dataset) -> None:
    """Force: Gamma(xi_b) Omega_b J / (1 + R). Deceleration: that force less the absorber spring's pull at the impact,
    over M2; the spring force here comes from an independent exact-engine run of the orbit (state just before an
    impact)."""
    from vibroimpact.engines.exact import ExactEngine

    from tests.engine_cases import pgf_start

    ds = stiffness_run.sel(solution="pgf")
    xi = float(stiffness_run["bumper_loss_factor"])
    s = PAPER_SYSTEM_SPEC
    for f in ds["frequency"].values:
        problem, state, t0, _orbit = pgf_start(float(f), 0.2)
        exact = ExactEngine()
        trajectory = exact.integrate(problem, state, t0, 2)
        before = exact.dense(trajectory, np.array([trajectory.impact_times[0] - 1e-12]))[0]
        spring = s["k2"] * (before[0] - before[1]) + s["b2"] * (before[2] - before[3])
        impulse = float(ds["impulse"].sel(frequency=f, bumper_frequency=500.0))
        assert trajectory.impulses[0] == pytest.approx(impulse, rel=1e-9)
        for bumper in ds["bumper_frequency"].values:
            point = ds.sel(frequency=f, bumper_frequency=bumper)
            force = peak_acceleration_factor(xi) * 2 * math.pi * bumper * impulse / 1.2
            assert float(point["peak_contact_force"]) == pytest.approx(force, rel=1e-12)
            assert float(point["peak_acceleration"]) == pytest.approx((force - spring) / s["m2"], rel=1e-8)


def test_compliant_peaks_and_amplitudes_approach_the_rigid_values(stiffness_run: xr.Dataset) -> None:
    """As Omega_b grows 8x the compliant |X1| and peak deceleration approach the rigid-stop values (PGF): |X1| within
    6 % at 500 Hz and 1 % at 4 kHz (measured 5.3/4.8 % and 0.66/0.60 %), peak deceleration and force within 5 % and
    1 % (3.5/2.7 % and 0.45/0.36 % for both), the errors shrinking about 8x (first order in 1 / Omega_b)."""
    ds = stiffness_run
    x1 = ds["x1_amplitude"].sel(solution="compliant") / ds["x1_amplitude"].sel(solution="pgf") - 1.0
    peak = ds["peak_acceleration"].sel(solution="compliant") / ds["peak_acceleration"].sel(solution="pgf") - 1.0
    assert np.all(np.abs(x1.sel(bumper_frequency=500.0)) < 0.06) and np.all(np.abs(x1.sel(bumper_frequency=4000.0)) < 0.01)
    force = ds["peak_contact_force"].sel(solution="compliant") / ds["peak_contact_force"].sel(solution="pgf") - 1.0
    for error in (peak, force):
        assert np.all(np.abs(error.sel(bumper_frequency=500.0)) < 0.05) and np.all(np.abs(error.sel(bumper_frequency=4000.0)) < 0.01)
    for error in (x1, peak, force):
        ratio = (error.sel(bumper_frequency=500.0) / error.sel(bumper_frequency=4000.0)).values
        assert np.all((ratio > 6.0) & (ratio < 10.0)), ratio
    assert np.all(ds["impacts_per_period"].sel(solution="compliant").values == 1.0)  # exact: a count per period


def test_swept_loss_factor_becomes_the_dimension() -> None:
    document = bumper_scene(solutions=["pgf"], stop={"clearance": 0.003})
    del document["simulation"]
    document["bumper"] = {"frequency": 250.0}
    document["sweep"] = {"bumper_loss_factor": [0.3, 0.7], "frequency": [24.0, 25.0]}
    ds = run_study(parse_scene(document), progress=None)
    assert ds["x1_amplitude"].dims == ("solution", "bumper_loss_factor", "frequency")
    np.testing.assert_allclose(ds["restitution"].values, [restitution_from_loss_factor(x) for x in (0.3, 0.7)])
    assert ds["restitution"].dims == ("bumper_loss_factor",)
