"""What stepped and swept studies share: the full grid, the loop over solutions, and the dataset around the values.

The full grid is (restitution, clearance, bumper_frequency, sweep, frequency): unswept axes have length 1 and are
squeezed at the end; each solution computes only along the axes it depends on, then is broadcast.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Callable

import numpy as np
import xarray as xr

from vibroimpact.model.modal import fit_modal_parameters
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, STOP_QUANTITIES, Scene
from vibroimpact.scene.variables import COORDINATE_ATTRIBUTES
from vibroimpact.kinds.stepped.values import general_linear_values, general_pgf_values
from vibroimpact.runs.cluster import Progress
from vibroimpact.runs.estimate import TASK_SECONDS, WRITE_SECONDS_PER_VARIABLE, Costs, Estimate, cluster_startup, cost_engine, os_cpus
from vibroimpact.runs.run import provenance
from vibroimpact.reporting.solutions import closed_form_methods, solution_method

__all__ = ["EnginePart", "grid_estimate", "memory", "StudyGrid", "solve_each", "grid_coordinates", "steady_variable", "finish_dataset", "no_one_impact_orbit"]

#: The values of one solution, quantity -> array over (part of) the full grid.
Values = dict[str, np.ndarray]


@dataclass(frozen=True, eq=False)
class StudyGrid:
    """The full grid of a study and its axes, shaped for broadcasting.

    Attributes
    ----------
    frequency : ndarray
        Every frequency of the dataset [Hz].
    bumper : ndarray
        Omega_b / 2 pi [Hz]; ``[nan]`` without a bumper.
    directions : tuple of str
        Sweep directions; ``("",)`` for stepped studies.
    full : tuple of int
        Shape of the full grid.
    r, delta, omega : ndarray
        Restitution [-], clearance [m] and angular frequency [rad s-1] on their axes of the full grid.
    base : tuple of int
        Shape of the closed forms' grid (restitution, clearance, frequency).
    """

    frequency: np.ndarray
    bumper: np.ndarray
    directions: tuple[str, ...]
    full: tuple[int, ...]
    r: np.ndarray
    delta: np.ndarray
    omega: np.ndarray
    base: tuple[int, ...]

    @classmethod
    def of(cls, scene: Scene) -> "StudyGrid":
        """The grid of ``scene``."""
        frequency = scene.settings.all_frequencies
        bumper = scene.settings.bumper_frequency if scene.settings.bumper_frequency is not None else np.array([np.nan])
        directions = scene.settings.sweep_directions or ("",)
        full = (scene.settings.restitution.size, scene.settings.clearance.size, bumper.size, len(directions), frequency.size)
        r = scene.settings.restitution[:, None, None, None, None]
        delta = scene.settings.clearance[None, :, None, None, None]
        omega = 2.0 * np.pi * frequency[None, None, None, None, :]
        base = np.broadcast_shapes(r.shape, delta.shape, omega.shape)
        return cls(frequency, bumper, directions, full, r, delta, omega, base)


def solve_each(scene: Scene, grid: StudyGrid, simulate: Callable[[str], Values], progress: Progress | None) -> list[Values]:
    """The values of every solution of ``scene``, in its order; ``simulate(name)`` computes a time-domain one.

    The closed forms are those of any layout (:mod:`vibroimpact.kinds.stepped.values`): per-coordinate quantities named
    after the coordinates, per-stop ones with a leading axis of one entry per stop; ``pgf_paper`` is the paper's own
    route where the scene has its layout (:mod:`vibroimpact.kinds.stepped.values`).
    """
    report = progress or (lambda _message: None)
    total = len(scene.settings.solutions)
    per_solution = []
    for i, name in enumerate(scene.settings.solutions, start=1):
        if name == "linear":
            values = general_linear_values(scene, grid.omega, grid.base)
        elif name in ENGINE_SOLUTIONS:
            values = simulate(name)
        else:  # pgf, or pgf_paper: the same orbit with the paper's fitted Green function
            values = general_pgf_values(scene, grid.omega, grid.delta, grid.r, grid.base, name)
        per_solution.append(values)
        report(f"[{i}/{total}] {name}: done")
    return per_solution


def grid_coordinates(scene: Scene, grid: StudyGrid, solutions: list[str]) -> dict[str, object]:
    """Coordinates of the dataset before squeezing: ``solution`` (if any), the parameters and ``frequency``."""
    coords: dict[str, object] = {"solution": np.array(solutions, dtype=object), "restitution": scene.settings.restitution, "clearance": scene.settings.clearance, "frequency": grid.frequency}
    if scene.settings.bumper_frequency is not None:
        coords["bumper_frequency"] = scene.settings.bumper_frequency
    if not solutions:
        del coords["solution"]
    return coords


def steady_variable(quantity: str, scene: Scene, grid: StudyGrid, per_solution: list[Values], solutions: list[str]) -> np.ndarray | None:
    """``quantity`` of the named solutions stacked along a leading ``solution`` axis over the full grid; None if none.
    A per-stop quantity is taken at the scene's one stop (a layout with one stop has no ``stop`` dimension)."""
    one_stop = quantity in STOP_QUANTITIES and len(scene.layout.stops) == 1

    def full(name: str, values: Values) -> np.ndarray:
        value = values[quantity]
        if one_stop and name not in ENGINE_SOLUTIONS:
            value = np.broadcast_to(value, (1, *grid.full))[0]
        return np.broadcast_to(value, grid.full)

    steady = [full(name, values) for name, values in zip(scene.settings.solutions, per_solution) if name in solutions]
    return np.stack(steady) if steady else None


