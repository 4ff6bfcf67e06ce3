"""The estimate of a study on the frequency grid shared by the stepped and swept kinds: its grid's closed forms, its
time-domain solutions (each kind says what one costs, :data:`EnginePart`), its report and its memory.
"""

from __future__ import annotations

from typing import Callable

from vibroimpact.runs.estimate import TASK_SECONDS, WRITE_SECONDS_PER_VARIABLE, Costs, Estimate, cluster_startup, cost_engine, os_cpus
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, Scene

__all__ = ["EnginePart", "grid_estimate", "memory", "closed_form_scale", "CLOSED_FORM_FACTOR"]

#: Cost of the general closed form per point over the named one's, on the paper's layout (measured).
CLOSED_FORM_FACTOR = 1.3


def closed_form_scale(scene: Scene, solution: str) -> float:
    """A closed form's cost per grid point relative to the one measured on the paper's layout by its named route."""
    if solution == "pgf_paper":
        return 1.0
    size = (scene.layout.size / 2.0) ** 2
    return CLOSED_FORM_FACTOR * size * (len(scene.layout.stops) if solution == "linear" else 1.0)


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
