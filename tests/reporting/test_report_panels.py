"""Every panel of the report shows the data of its solution: each finite value of the dataset is a visible point.

Simulations leave NaN wherever they were not run (90 % of the points of the made-up datasets, 95 % in the shipped
studies); a plain line through such data draws nothing, which is how simulated curves once vanished.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from vibroimpact.kinds.stepped.page import peak_acceleration_figure
from vibroimpact.kinds.stepped.responses import response_figure, simulation_figure
from vibroimpact.reporting.style import QUANTITIES
from vibroimpact.scene.schema import ENGINE_SOLUTIONS
from vibroimpact.kinds.swept.page import sweep_figures, swept_sine_run

from tests.reporting.test_report_support import shown_points, steady_dataset, swept_dataset


def _expected(values: np.ndarray, f: np.ndarray, log: bool, scale: float = 1.0) -> set[tuple[float, float]]:
    """The points a panel must show: every finite value (positive on a log axis) in the page's units (``scale``)."""
    keep = np.isfinite(values) & ((values > 0.0) if log else True)
    return set(zip(np.round(f[keep], 9).tolist(), np.round(scale * values[keep], 12).tolist()))


def _panel_solution(title: str) -> str:
    """The solution a response panel is titled with ("'name': ...")."""
    return title.split("'")[1]


@pytest.mark.parametrize("quantity", ["x1_amplitude", "x2_amplitude", "force_amplitude", "suspension_force_amplitude", "impulse"])
def test_each_solution_panel_shows_every_value_of_its_solution(quantity: str) -> None:
    ds = steady_dataset()
    drawn = response_figure(ds, quantity, quantity)
    assert drawn is not None
    f = ds["frequency"].values
    solutions = {_panel_solution(ax.get_title()) for ax in drawn.figure.axes}
    assert solutions == {"pgf", "pgf_paper", *ENGINE_SOLUTIONS}
    for ax in drawn.figure.axes:
        solution = _panel_solution(ax.get_title())
        log = ax.get_yscale() == "log"
        expected = set().union(*(_expected(ds[quantity].sel(solution=solution, restitution=r).values, f, log, QUANTITIES[quantity].scale) for r in ds["restitution"].values))
        shown = shown_points(ax, solution)
        assert expected, solution
        missing = expected - shown
        assert not missing, f"{solution}: {len(missing)} of {len(expected)} values not visible"
    plt.close(drawn.figure)


@pytest.mark.parametrize("quantity", ["x1_amplitude", "impulse"])
def test_each_restitution_panel_shows_every_simulated_value(quantity: str) -> None:
    ds = steady_dataset()
    drawn = simulation_figure(ds, quantity, list(ENGINE_SOLUTIONS), quantity)
    assert drawn is not None
    f = ds["frequency"].values
    assert len(drawn.figure.axes) == ds.sizes["restitution"]
    for ax, r in zip(drawn.figure.axes, ds["restitution"].values):
        log = ax.get_yscale() == "log"
        for solution in (*ENGINE_SOLUTIONS, "pgf"):
            expected = _expected(ds[quantity].sel(solution=solution, restitution=r).values, f, log, QUANTITIES[quantity].scale)
            assert expected and not expected - shown_points(ax, solution), (solution, r)
    plt.close(drawn.figure)


def test_peak_contact_panels_show_the_simulation_and_the_estimate() -> None:
    ds = steady_dataset()
    drawn = peak_acceleration_figure(ds, "peak_acceleration")
    assert drawn is not None
    f = ds["frequency"].values
    for ax, quantity in zip(drawn.figure.axes, ("peak_acceleration", "peak_contact_force")):
        for solution in ("compliant", "pgf"):
            expected = set().union(*(_expected(ds[quantity].sel(solution=solution, restitution=r).values, f, False) for r in ds["restitution"].values))
            assert expected and not expected - shown_points(ax, solution), (quantity, solution)
    plt.close(drawn.figure)


def test_sweep_panels_show_both_sweeps_and_the_steady_states() -> None:
    ds = swept_dataset()
    figures = {drawn.name: drawn for drawn in sweep_figures(ds, swept_sine_run(ds))}
    assert {"sweep_displacements", "sweep_force_impulse", "sweep_regime", "sweep_time"} <= set(figures)
    f = ds["frequency"].values
    panels = {"sweep_displacements": ("x1_amplitude", "x2_amplitude"), "sweep_force_impulse": ("force_amplitude", "impulse", "impacts_per_period")}
    for name, quantities in panels.items():
        axes = figures[name].figure.axes
        assert len(axes) == len(quantities)
        for ax, quantity in zip(axes, quantities):
            log = ax.get_yscale() == "log"
            scale = QUANTITIES[quantity].scale
            swept = set().union(*(_expected(ds[f"swept_{quantity}"].sel(sweep=d).values, f, log, scale) for d in ds["sweep"].values))
            assert swept and not swept - shown_points(ax, "compliant"), (name, quantity)
            if quantity in ds:
                steady = _expected(ds[quantity].sel(solution="pgf").values, f, log, scale)
                assert steady and not steady - shown_points(ax, "pgf"), (name, quantity)
    for drawn in figures.values():
        plt.close(drawn.figure)


def test_a_lone_value_between_gaps_still_shows() -> None:
    """A closed-form value with no finite neighbour (a line draws nothing there) gets a dot."""
    ds = steady_dataset(engines=(), restitution=(0.2,), step=0.5)
    values = ds["x1_amplitude"].values.copy()
    pgf = list(ds["solution"].values).index("pgf")
    values[pgf, 1::2] = np.nan  # every other value missing: no two neighbours are finite
    lonely = ds.assign(x1_amplitude=xr.DataArray(values, dims=ds["x1_amplitude"].dims))
    drawn = response_figure(lonely, "x1_amplitude", "x1")
    assert drawn is not None
    ax = next(a for a in drawn.figure.axes if _panel_solution(a.get_title()) == "pgf")
    expected = _expected(values[pgf], ds["frequency"].values, True, 1e3)  # drawn in mm
    assert not expected - shown_points(ax, "pgf")
    plt.close(drawn.figure)
