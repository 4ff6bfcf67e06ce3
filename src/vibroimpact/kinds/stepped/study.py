"""Stepped studies: steady states (closed forms and time-domain engines) at each point of the grid (the grid, its
closed forms, its dataset and its estimate: :mod:`vibroimpact.grids`, shared with the swept kind)."""

from __future__ import annotations

from dataclasses import asdict

import numpy as np
import xarray as xr

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.analysis.stability import floquet_multipliers
from vibroimpact.engines.registry import BUMPER, engine_spec
from vibroimpact.kinds.stepped.cases import general_simulated_values
from vibroimpact.grids.closed_forms import stop_clearances
from vibroimpact.grids.estimate import EnginePart, closed_form_scale, grid_estimate
from vibroimpact.grids.grid import StudyGrid, describe_stops, finish_dataset, general_quantity_attributes, grid_coordinates, grid_engines, solve_each
from vibroimpact.kinds.stepped.blocks import plan_blocks, run_grid
from vibroimpact.scene.subset import subset_axes, subset_share, subset_text
from vibroimpact.runs.cluster import Progress
from vibroimpact.runs.estimate import Costs, Estimate, engine_scale
from vibroimpact.runs.runner import Runner
from vibroimpact.model.layout import stop_descriptions
from vibroimpact.reporting.solutions import solution_method
from vibroimpact.scene.schema import Scene, GRID_DIMS, STOP_QUANTITIES, ENGINE_SOLUTIONS
from vibroimpact.simulation.settings import SWEEP_STARTS

__all__ = ["general_orbit_outlook", "UNKNOWN_WANDERING", "general_block", "general_coordinates", "SteppedStudy", "expected_periods", "SETTLING_PERIODS", "SHOOTING_PERIODS", "ESTIMATE_POINTS"]


# --------------------------------------------------------------------------------------------------------------------
# What ``--estimate`` assumes of a stepped scene's layout (any structure, load and stops).
# --------------------------------------------------------------------------------------------------------------------

#: Share of impacting points assumed never to settle where no closed form says which orbits are stable.
UNKNOWN_WANDERING = 0.25