def finish_dataset(dataset: xr.Dataset, scene: Scene, coords: dict[str, object], simulation_attributes: dict[str, object], keep: tuple[str, ...] = ()) -> xr.Dataset:
    """Squeeze the unswept axes (not those in ``keep``), add the bumper's loss factor, the coordinates' attributes and
    the dataset's metadata (``simulation_attributes``: what the study kind says of its simulations)."""
    for key in ("restitution", "clearance", "bumper_frequency", "sweep"):
        if key in keep:
            continue
        swept = key in scene.settings.swept or (key == "restitution" and "bumper_loss_factor" in scene.settings.swept)
        if not swept and key in dataset.dims:
            dataset = dataset.squeeze(key, drop=key not in coords)
        if key in dataset.coords and dataset[key].ndim == 0 and dataset[key].dtype.kind == "f" and not np.isfinite(float(dataset[key])):
            dataset = dataset.drop_vars(key)  # the stops give different values: the stop descriptions say them
    if scene.settings.bumper_frequency is not None:
        losses = scene.settings.loss_factors()
        if "restitution" in dataset.dims or np.isfinite(losses[0]):  # none at R = 0 (no loss factor gives it); stops may each have their own
            dataset = dataset.assign_coords(bumper_loss_factor=("restitution", losses) if "restitution" in dataset.dims else float(losses[0]))
        if "bumper_loss_factor" in scene.settings.swept:
            dataset = dataset.swap_dims({"restitution": "bumper_loss_factor"})
    for key, attrs in COORDINATE_ATTRIBUTES.items():
        if key in dataset.coords:
            dataset[key].attrs.update(attrs)
    dataset.attrs.update(_metadata(scene, simulation_attributes))
    return dataset


def _metadata(scene: Scene, simulation_attributes: dict[str, object]) -> dict[str, object]:
    structure = scene.layout.structure
    named = scene.layout.named_view()  # the named view: the paper's two-mass chain, however it was written
    fit = fit_modal_parameters(named) if named is not None and "pgf_paper" in scene.settings.solutions else None
    natural = named.natural_angular_frequencies() if named is not None else structure.natural_angular_frequencies()
    attrs: dict[str, object] = {
        "title": f"vibroimpact study '{scene.name}'",
        "scene_name": scene.name,
        "scene": scene.text,
        **provenance(),
        "excitation_amplitude_N": scene.amplitude,
        "natural_frequencies_Hz": np.array(natural) / (2.0 * np.pi),
    }
    if named is not None:
        attrs["antiresonance_frequency_Hz"] = named.antiresonance_angular_frequency() / (2.0 * np.pi)
    attrs.update(scene.layout.attributes(scene.settings.restitution, scene.settings.clearance) | closed_form_methods())
    if "pgf_paper" in scene.settings.solutions:
        attrs["method_pgf_paper"] = solution_method("pgf_paper")
    for key, value in asdict(scene.settings.admissibility).items():
        attrs[f"admissibility_{key}"] = value
    attrs.update(simulation_attributes)
    if isinstance(scene.report, str):
        attrs["report_page"] = scene.report  # the page the scene asks for (reporting.page.page_for)
    if fit is not None:
        attrs["pgf_paper_form_factors_per_kg"] = np.real(fit.form_factor)
        attrs["pgf_paper_loss_factors"] = fit.loss_factor
    return attrs


