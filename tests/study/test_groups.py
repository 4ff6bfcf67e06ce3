"""A dataset splits into netCDF groups, the closed forms on every frequency and the simulated solutions on the
frequencies they were simulated at (issue 21, item 7), and joins back."""

from __future__ import annotations

from pathlib import Path

import netCDF4
import pytest
import xarray as xr

from vibroimpact.runs.run import SIMULATED_GROUP, join_groups, read_dataset, run_study, split_groups, write_dataset
from vibroimpact.scene import load_scene

from tests.golden.golden import SCENES


@pytest.fixture(scope="module")
def relative_stop() -> xr.Dataset:
    """The golden relative-stop scene (2 s): linear and pgf on a 0.1 Hz grid, momentary and exact at 11 frequencies."""
    return run_study(load_scene(SCENES / "relative_stop.yaml"), progress=None)


@pytest.mark.parametrize("solutions", [None, ["exact"]], ids=["closed_forms_and_engines", "engine_only"])
def test_joining_the_groups_gives_the_dataset_back(relative_stop: xr.Dataset, solutions: list[str] | None, tmp_path: Path) -> None:
    """join(split(ds)) is ds, types included (a flag is not_applicable where it was not computed, not NaN), and so is
    the file read back; a dataset of simulated solutions only keeps the root's frequency axis."""
    dataset = relative_stop if solutions is None else relative_stop.sel(solution=solutions)
    groups = split_groups(dataset)
    assert list(groups) == ["/", f"/{SIMULATED_GROUP}"]
    joined = join_groups(groups)
    xr.testing.assert_identical(joined, dataset)
    assert {name: joined[name].dtype for name in dataset.variables} == {name: dataset[name].dtype for name in dataset.variables}
    back = read_dataset(write_dataset(dataset, tmp_path / "run.nc"))
    assert back.attrs.pop("history")
    xr.testing.assert_identical(back, dataset)


def test_a_dataset_without_simulation_has_no_group(tmp_path: Path) -> None:
    """Closed forms only: one group, as it is, and no attribute pointing to a group."""
    dataset = run_study(load_scene(SCENES / "closed_form_map.yaml"), progress=None)
    assert list(split_groups(dataset)) == ["/"]
    path = write_dataset(dataset, tmp_path / "map.nc")
    with netCDF4.Dataset(path) as file:
        assert not file.groups and "simulated_solutions_group" not in file.ncattrs()
    back = read_dataset(path)
    assert back.attrs.pop("history")
    xr.testing.assert_identical(back, dataset)
