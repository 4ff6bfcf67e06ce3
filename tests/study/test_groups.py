"""The written file keeps each solution on the frequencies it was computed at: the closed forms in the root group on
every frequency, the simulated solutions in the group ``simulated`` on the frequencies they were simulated at, so
that the naive plot of a simulated solution draws its curve (issue 21, item 7)."""

from __future__ import annotations

from pathlib import Path

import netCDF4
import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from vibroimpact.runs.run import SIMULATED_GROUP, absent_value, join_groups, read_dataset, run_study, split_groups, write_dataset
from vibroimpact.scene import load_scene

from tests.golden.golden import SCENES


@pytest.fixture(scope="module")
def relative_stop() -> xr.Dataset:
    """The golden relative-stop scene (2 s): linear and pgf on a 0.1 Hz grid, momentary and exact at 11 frequencies."""
    return run_study(load_scene(SCENES / "relative_stop.yaml"), progress=None)


def drawn(data: xr.DataArray) -> tuple[np.ndarray, np.ndarray]:
    """The x and y of the line ``data.plot()`` draws."""
    (line,) = data.plot(ax=Figure().add_subplot())
    return np.asarray(line.get_xdata(), dtype=float), np.asarray(line.get_ydata(), dtype=float)


def test_the_naive_plot_of_a_simulated_solution_draws_its_curve(relative_stop: xr.Dataset, tmp_path: Path) -> None:
    """In the group, with its labels as index, ``x1_amplitude.sel(solution_label=engine).plot()`` draws a finite value
    at every simulated frequency; the same plot of the one in-memory dataset draws isolated points between NaNs (the
    trap). In the file ``solution`` is an index dimension and its labels are ``solution_label`` (CF 1.8 6.1.1)."""
    path = write_dataset(relative_stop, tmp_path / "relative_stop.nc")
    simulation = np.atleast_1d(relative_stop.attrs["simulation_frequency_Hz"])
    with xr.open_dataset(path, group=SIMULATED_GROUP) as opened, xr.open_dataset(path) as root:
        assert "solution" not in opened.variables and "solution" not in root.variables
        simulated = opened.set_xindex("solution_label")  # the README's recipe
        assert list(simulated["solution_label"].values) == ["momentary", "exact"] and list(root["solution_label"].values) == ["linear", "pgf"]
        assert root.attrs["simulated_solutions_group"] == SIMULATED_GROUP and SIMULATED_GROUP in root.attrs["comment"]
        for engine in ("momentary", "exact"):
            x, y = drawn(simulated["x1_amplitude"].sel(solution_label=engine))
            np.testing.assert_array_equal(x, simulation)
            assert np.isfinite(y).all() and (y > 0.0).all(), engine
        assert root["frequency"].size == relative_stop["frequency"].size > 10 * simulation.size
        # no placeholder: every variable holds a value over its group's solutions, but the rotation number, a result
        # of the simulations that is NaN wherever the motion is not quasi-periodic (nowhere here)
        for group in (root, simulated):
            empty = [str(name) for name, variable in group.data_vars.items() if not bool((variable.notnull() if variable.dtype.kind == "f" else variable != absent_value(variable)).any())]
            assert empty == ([] if group is root else ["rotation_number"])
        assert "converged" not in root and "lyapunov_exponent" not in root and "stable" not in simulated and "phase" not in simulated
        assert simulated["x1_amplitude"].attrs == root["x1_amplitude"].attrs == relative_stop["x1_amplitude"].attrs
    _, trap = drawn(relative_stop["x1_amplitude"].sel(solution="exact"))
    assert np.isnan(trap).sum() > 10 * np.isfinite(trap).sum()


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
