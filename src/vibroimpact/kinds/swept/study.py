"""Swept-sine studies: the compliant model run through whole sweeps (the paper's Simulink runs, section 5), on any
structure, load and stops.

The steady-state solutions are not repeated along ``sweep``; the swept runs' estimates on the frequency grid are the
``swept_<quantity>`` variables (sweep, frequency), their running estimates ``running_<quantity>`` (sweep,
elapsed_time) and their costs ``sweep_<statistic>`` (sweep). Quantities are named as a stepped study of the same
scene names them: the paper's (``x1_amplitude`` ...) for its named form, ``<coordinate>_amplitude`` and
``<coordinate>_rms`` per coordinate of a general scene; per-stop quantities (impulse, peaks) get a dimension ``stop``
where the scene has several stops. The closed forms are the general ones
(:func:`~vibroimpact.grids.closed_forms.general_linear_values`, :func:`~vibroimpact.grids.closed_forms.general_pgf_values`);
``pgf_paper``, the paper's own fitted route, exists for the named form only.
"""

from __future__ import annotations

import sys
import time
from dataclasses import asdict, dataclass, replace

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from vibroimpact.analysis.stability import Regime
from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.grids.closed_forms import general_linear_values, general_pgf_values
from vibroimpact.grids.estimate import EnginePart, closed_form_scale, grid_estimate
from vibroimpact.grids.grid import StudyGrid, describe_stops, finish_dataset, general_quantity_attributes, grid_coordinates, grid_engines
from vibroimpact.model.contact import Stop
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.runs.cluster import Progress
from vibroimpact.runs.estimate import Costs, Estimate, engine_scale
from vibroimpact.runs.runner import ProgressReport, Runner
from vibroimpact.runs.fingerprints import case_key
from vibroimpact.model.layout import LoadSpec, build_stops, stop_descriptions
from vibroimpact.scene.grid import SweptSineSettings
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, GRID_DIMS, MOTION_QUANTITIES, STOP_QUANTITIES, Scene
from vibroimpact.scene.variables import quantity_attributes
from vibroimpact.kinds.swept.variables import SWEEP_STAT_ATTRIBUTES, SWEEP_TIME_ATTRIBUTES, running_attributes, swept_attributes
from vibroimpact.simulation.harmonics import resting_state
from vibroimpact.simulation.swept import SWEEP_STOP_QUANTITIES, sweep_estimates, sweep_quantities, sweep_start_state

__all__ = ["SweepCase", "SWEEP_STATS", "run_sweep_case", "SweptStudy", "swept_values", "closed_form_values", "REPORT_FIGURES"]


# --------------------------------------------------------------------------------------------------------------------
# Swept-sine tests of the compliant model as cases of a study (the paper's Simulink runs, section 5).
# --------------------------------------------------------------------------------------------------------------------

#: Whole-run statistics of a sweep.
SWEEP_STATS = ("wall_time", "steps", "contacts", "rhs_calls", "linear_start", "failed")


