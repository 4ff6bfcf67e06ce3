"""Studies: the output contract, the golden regression file, and what a scene asks for."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from vibroimpact.analysis.stability import Regime
from vibroimpact.scene import load_scene, parse_scene
from vibroimpact.runs.labels import decode_labels
from vibroimpact.runs.run import read_dataset, write_dataset
from vibroimpact.runs.run import run_study

DATA = Path(__file__).parents[2] / "data"


def small_scene(**changes: object) -> dict:
    scene = yaml.safe_load((DATA / "golden_small.yaml").read_text())
    scene.update(changes)
    return scene


@pytest.fixture(scope="module")
def golden_run() -> xr.Dataset:
    return run_study(load_scene(DATA / "golden_small.yaml"), progress=None)


def test_matches_golden_netcdf(golden_run: xr.Dataset, tmp_path: Path) -> None:
    """Regression: the same scene gives the stored dataset (after a write/read round trip). The stored file predates
    the labels' move to ``solution_label`` (a string coordinate variable ``solution``): read_dataset reads both."""
    fresh, golden = read_dataset(write_dataset(golden_run, tmp_path / "run.nc")), read_dataset(DATA / "golden_small.nc")
    xr.testing.assert_allclose(fresh, golden, rtol=1e-9, atol=1e-15)
    xr.testing.assert_equal(fresh["regime"], golden["regime"])


def test_output_contract(golden_run: xr.Dataset) -> None:
    ds = golden_run
    assert ds["x1_amplitude"].dims == ("solution", "restitution", "clearance", "frequency")
    assert list(ds["solution"].values) == ["linear", "pgf", "pgf_paper"]
    for name in ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse", "frequency", "clearance", "restitution", "regime"):
        assert ds[name].attrs["units"] and ds[name].attrs["long_name"], name
    assert ds["frequency"].attrs["units"] == "Hz" and ds["clearance"].attrs["units"] == "m"
    assert ds["force_amplitude"].attrs["units"] == "N" and ds["impulse"].attrs["units"] == "N s"
    meanings = ds["regime"].attrs["flag_meanings"].split()
    assert {"linear", "one_impact", "none", "not_computed"} <= set(meanings)
    assert dict(zip(meanings, ds["regime"].attrs["flag_values"]))["linear"] == 0
    np.testing.assert_array_equal(ds["regime"].attrs["flag_values"], [int(r) for r in Regime])
    assert "golden_small" in ds.attrs["scene"] and ds.attrs["vibroimpact_version"]
    assert "admissibility_samples_per_period" in ds.attrs and "method_pgf" in ds.attrs


def test_values_follow_the_regime(golden_run: xr.Dataset) -> None:
    """Admissible one-impact -> impulse > 0; linear -> impulse 0 and linear amplitudes; none -> NaN."""
    pgf = golden_run.sel(solution="pgf", drop=True)
    linear = golden_run.sel(solution="linear", drop=True)
    regime = pgf["regime"]
    impact = regime.isin([Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR])
    free = regime.isin([Regime.LINEAR, Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT, Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT])
    assert impact.any() and free.any()
    assert bool((pgf["impulse"].where(impact) > 0).sum() == impact.sum())
    xr.testing.assert_allclose(pgf["x1_amplitude"].where(free), linear["x1_amplitude"].where(free))
    assert bool(pgf["x1_amplitude"].where(~impact & ~free).isnull().all())
    # linear regime is only claimed where the linear motion really fits inside the clearance
    assert bool((linear["x2_amplitude"].where(free) <= golden_run["clearance"]).sum() == free.sum())
    # an unstable one-impact orbit is never reported where the stable linear motion fits
    coexisting = regime == Regime.ONE_IMPACT_COEXISTING_LINEAR
    assert not bool(((pgf["stable"] == 0) & coexisting).any())
    assert bool((regime == Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT).any())
    # the raw one-impact values cover every point where a solution exists
    exists = pgf["one_impact_impulse"].notnull()
    assert bool((pgf["one_impact_x1_amplitude"].notnull() == exists).all()) and bool(exists.sum() >= impact.sum())


def test_large_clearance_study_is_linear() -> None:
    """Delta -> infinity through the whole pipeline: every pgf value equals the linear one, impulse 0."""
    scene = parse_scene(small_scene(sweep={"restitution": [0.0, 0.5], "clearance": [1.0, 5.0], "frequency": {"start": 15, "stop": 45, "step": 0.05}}, solutions=["linear", "pgf"]))
    ds = run_study(scene, progress=None)
    for name in ("x1_amplitude", "x2_amplitude", "force_amplitude"):
        xr.testing.assert_allclose(ds[name].sel(solution="pgf", drop=True), ds[name].sel(solution="linear", drop=True), rtol=1e-14)
    assert bool((ds["impulse"].sel(solution="pgf") == 0).all())
    assert bool((ds["regime"].sel(solution="pgf") == Regime.LINEAR).all())


