"""Bifurcation studies: the output contract on a small fast scene, and the physics of what it holds."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from vibroimpact.scene import parse_scene
from vibroimpact.kinds.bifurcation.study import diagram_problem
from vibroimpact.kinds.bifurcation.branches import closed_form_orbits
from vibroimpact.runs.run import run_study

pytestmark = pytest.mark.slow  # a whole study per module: the slow tier (issue 49, measured)

SMALL = {
    "name": "bif_small",
    "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0},
    "stop": {"clearance": 0.003},
    "bifurcation": {
        "frequency": {"start": 20.0, "stop": 27.0},
        "restitution": [0.8],
        "brute_force": {"step": 0.5, "transient_periods": 150, "strobes": 16},
        "continuation": {"max_steps": 300},
        "chart": {"restitution": 0.8, "clearance": {"start": 0.002, "stop": 0.004}, "kinds": ["fold", "grazing"], "max_steps": 10,
                  "frequency_step": 1.0, "clearance_num": 2, "transient_periods": 50, "strobes": 64},
    },
}  # fmt: skip


@pytest.fixture
def dataset(small_bifurcation: xr.Dataset) -> xr.Dataset:
    return small_bifurcation


def test_output_contract(dataset: xr.Dataset) -> None:
    assert dataset.attrs["study_kind"] == "bifurcation"
    for name in ("x1_amplitude", "x2_amplitude", "impulse", "floquet_modulus", "stable", "impacts_per_period", "period_multiplicity"):
        assert dataset[name].dims == ("branch_point",), name
    for name in ("branch", "branch_frequency", "branch_restitution"):
        assert name in dataset.coords and dataset[name].dims == ("branch_point",)
    assert np.issubdtype(dataset["branch"].dtype, np.integer)
    assert dataset["branch_frequency"].attrs["units"] == "Hz" and dataset["x1_amplitude"].attrs["units"] == "m" and dataset["impulse"].attrs["units"] == "N s"
    kind = dataset["special_point_kind"]
    assert kind.dims == ("special_point",) and kind.attrs["flag_meanings"] == "fold period_doubling neimark_sacker grazing"
    assert list(kind.attrs["flag_values"]) == [0, 1, 2, 3]
    assert dataset["special_point_frequency"].attrs["units"] == "Hz" and "special_point_restitution" in dataset.coords
    assert dataset["special_point_multiplier_real"].dims == ("special_point", "multiplier")
    assert dataset["brute_x1"].dims == ("restitution", "sweep", "frequency", "strobe")
    assert dataset["brute_impact_velocity"].dims[:3] == ("restitution", "sweep", "frequency")
    assert list(dataset["sweep"].values) == ["up", "down"] and dataset["frequency"].attrs["units"] == "Hz"
    assert dataset["brute_regime"].dtype == np.int8 and "one_impact" in dataset["brute_regime"].attrs["flag_meanings"]
    assert dataset["chart_regime"].dims == ("sweep", "map_clearance", "map_frequency")
    assert {"chart_curve", "chart_kind", "chart_frequency", "chart_clearance"} <= set(dataset.coords)
    assert dataset["chart_clearance"].attrs["units"] == "m"
    for name in dataset.variables:
        if name not in ("sweep", "special_point_note"):
            assert "long_name" in dataset[name].attrs, name


def test_one_impact_branch_is_the_closed_form(dataset: xr.Dataset) -> None:
    one = dataset.where((dataset["impacts_per_period"] == 1) & (dataset["period_multiplicity"] == 1), drop=True)
    assert one.sizes["branch_point"] > 50
    f = one["branch_frequency"].values
    plus, minus = (orbit.impulse for orbit in closed_form_orbits(diagram_problem(parse_scene(SMALL), 0.8), f))
    impulse = one["impulse"].values
    closest = np.where(np.abs(plus - impulse) < np.abs(minus - impulse), plus, minus)
    assert np.nanmax(np.abs(impulse - closest) / np.nanmax(plus)) < 1e-8


def test_located_neimark_sacker_point_has_a_pair_on_the_unit_circle(dataset: xr.Dataset) -> None:
    ns = dataset.where(dataset["special_point_kind"] == 2, drop=True)
    assert ns.sizes["special_point"] >= 1  # R = 0.8 loses the one-impact orbit near 23.39 Hz
    mu = ns["special_point_multiplier_real"].values + 1j * ns["special_point_multiplier_imag"].values
    for row in mu:
        pair = row[np.abs(row.imag) > 1e-9]
        assert np.min(np.abs(np.abs(pair) - 1.0)) < 1e-6
    assert np.min(np.abs(ns["special_point_frequency"].values - 23.386)) < 0.01


def test_brute_force_settles_on_the_stable_branch(dataset: xr.Dataset) -> None:
    stable = dataset.where((dataset["impacts_per_period"] == 1) & (dataset["period_multiplicity"] == 1) & (dataset["stable"] == 1), drop=True)
    f_branch = stable["branch_frequency"].values
    checked = 0
    for direction in dataset["sweep"].values:
        brute = dataset.isel(restitution=0).sel(sweep=direction)
        for f in brute["frequency"].values:
            point = brute.sel(frequency=f)
            if int(point["brute_regime"]) != 1:
                continue
            near = np.flatnonzero(np.abs(f_branch - f) < 0.02)
            if near.size == 0:
                continue
            velocity = float(np.nanmax(point["brute_impact_velocity"].values))
            branch = stable["impact_velocity"].values[near, 0]
            assert np.min(np.abs(branch - velocity)) < 2e-2 * velocity
            checked += 1
    assert checked >= 5


@pytest.mark.slow
@pytest.mark.timeout(900)  # 174 s alone with 2 workers on the quiet machine; the slow tier runs another test beside it
def test_the_shipped_study_runs(tmp_path) -> None:
    from vibroimpact.scene import find_scene, load_scene
    from vibroimpact.runs.store import StudyStore, store_fingerprint

    scene = load_scene(find_scene("bifurcation"))
    store = StudyStore(tmp_path / "bifurcation.zarr", store_fingerprint(scene.text))  # its cases kept as they finish
    data = run_study(scene, progress=None, jobs=2, store=store)
    assert store.case_count() > 0
    kinds = data["special_point_kind"].values
    assert {0, 1, 2, 3} <= set(kinds.tolist())
    assert set(data["restitution"].values) == {0.2, 0.8} and data.sizes["frequency"] == 601
    lost = data.where((data["special_point_kind"] == 2) & (data["special_point_restitution"] == 0.2), drop=True)["special_point_frequency"].values  # exact: parsed inputs
    assert np.min(np.abs(lost - 21.205)) < 1e-3 and np.min(np.abs(lost - 39.026)) < 1e-3