def no_one_impact_orbit(shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """Values of the variables that describe the closed form's orbit, for solutions that have none (time-domain
    engines, swept-sine tests)."""
    nan = np.full(shape, np.nan)
    return {
        "stable": np.full(shape, -1, dtype=np.int8),
        "floquet_modulus": nan,
        "one_impact_x1_amplitude": nan,
        "one_impact_x2_amplitude": nan,
        "one_impact_force_amplitude": nan,
        "one_impact_impulse": nan,
    }


# --------------------------------------------------------------------------------------------------------------------
# The estimate of a stepped or swept study: its grid's closed forms, engines, report and memory.
# --------------------------------------------------------------------------------------------------------------------

#: One time-domain solution's predicted work: (seconds, what it runs, the longest serial case [s]).
EnginePart = tuple[float, str, float]


def grid_estimate(
    scene: Scene, jobs: int, costs: Costs, engine_part: Callable[[str, str], EnginePart], figures: int, sweep_samples: float = 0.0,
    closed_form_scale: Callable[[str], float] = lambda _name: 1.0, blocks: Callable[[int], int] | None = None,
) -> Estimate:  # fmt: skip
    """The estimate of a stepped or swept study on the calibration machine: the closed forms per grid point (times
    ``closed_form_scale(solution)``: a general layout's relative cost), each time-domain solution by
    ``engine_part(solution, cost engine)``, spread over the workers, and the report's ``figures``;
    ``sweep_samples`` output samples of one swept run held in memory per worker; ``blocks(workers)``: the dask tasks
    of a study solved in grid blocks, each costing the scheduler and the store's writes in the main process."""
    parts: dict[str, float] = {}
    points: dict[str, str] = {}
    frequency = scene.settings.all_frequencies
    bumpers = scene.settings.bumper_frequency.size if scene.settings.bumper_frequency is not None else 1
    grid = scene.settings.restitution.size * scene.settings.clearance.size * frequency.size
    closed_form = 0.0
    simulated = 0.0
    biggest_case = 0.0
    for name in scene.settings.solutions:
        if name not in ENGINE_SOLUTIONS:
            seconds = costs.closed_form_per_point[name] * grid * (bumpers if name == "pgf" and scene.settings.bumper_frequency is not None else 1) * closed_form_scale(name)
            parts[name] = seconds
            closed_form += seconds
            continue
        assert scene.settings.simulation is not None
        parts[name], points[name], serial = engine_part(name, cost_engine(name, scene.settings.simulation.engine.method))
        biggest_case = max(biggest_case, serial)
        simulated += parts[name]
    report = 0.0
    if scene.report:
        report = costs.report_base + costs.report_per_figure * figures
        parts["report"] = report
    workers = min(jobs, os_cpus())
    overhead = 0.0
    if blocks is not None:
        overhead = blocks(workers) * (TASK_SECONDS + WRITE_SECONDS_PER_VARIABLE * len(scene.settings.quantities))
        parts["scheduler and store"] = overhead
        closed_form /= workers  # the closed forms are solved block by block on the workers too
    startup = costs.startup + cluster_startup(jobs)
    wall = startup + closed_form + max(simulated / workers, biggest_case) + overhead + report
    return Estimate(wall_time=wall, memory=memory(scene, jobs, costs, sweep_samples, streamed=blocks is not None), parts=parts, points=points)


def memory(scene: Scene, jobs: int, costs: Costs, sweep_samples: float = 0.0, streamed: bool = False) -> float:
    """Peak memory of the run, main process and workers [bytes]: the main process's footprint and its dataset (built,
    stacked, written: ~3 copies; ``streamed``: solved in blocks into the store and exported chunk by chunk, so only
    the report reads it whole), one worker footprint per process simulating, and the ``sweep_samples`` of one sweep
    per worker."""
    frequency = scene.settings.all_frequencies
    bumpers = scene.settings.bumper_frequency.size if scene.settings.bumper_frequency is not None else 1
    directions = max(1, len(scene.settings.sweep_directions))
    cells = scene.settings.restitution.size * scene.settings.clearance.size * bumpers * directions * frequency.size
    dataset = 3.0 * 8.0 * len(scene.settings.quantities) * len(scene.settings.solutions) * cells
    if streamed:
        dataset = dataset / 3.0 if scene.report else 0.0
    simulating = any(name in ENGINE_SOLUTIONS for name in scene.settings.solutions)
    workers = min(jobs, os_cpus()) if (simulating or streamed) and jobs > 1 else 0
    sweep = 0.0
    if sweep_samples:
        sweep = sweep_samples * 8.0 * 16 * max(1, workers)  # samples, cumulative integrals and temporaries of the estimators
    return costs.main_process_memory + dataset + workers * costs.worker_process_memory + sweep
