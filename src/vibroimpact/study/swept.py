"""Swept-sine studies: the compliant model run through whole sweeps (the paper's Simulink runs, section 5).

The steady-state solutions are not repeated along ``sweep``; the swept runs' estimates on the frequency grid are the
``swept_<quantity>`` variables (sweep, frequency), their running estimates ``running_<quantity>`` (sweep,
elapsed_time) and their costs ``sweep_<statistic>`` (sweep).
"""

from __future__ import annotations

from dataclasses import asdict

import numpy as np
import xarray as xr

from vibroimpact.analysis.regime import Regime
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, GRID_DIMS, MOTION_QUANTITIES, Scene
from vibroimpact.scene.variables import SWEEP_STAT_ATTRIBUTES, SWEEP_TIME_ATTRIBUTES, quantity_attributes, running_attributes, swept_attributes
from vibroimpact.study.cost_model import Costs, EnginePart, Estimate, grid_estimate
from vibroimpact.study.grid import Progress, StudyGrid, finish_dataset, grid_coordinates, no_one_impact_orbit, solve_each, steady_variable
from vibroimpact.study.runner import Runner
from vibroimpact.simulation.swept import SWEEP_QUANTITIES
from vibroimpact.study.swept_cases import SWEEP_STATS, SweepCase

__all__ = ["SweptStudy", "swept_values", "REPORT_FIGURES"]

#: Figures of a swept-sine study's report page.
REPORT_FIGURES = 4