def test_only_requested_quantities_and_unswept_parameters_as_scalars() -> None:
    scene = parse_scene(small_scene(sweep={"frequency": [24.0, 25.0]}, stop={"clearance": 0.003, "restitution": 0.2}, solutions=["pgf"], quantities=["impulse"]))
    ds = run_study(scene, progress=None)
    assert set(ds.data_vars) == {"impulse", "regime"}
    assert ds["impulse"].dims == ("solution", "frequency")
    assert float(ds["clearance"]) == 0.003 and float(ds["restitution"]) == 0.2  # exact: input coordinates


def test_write_is_atomic_and_leaves_no_temporary(golden_run: xr.Dataset, tmp_path: Path) -> None:
    target = tmp_path / "out" / "x.nc"
    write_dataset(golden_run, target)
    write_dataset(golden_run, target)  # overwrite through a rename
    assert sorted(p.name for p in target.parent.iterdir()) == ["x.nc"]


def test_failed_write_keeps_previous_file(golden_run: xr.Dataset, tmp_path: Path) -> None:
    target = tmp_path / "x.nc"
    write_dataset(golden_run, target)
    before = target.read_bytes()
    broken = golden_run.copy()
    broken.attrs["not_serialisable"] = {"a": 1}
    with pytest.raises(Exception):
        write_dataset(broken, target)
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.nc"]


@pytest.mark.slow
def test_simulated_solutions_join_the_dataset(tmp_path: Path) -> None:
    """Engines on their own coarse grid (the file's group ``simulated``); on stable one-impact points they equal pgf;
    CLI in this process (--jobs 1; the local dask cluster's results are the same: test_cases.py)."""
    from vibroimpact import cli

    doc = small_scene(
        sweep={"frequency": {"start": 24.0, "stop": 26.0, "step": 0.25}},
        stop={"clearance": 0.003, "restitution": 0.2},
        solutions=["pgf", "exact", "momentary"],
        simulation={"frequency": [24.5, 25.1, 30.0], "start": "pgf", "tolerance": 1e-9, "rtol": 1e-10, "atol": 1e-14},
        report=True,
    )
    path = tmp_path / "sim.yaml"
    path.write_text(yaml.safe_dump(doc))
    assert cli.main([str(path), "--out", str(tmp_path / "o"), "--jobs", "1"]) == 0
    assert not (tmp_path / "o" / ".cache").exists()
    path = tmp_path / "o" / "golden_small.nc"
    with xr.open_dataset(path) as root, xr.open_dataset(path, group="simulated") as group:  # the engines on their own grid
        ds, simulated = decode_labels(root), decode_labels(group)  # the labels back on ``solution``
        assert 25.1 in ds["frequency"].values and 30.0 in ds["frequency"].values and list(ds["solution"].values) == ["pgf"]
        np.testing.assert_array_equal(simulated["frequency"].values, [24.5, 25.1, 30.0])
        for engine in ("exact", "momentary"):
            assert bool(simulated["x1_amplitude"].sel(solution=engine).notnull().all())
            for f in (24.5, 25.1):
                point = simulated.sel(solution=engine, frequency=f)
                assert int(point["converged"]) == 1 and float(point["impacts_per_period"]) == 1.0  # exact: a count per period
                assert int(point["regime"]) == Regime.ONE_IMPACT
                assert float(point["x1_amplitude"]) == pytest.approx(float(ds["x1_amplitude"].sel(solution="pgf", frequency=f)), rel=1e-6)
                assert float(point["impulse"]) == pytest.approx(float(ds["impulse"].sel(solution="pgf", frequency=f)), rel=1e-6)
            linear_point = simulated.sel(solution=engine, frequency=30.0)
            assert int(linear_point["regime"]) == Regime.LINEAR and float(linear_point["impacts_per_period"]) == 0.0  # exact: a count per period
        assert "converged" not in ds  # the closed form's would be not_applicable everywhere: no placeholder
    page = (tmp_path / "o" / "report.html").read_text()
    assert "Simulation against PGF by band" in page and (tmp_path / "o" / "simulation_x1_amplitude.png").is_file()
    # a table of contents, and the simulations' reduction factors counted on their own grid (3 points, all in band 1)
    assert "<nav id='contents'>" in page and "Reduction factors" in page
    assert "<td>3 / 0</td><td>0 / 0</td>" in page