@dataclass(frozen=True)
class SweepCase:
    """One swept-sine run of the compliant model and the frequencies and times its estimates are reported at.

    Attributes
    ----------
    system : LinearStructure
        The linear structure: the paper's named system or matrices with named coordinates.
    amplitude : float
        q [N].
    stops : tuple of Stop
        Every stop, each with its :class:`~vibroimpact.model.contact.KelvinVoigtBumper` (clearance Delta [m],
        Omega_b / 2 pi [Hz], xi_b [-]).
    settings : SweptSineSettings
        The sweep (ends, rate, sampling, window).
    direction : str
        ``up`` or ``down``.
    engine_settings : EngineSettings
        IDA tolerances.
    frequencies : tuple of float
        Frequencies at which window-centred estimates are reported [Hz] (NaN outside the sweep or its windows).
    load : LoadSpec or None
        How q is distributed over the coordinates, and a constant force; None: all of q on the first coordinate.
    time_points : int
        Points of the uniform time grid of the running estimates.
    """

    system: LinearStructure
    amplitude: float
    stops: tuple[Stop, ...]
    settings: SweptSineSettings
    direction: str
    engine_settings: EngineSettings
    frequencies: tuple[float, ...]
    load: LoadSpec | None = None
    time_points: int = 2001

    engine = "compliant_sweep"
    #: The registered engine that runs the sweep.
    engine_name = "compliant"
    progress_unit = "s simulated"

    def __post_init__(self) -> None:
        if not self.stops:
            raise ValueError("stops: a swept-sine run needs at least one stop")
        if self.load is not None and self.load.base_motion:
            raise ValueError("load: a swept-sine run drives a force; a swept base motion is not supported")

    @property
    def fields(self) -> tuple[str, ...]:
        """Names of the result's arrays: every estimate, on the frequency grid and running, the time axes and the
        run's statistics."""
        names = sweep_quantities(tuple(self.system.coordinates))
        return names + tuple(f"running_{q}" for q in names) + ("time", "instantaneous_frequency") + SWEEP_STATS

    @property
    def sweep(self) -> SweptSine:
        """The excitation: the settings' sweep in this direction, distributed as the load says."""
        sweep = self.settings.sweep(self.amplitude, self.direction)
        if self.load is None:
            return sweep
        return replace(sweep, weights=self.load.weights, static=self.load.static)

    def problem(self) -> ImpactProblem:
        """The structure, its bumpers and the sweep."""
        return ImpactProblem(self.system, self.stops, self.sweep)

    @property
    def progress_total(self) -> float:
        """The sweep's duration [s]: progress is counted in simulated time."""
        return self.sweep.duration

    def key(self) -> str:
        """A stable hash of everything that determines the result, the package version and its source code."""
        return case_key({"kind": type(self.system).__name__, **asdict(self)})

    def run(self, report: ProgressReport | None = None) -> dict[str, NDArray[np.generic]]:
        """Simulate the sweep and estimate (see :func:`run_sweep_case`)."""
        return run_sweep_case(self, report)


def run_sweep_case(case: SweepCase, report: ProgressReport | None = None) -> dict[str, NDArray[np.generic]]:
    """Run one sweep; estimates on ``case.frequencies`` and on the time grid, and the run's cost.

    The run starts on the linear steady state at its first frequency where the settings ask for it and that motion
    stays clear of every stop, else at rest (the static position, on the stops it would cross). ``report`` receives
    the simulated time reached [s] as the run goes on."""
    problem = case.problem()
    sweep = problem.sweep
    engine = make_engine(case.engine_name, case.engine_settings)
    started = time.perf_counter()
    linear = sweep_start_state(problem) if case.settings.initial_state == "linear" else None
    state = linear if linear is not None else resting_state(problem)
    times = np.linspace(0.0, sweep.duration, case.time_points)
    names = sweep_quantities(tuple(case.system.coordinates))
    count = len(case.stops)
    try:
        record = engine.sweep(problem, case.settings.sample_rate, state, report)
    except (RuntimeError, ValueError, ArithmeticError) as error:
        # a failing run must not cost the others: it stays NaN, flagged, and the study goes on
        print(f"compliant sweep {case.direction}: {case.stops} failed: {error}", file=sys.stderr)
        failed: dict[str, NDArray[np.generic]] = {}
        for name in names:
            per_stop = (count,) if name in SWEEP_STOP_QUANTITIES else ()
            failed[name] = np.full((*per_stop, len(case.frequencies)), np.nan)
            failed[f"running_{name}"] = np.full((*per_stop, times.size), np.nan)
        failed |= {"time": times, "instantaneous_frequency": sweep.frequency(times)}
        failed |= {name: np.array(np.nan) for name in SWEEP_STATS}
        failed["linear_start"] = np.array(float(linear is not None))
        failed["failed"] = np.array(1.0)
        return failed
    wall_time = time.perf_counter() - started
    out = sweep_estimates(record, sweep, case.frequencies, times, case.settings.window_cycles)
    stats = record.trajectory.stats
    out["wall_time"] = np.array(wall_time)
    for name in ("steps", "contacts", "rhs_calls"):
        out[name] = np.array(float(stats.get(name, np.nan)))
    out["linear_start"] = np.array(float(linear is not None))  # the linear start falls back to rest where it would reach a stop
    out["failed"] = np.array(0.0)
    return out