def general_orbit_outlook(scene: Scene, frequencies: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """(fits, admissible, stable, wandering share) over (restitution, clearance, frequency) for a general scene.

    ``fits``: the linear motion stays clear of every stop; ``admissible``/``stable``: a closed-form orbit exists, stays
    off the stops, is stable (all False without a closed form); the share of impacting points without a closed form
    assumed never to settle (0 where a closed form applies).
    """
    problem = scene.layout.problem(scene.amplitude, float(frequencies[0]), float(scene.settings.restitution[0]), float(scene.settings.clearance[0]))
    omega = 2.0 * np.pi * frequencies[None, None, :]
    clearances = stop_clearances(scene)[None, :, None, :]  # (1, nc, 1, K)
    fits = np.broadcast_to(linear_amplitudes(problem, omega=omega).fits(clearances), (scene.settings.restitution.size, scene.settings.clearance.size, frequencies.size))
    shape = fits.shape
    if closed_form_refusal(problem) is not None:
        return fits, np.zeros(shape, dtype=bool), np.zeros(shape, dtype=bool), UNKNOWN_WANDERING
    orbit = solve_impact_orbit(problem, omega=omega, clearance=scene.settings.clearance[None, :, None], restitution=scene.settings.restitution[:, None, None])
    admissible = np.broadcast_to(orbit.admissible(), shape)
    stable = np.zeros(shape, dtype=bool)
    if admissible.any():
        modulus = np.max(np.abs(floquet_multipliers(orbit)), axis=-1)
        stable = admissible & (modulus < 1.0)
    return fits, admissible, stable, 0.0


# --------------------------------------------------------------------------------------------------------------------
# The values of a stepped study, whichever way its scene writes the system (the paper's named form is the layout
# of a two-mass chain, one upper stop on x2 and a force on x1, and takes this path too): any structure, load and stops.
# --------------------------------------------------------------------------------------------------------------------

_PER_COORDINATE = {"_amplitude": "x1_amplitude", "_rms": "x1_rms"}


def general_block(scene: Scene, runner: Runner) -> xr.Dataset:
    """Every solution of ``scene`` (or of a block of one) over its unsqueezed grid, without coordinates or metadata;
    per-stop quantities have the dimension ``stop`` where the scene has several stops."""
    grid = StudyGrid.of(scene)
    per_solution = solve_each(scene, grid, lambda name: general_simulated_values(scene, name, grid.full, runner), None)
    count = len(scene.layout.stops)
    data_vars = {}
    for quantity in scene.settings.quantities:
        attrs = general_quantity_attributes(quantity, scene)
        if quantity in STOP_QUANTITIES:
            stacked = np.stack([np.broadcast_to(values[quantity], (count, *grid.full)) for values in per_solution])
            if count > 1:
                data_vars[quantity] = xr.Variable(("solution", "stop", *GRID_DIMS), stacked, attrs)
            else:
                data_vars[quantity] = xr.Variable(("solution", *GRID_DIMS), stacked[:, 0], attrs)
        else:
            stacked = np.stack([np.broadcast_to(values[quantity], grid.full) for values in per_solution])
            data_vars[quantity] = xr.Variable(("solution", *GRID_DIMS), stacked, attrs)
    return xr.Dataset(data_vars)


def general_coordinates(scene: Scene, grid: StudyGrid) -> dict[str, object]:
    """Coordinates of a stepped study's dataset before squeezing: those of :func:`grid_coordinates`, and ``stop``
    with ``stop_description`` where the scene has several stops and writes a per-stop quantity."""
    coords = grid_coordinates(scene, grid, list(scene.settings.solutions))
    count = len(scene.layout.stops)
    if count > 1 and any(q in STOP_QUANTITIES for q in scene.settings.quantities):
        coords["stop"] = np.arange(count, dtype=np.int32)  # CF 2.2 (netCDF classic types): no int64
        coords["stop_description"] = ("stop", np.array(stop_descriptions(scene.layout.stops, scene.coordinates, scene.settings.restitution, scene.settings.clearance, scene.settings.bumper_frequency), dtype=object))
    return coords


#: Periods of a transient that settles on a stable orbit (two convergence chunks), before the measurement.
SETTLING_PERIODS = 40
#: Periods a ``shooting`` start integrates before measuring a stable orbit: 1-2 map evaluations and the 3-period check
#: of an integrator (measured on the restitution study: 1-4).
SHOOTING_PERIODS = 5
#: Largest number of simulated points whose closed form is solved for the estimate (a larger grid is subsampled).
ESTIMATE_POINTS = 20_000


class SteppedStudy:
    """Steady states over (restitution, clearance, bumper, frequency): dimension ``solution`` for every solution."""

    name = "stepped"
    engines = staticmethod(grid_engines)

    def run(self, scene: Scene, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """Every solution of ``scene`` over its grid (see :func:`vibroimpact.runs.run.run_study`), solved block by
        block (:mod:`vibroimpact.kinds.stepped.blocks`) by :func:`~vibroimpact.kinds.stepped.study.general_block`, whichever
        way the scene writes its system; the variables are read lazily from the runner's store."""
        say = progress or (lambda _message: None)
        grid = StudyGrid.of(scene)
        solutions = list(scene.settings.solutions)
        coords = general_coordinates(scene, grid)
        raw = run_grid(scene, runner, general_block, {"solution": len(solutions), "stop": len(scene.layout.stops)})
        dataset = describe_stops(raw.assign_coords(coords))
        say(f"{', '.join(solutions)}: done")
        finished = finish_dataset(dataset, scene, coords, self.simulation_attributes(scene))
        from vibroimpact.kinds.stepped.operating import unreached_text  # a page's module (matplotlib): not on the workers

        unreached = unreached_text(finished)  # a clearance typed in mm runs silently else: run-study says it in one line
        if unreached:
            finished.attrs["run_warnings"] = [unreached]
        return finished

    @staticmethod
    def simulation_attributes(scene: Scene) -> dict[str, object]:
        """What the dataset records of the time-domain solutions' settings and methods."""
        attrs: dict[str, object] = {}
        if scene.settings.simulation is not None:
            attrs["simulation_frequency_Hz"] = scene.settings.simulation.frequency
            attrs["simulation_start"] = scene.settings.simulation.start
            for key, value in asdict(scene.settings.simulation.engine).items():
                attrs[f"simulation_engine_{key}"] = value
            for key, value in asdict(scene.settings.simulation.steady).items():
                attrs[f"simulation_steady_{key}"] = value
            for name in ("exact", "momentary", "compliant"):  # recorded whether the scene runs them or not
                attrs[f"method_{name}"] = solution_method(name)
            for name in scene.settings.solutions:  # any other engine the scene runs
                if name in ENGINE_SOLUTIONS and f"method_{name}" not in attrs:
                    attrs[f"method_{name}"] = solution_method(name)
            for name, kept in scene.settings.simulation.subset.items():
                attrs[f"simulation_subset_{name}"] = subset_text(kept)
        return attrs

    def estimate(self, scene: Scene, jobs: int, costs: Costs) -> Estimate:
        """Seconds per simulated period of each engine at its tolerance times the periods each point is predicted to
        integrate (:func:`expected_periods`), on the calibration machine."""
        bumpers = scene.settings.bumper_frequency.size if scene.settings.bumper_frequency is not None else 1
        # the same for every engine: solved once (the closed form over up to ESTIMATE_POINTS points)
        periods, scale = expected_periods(scene) if scene.settings.simulation is not None else (np.zeros(0), 1.0)

        def engine_part(name: str, engine: str) -> EnginePart:
            assert scene.settings.simulation is not None
            capabilities = engine_spec(name).capabilities
            copies = bumpers if capabilities.contact == BUMPER else 1  # a bumper engine runs once per bumper
            steady = scene.settings.simulation.steady
            # where the motion may never settle, an engine without exact Jacobians also runs a perturbed copy of its
            # Lyapunov run
            wandering = np.count_nonzero(periods >= steady.max_periods + steady.lyapunov_periods) if not capabilities.exact_jacobians else 0
            share = subset_share(scene.settings.simulation.subset, name, subset_axes(scene))
            total_periods = (float(periods.sum()) + wandering * steady.lyapunov_periods) * scale * copies * share
            seconds = costs.per_period_cost(engine, scene.settings.simulation.engine.rtol) * engine_scale(scene.layout) * total_periods
            integrated = int(np.count_nonzero(periods) * scale) * copies
            integrated = round(integrated * share)
            points = f"{round(scene.settings.restitution.size * scene.settings.clearance.size * scene.settings.simulation.frequency.size * copies * share)} points, ~{integrated} integrated, ~{total_periods:.0f} periods"
            serial = 0.0
            if scene.settings.simulation.start in SWEEP_STARTS:  # one serial chain per (R, Delta, bumper)
                serial = seconds / (scene.settings.restitution.size * scene.settings.clearance.size * copies)
            return seconds, points, serial

        return grid_estimate(
            scene, jobs, costs, engine_part, report_figures(scene), closed_form_scale=lambda name: closed_form_scale(scene, name),
            blocks=lambda workers: plan_blocks(scene, workers).count,
        )  # fmt: skip


def report_figures(scene: Scene) -> int:
    """Figures of the study's report page."""
    per_clearance = 12 if any(s in ENGINE_SOLUTIONS for s in scene.settings.solutions) else 7
    return 1 + per_clearance * scene.settings.clearance.size + (2 if len(scene.settings.swept) > 1 else 0)


def expected_periods(scene: Scene) -> tuple[np.ndarray, float]:
    """Periods each simulated (restitution, clearance, frequency) point is predicted to integrate, on the grid or on
    an evenly subsampled frequency grid, and the factor that scales its sum to the whole grid.

    As :func:`vibroimpact.simulation.steady.steady_state` and :func:`vibroimpact.kinds.stepped.cases.run_case` do: ``linear`` and stepped
    sweeps answer a point whose linear motion fits without integrating; ``pgf`` also needs no admissible one-impact
    orbit there; a stable orbit settles in a short transient; elsewhere the motion may never settle (``max_periods``
    plus the irregular measurement). From ``rest`` every point integrates, and the lightly damped transient of the
    linear modes (damping ratios ~1e-3) outlasts ``max_periods``.
    """
    assert scene.settings.simulation is not None
    sim = scene.settings.simulation
    per_line = max(1, ESTIMATE_POINTS // (scene.settings.restitution.size * scene.settings.clearance.size))
    frequencies = sim.frequency if sim.frequency.size <= per_line else sim.frequency[np.linspace(0, sim.frequency.size - 1, per_line).astype(int)]
    scale = sim.frequency.size / frequencies.size
    steady = sim.steady
    wander = steady.max_periods + steady.lyapunov_periods + steady.irregular_measure_periods
    shape = (scene.settings.restitution.size, scene.settings.clearance.size, frequencies.size)
    if sim.start == "rest":
        return np.full(shape, float(wander)), scale
    fits, admissible, stable, wandering = general_orbit_outlook(scene, frequencies)
    settle = (SHOOTING_PERIODS if sim.start == "shooting" else SETTLING_PERIODS) + steady.measure_periods
    if sim.start in SWEEP_STARTS:
        # a chain: a fitting point is answered linear unless the point before it impacted (then it integrates from
        # there, and keeps impacting where a one-impact orbit coexists with the linear motion)
        order = range(frequencies.size) if sim.start == "sweep_up" else range(frequencies.size - 1, -1, -1)
        no_integration = np.zeros(shape, dtype=bool)
        impacting = np.zeros(shape[:2], dtype=bool)
        for k in order:
            no_integration[..., k] = fits[..., k] & ~impacting
            impacting = ~fits[..., k] | (impacting & admissible[..., k])
    else:
        no_integration = fits & ~admissible if sim.start in ("pgf", "shooting") else fits
    unknown = settle + wandering * (wander - settle)  # no closed form: an assumed share never settles
    return np.where(no_integration, 0, np.where(stable, settle, unknown if wandering else wander)).astype(float), scale