class SweptStudy:
    """Swept-sine tests of the compliant model beside the steady-state closed forms; dimension ``sweep``."""

    name = "swept"

    def run(self, scene: Scene, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """Every solution of ``scene`` over its grid (see :func:`vibroimpact.study.run.run_study`)."""
        grid = StudyGrid.of(scene)
        running: dict[str, np.ndarray] = {}
        sweep_axes: dict[str, np.ndarray] = {}

        def simulate(name: str) -> dict[str, np.ndarray]:
            values, sweep_running, axes = swept_values(scene, grid.full, runner)
            running.update(sweep_running)
            sweep_axes.update(axes)
            return values

        per_solution = solve_each(scene, grid, simulate, progress)
        # a swept-sine test depends on its direction, the steady-state solutions do not: they are not repeated along
        # ``sweep``; the swept runs' estimates on the frequency grid are the ``swept_*`` variables (sweep, frequency)
        steady_solutions = [name for name in scene.solutions if name not in ENGINE_SOLUTIONS]
        steady_dims = tuple(d for d in GRID_DIMS if d != "sweep")
        coords = grid_coordinates(scene, grid, steady_solutions)
        coords["sweep"] = np.array(grid.directions, dtype=object)
        data_vars = {}
        for quantity in scene.quantities:
            attrs = quantity_attributes(quantity)
            stacked = steady_variable(quantity, scene, grid, per_solution, steady_solutions)
            if stacked is not None:
                data_vars[quantity] = xr.Variable(("solution", *steady_dims), stacked[:, :, :, :, 0, :], attrs)
            for name, values in zip(scene.solutions, per_solution):
                if name not in steady_solutions and quantity not in MOTION_QUANTITIES:
                    data_vars[f"swept_{quantity}"] = xr.Variable(GRID_DIMS, values[quantity], swept_attributes(name, attrs))
        for name, values in running.items():
            if name.startswith("sweep_"):  # one value per sweep run
                data_vars[name] = xr.Variable(GRID_DIMS[:-1], values, SWEEP_STAT_ATTRIBUTES[name])
            else:
                data_vars[name] = xr.Variable((*GRID_DIMS[:-1], "elapsed_time"), values, running_attributes(name))
        dataset = xr.Dataset(data_vars, coords=coords)
        if running:
            dataset = dataset.assign_coords(
                elapsed_time=("elapsed_time", sweep_axes["time"], dict(SWEEP_TIME_ATTRIBUTES["elapsed_time"])),
                instantaneous_frequency=(("sweep", "elapsed_time"), sweep_axes["instantaneous_frequency"], dict(SWEEP_TIME_ATTRIBUTES["instantaneous_frequency"])),
            )
        # a swept-sine study keeps its sweep dimension even with one direction
        return finish_dataset(dataset, scene, coords, self.simulation_attributes(scene), keep=("sweep",))

    @staticmethod
    def simulation_attributes(scene: Scene) -> dict[str, object]:
        """What the dataset records of the sweep and of the compliant engine's tolerances."""
        assert scene.swept_sine is not None
        attrs: dict[str, object] = {}
        if scene.simulation is not None:
            for key, value in asdict(scene.swept_sine).items():
                attrs[f"swept_sine_{key}"] = np.array(value, dtype=str) if key == "directions" else value
            for key in ("rtol", "atol", "max_step"):
                attrs[f"simulation_engine_{key}"] = getattr(scene.simulation.engine, key)
        return attrs

    def estimate(self, scene: Scene, jobs: int, costs: Costs) -> Estimate:
        """Seconds per simulated second of the compliant engine at its tolerance times the sweeps' durations, on the
        calibration machine; the memory holds one sweep's samples per worker."""
        assert scene.swept_sine is not None
        s = scene.swept_sine
        bumpers = scene.bumper_frequency.size if scene.bumper_frequency is not None else 1
        directions = max(1, len(scene.sweep_directions))

        def engine_part(name: str, engine: str) -> EnginePart:
            assert scene.simulation is not None
            duration = abs(s.stop_frequency - s.start_frequency) / s.rate
            one = costs.per_sweep_second_cost(engine, scene.simulation.engine.rtol) * duration
            runs = scene.restitution.size * scene.clearance.size * bumpers * directions
            return one * runs, f"{runs} sweeps of {duration:g} s", one

        samples = abs(s.stop_frequency - s.start_frequency) / s.rate * s.sample_rate
        return grid_estimate(scene, jobs, costs, engine_part, REPORT_FIGURES, samples)


def swept_values(scene: Scene, shape: tuple[int, ...], runner: Runner) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Swept-sine tests of the compliant model: estimates on the frequency grid, running estimates against time, and
    the time axes (``time``, ``instantaneous_frequency`` per direction)."""
    assert scene.swept_sine is not None and scene.bumper_frequency is not None and scene.simulation is not None
    losses = scene.loss_factors()
    frequencies = tuple(float(f) for f in scene.all_frequencies)
    cases, places = [], []
    for i in range(scene.restitution.size):
        for j, clearance in enumerate(scene.clearance):
            for k, bumper in enumerate(scene.bumper_frequency):
                for d, direction in enumerate(scene.swept_sine.directions):
                    cases.append(SweepCase(scene.system, scene.amplitude, KelvinVoigtBumper(float(clearance), float(bumper), float(losses[i])), scene.swept_sine, direction, scene.simulation.engine, frequencies))
                    places.append((i, j, k, d))
    results = runner.map(cases)
    times = results[0]["time"]
    values = {name: np.full(shape, np.nan) for name in SWEEP_QUANTITIES}
    running = {f"running_{name}": np.full((*shape[:-1], times.size), np.nan) for name in SWEEP_QUANTITIES}
    stats = {name: np.full(shape[:-1], np.nan) for name in SWEEP_STATS}
    instantaneous = np.full((shape[3], times.size), np.nan)
    for (i, j, k, d), result in zip(places, results):
        for name in SWEEP_QUANTITIES:
            values[name][i, j, k, d] = result[name]
            running[f"running_{name}"][i, j, k, d] = result[f"running_{name}"]
        for name in stats:
            stats[name][i, j, k, d] = result[name]
        instantaneous[d] = result["instantaneous_frequency"]
    impacts = values["impacts_per_period"]
    regime = np.full(shape, Regime.NOT_COMPUTED, dtype=np.int8)
    regime[impacts == 0.0] = Regime.LINEAR
    regime[impacts > 0.0] = Regime.SWEPT_CONTACT
    regime[np.broadcast_to(stats["failed"][..., None] == 1.0, shape)] = Regime.FAILED
    values |= {
        "phase": np.full(shape, np.nan),
        "regime": regime,
        **no_one_impact_orbit(shape),
        "converged": np.full(shape, -1, dtype=np.int8),
        "wall_time": np.broadcast_to(stats["wall_time"][..., None], shape),
        **{name: np.full(shape, np.nan) for name in MOTION_QUANTITIES},  # a sweep is a transient: no attractor to classify
    }
    running = {name: value for name, value in running.items() if name.removeprefix("running_") in scene.quantities}
    for name, value in stats.items():
        running[f"sweep_{name}"] = value  # one value per sweep: the run's cost
    return {q: values[q] for q in scene.quantities}, running, {"time": times, "instantaneous_frequency": instantaneous}