#: Figures of a swept-sine study's report page.
REPORT_FIGURES = 4
#: Quantities of a simulated steady state that the closed forms (the steady-state solutions of a swept-sine study) do
#: not compute: the attractor's classification, whether a simulation converged and its wall time. Not written for
#: them (they would be all NaN, and ``converged`` all -1).
NOT_CLOSED_FORM = (*MOTION_QUANTITIES, "converged", "wall_time")
Values = dict[str, np.ndarray]


class SweptStudy:
    """Swept-sine tests of the compliant model beside the steady-state closed forms; dimension ``sweep``."""

    name = "swept"
    engines = staticmethod(grid_engines)  # a swept sine runs the compliant engine

    def run(self, scene: Scene, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """Every solution of ``scene`` over its grid (see :func:`vibroimpact.runs.run.run_study`)."""
        grid = StudyGrid.of(scene)
        report = progress or (lambda _message: None)
        count = len(scene.layout.stops)
        steady: dict[str, Values] = {}
        swept: Values = {}
        running: Values = {}
        axes: Values = {}
        for i, name in enumerate(scene.settings.solutions, start=1):
            if name in ENGINE_SOLUTIONS:
                swept, running, axes = swept_values(scene, grid.full, runner)
            else:
                steady[name] = closed_form_values(scene, name, grid)
            report(f"[{i}/{len(scene.settings.solutions)}] {name}: done")
        # a swept-sine test depends on its direction, the steady-state solutions do not: they are not repeated along
        # ``sweep``; the swept runs' estimates on the frequency grid are the ``swept_*`` variables (sweep, frequency)
        engine = next((name for name in scene.settings.solutions if name in ENGINE_SOLUTIONS), "")
        steady_dims = tuple(d for d in GRID_DIMS if d != "sweep")
        coords = grid_coordinates(scene, grid, list(steady))
        coords["sweep"] = np.array(grid.directions, dtype=object)
        several = count > 1 and any(q in STOP_QUANTITIES for q in scene.settings.quantities)
        if several:
            coords["stop"] = np.arange(count, dtype=np.int32)  # CF 2.2 (netCDF classic types): no int64
            coords["stop_description"] = ("stop", np.array(stop_descriptions(scene.layout.stops, scene.coordinates, scene.settings.restitution, scene.settings.clearance, scene.settings.bumper_frequency), dtype=object))

        def stop_dims(quantity: str, dims: tuple[str, ...]) -> tuple[str, ...]:
            return ("stop", *dims) if quantity in STOP_QUANTITIES and several else dims

        def per_stop(quantity: str, values: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
            """Per-stop values with their leading stop axis (dropped for one stop), others as they are."""
            if quantity not in STOP_QUANTITIES:
                return np.broadcast_to(values, shape)
            values = np.broadcast_to(values, (count, *shape))
            return values if several else values[0]

        data_vars = {}
        for quantity in scene.settings.quantities:
            attrs = _attributes(scene, quantity)
            if steady and quantity not in NOT_CLOSED_FORM:
                stacked = np.stack([per_stop(quantity, values[quantity], grid.full) for values in steady.values()])
                data_vars[quantity] = xr.Variable(("solution", *stop_dims(quantity, steady_dims)), stacked[..., 0, :], attrs)
            if quantity in swept:  # what the sweep estimates (swept_values): no placeholder of a steady-state quantity
                data_vars[f"swept_{quantity}"] = xr.Variable(stop_dims(quantity, GRID_DIMS), per_stop(quantity, swept[quantity], grid.full), swept_attributes(engine, attrs))
        for name, values in running.items():
            if name.startswith("sweep_"):  # one value per sweep run
                data_vars[name] = xr.Variable(GRID_DIMS[:-1], values, SWEEP_STAT_ATTRIBUTES[name])
            else:
                quantity = name.removeprefix("running_")
                shape = (*grid.full[:-1], axes["time"].size)
                data_vars[name] = xr.Variable(stop_dims(quantity, (*GRID_DIMS[:-1], "elapsed_time")), per_stop(quantity, values, shape), running_attributes(_attributes(scene, quantity)))
        dataset = describe_stops(xr.Dataset(data_vars, coords=coords))
        if running:
            dataset = dataset.assign_coords(
                elapsed_time=("elapsed_time", axes["time"], dict(SWEEP_TIME_ATTRIBUTES["elapsed_time"])),
                instantaneous_frequency=(("sweep", "elapsed_time"), axes["instantaneous_frequency"], dict(SWEEP_TIME_ATTRIBUTES["instantaneous_frequency"])),
            )
        # a swept-sine study keeps its sweep dimension even with one direction
        return finish_dataset(dataset, scene, coords, self.simulation_attributes(scene), keep=("sweep",))

    @staticmethod
    def simulation_attributes(scene: Scene) -> dict[str, object]:
        """What the dataset records of the sweep and of the compliant engine's tolerances."""
        assert scene.settings.swept_sine is not None
        attrs: dict[str, object] = {}
        if scene.settings.simulation is not None:
            for key, value in asdict(scene.settings.swept_sine).items():
                attrs[f"swept_sine_{key}"] = np.array(value, dtype=str) if key == "directions" else value
            for key in ("rtol", "atol", "max_step"):
                attrs[f"simulation_engine_{key}"] = getattr(scene.settings.simulation.engine, key)
        return attrs

    def estimate(self, scene: Scene, jobs: int, costs: Costs) -> Estimate:
        """Seconds per simulated second of the compliant engine at its tolerance (scaled for the layout's coordinates
        and stops) times the sweeps' durations, on the calibration machine; the memory holds one sweep's samples per
        worker."""
        assert scene.settings.swept_sine is not None
        s = scene.settings.swept_sine
        bumpers = scene.settings.bumper_frequency.size if scene.settings.bumper_frequency is not None else 1
        directions = max(1, len(scene.settings.sweep_directions))

        def engine_part(name: str, engine: str) -> EnginePart:
            assert scene.settings.simulation is not None
            duration = abs(s.stop_frequency - s.start_frequency) / s.rate
            one = costs.per_sweep_second_cost(engine, scene.settings.simulation.engine.rtol) * duration * engine_scale(scene.layout)
            runs = scene.settings.restitution.size * scene.settings.clearance.size * bumpers * directions
            return one * runs, f"{runs} sweeps of {duration:g} s", one

        samples = abs(s.stop_frequency - s.start_frequency) / s.rate * s.sample_rate
        return grid_estimate(scene, jobs, costs, engine_part, REPORT_FIGURES, samples, closed_form_scale=lambda name: closed_form_scale(scene, name))


def _attributes(scene: Scene, quantity: str) -> dict[str, object]:
    """Units and long name of a quantity: the paper's for its named form, named after the coordinates and stops for a
    general scene."""
    return general_quantity_attributes(quantity, scene) if scene.layout.paper_view() is None else quantity_attributes(quantity)


def closed_form_values(scene: Scene, name: str, grid: StudyGrid) -> Values:
    """A closed-form steady-state solution (``linear``, ``pgf``; ``pgf_paper`` for the named form) over the grid, the
    scene's quantities; per-stop ones with a leading axis of one entry per stop."""
    if name == "linear":
        return general_linear_values(scene, grid.omega, grid.base)
    return general_pgf_values(scene, grid.omega, grid.delta, grid.r, grid.base, name)  # pgf_paper: the paper's fitted Green function (its layout only)


def swept_values(scene: Scene, shape: tuple[int, ...], runner: Runner) -> tuple[Values, Values, Values]:
    """Swept-sine tests of the compliant model: estimates on the frequency grid (per-stop ones with a leading stop
    axis), running estimates against time and each run's statistics (``sweep_<stat>``), and the time axes
    (``time``, ``instantaneous_frequency`` per direction)."""
    assert scene.settings.swept_sine is not None and scene.settings.bumper_frequency is not None and scene.settings.simulation is not None
    # xi_b: the scene's where it gives one, else each stop's own from its restitution (build_stops)
    losses = scene.settings.loss_factors() if scene.settings.bumper_loss_factor is not None else np.full(scene.settings.restitution.shape, np.nan)
    frequencies = tuple(float(f) for f in scene.settings.all_frequencies)
    cases, places = [], []
    for i, restitution in enumerate(scene.settings.restitution):
        for j, clearance in enumerate(scene.settings.clearance):
            for k, bumper in enumerate(scene.settings.bumper_frequency):
                stops = build_stops(scene.layout.stops, True, float(restitution), float(clearance), float(bumper), float(losses[i]))
                for d, direction in enumerate(scene.settings.swept_sine.directions):
                    cases.append(SweepCase(scene.layout.structure, scene.amplitude, stops, scene.settings.swept_sine, direction, scene.settings.simulation.engine, frequencies, scene.layout.load))
                    places.append((i, j, k, d))
    results = runner.map(cases)
    times = results[0]["time"]
    count = len(scene.layout.stops)
    names = sweep_quantities(scene.coordinates)

    def room(name: str, tail: tuple[int, ...]) -> np.ndarray:
        return np.full(((count,) if name in SWEEP_STOP_QUANTITIES else ()) + tail, np.nan)

    values = {name: room(name, shape) for name in names}
    running = {f"running_{name}": room(name, (*shape[:-1], times.size)) for name in names}
    stats = {name: np.full(shape[:-1], np.nan) for name in SWEEP_STATS}
    instantaneous = np.full((shape[3], times.size), np.nan)
    for (i, j, k, d), result in zip(places, results):
        for name in names:
            values[name][..., i, j, k, d, :] = result[name]
            running[f"running_{name}"][..., i, j, k, d, :] = result[f"running_{name}"]
        for name in stats:
            stats[name][i, j, k, d] = result[name]
        instantaneous[d] = result["instantaneous_frequency"]
    impacts = values["impacts_per_period"]
    regime = np.full(shape, Regime.NOT_COMPUTED, dtype=np.int8)
    regime[impacts == 0.0] = Regime.LINEAR
    regime[impacts > 0.0] = Regime.SWEPT_CONTACT
    regime[np.broadcast_to(stats["failed"][..., None] == 1.0, shape)] = Regime.FAILED
    # only what a sweep measures: a sweep is a transient, so it has no phase of a periodic orbit, no stability, Floquet
    # modulus or one-impact closed form, no attractor to classify and no convergence (those would be NaN or -1 only)
    values |= {"regime": regime, "wall_time": np.broadcast_to(stats["wall_time"][..., None], shape)}
    running = {name: value for name, value in running.items() if name.removeprefix("running_") in scene.settings.quantities}
    for name, value in stats.items():
        # one value per sweep: its cost, and two flags (started on the linear steady state, failed) that vary from run
        # to run although a small study's runs may agree
        running[f"sweep_{name}"] = value
    return {q: values[q] for q in scene.settings.quantities if q in values}, running, {"time": times, "instantaneous_frequency": instantaneous}
