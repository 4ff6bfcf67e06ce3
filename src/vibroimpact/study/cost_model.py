"""The calibrated costs (``costs.json``, shipped with the package) and the sums every kind of study's estimate shares.

``costs.json`` holds what the ``accuracy_cost`` study measured on the calibration machine (written by ``run-study
calibrate ACCURACY.nc``): seconds per closed-form grid point of each solution, seconds per simulated period (stepped)
and per simulated second (swept) of each registered engine at each measured rtol, the fixed costs (start-up, report,
memory of the main and worker processes) and the time of the speed probe on that machine.
"""

from __future__ import annotations

import functools
import json
import math
import os
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vibroimpact.engines.registry import engine_spec
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, Scene

__all__ = ["COSTS_FILE", "Costs", "Estimate", "default_costs", "cost_engine", "grid_estimate", "memory", "os_cpus", "cluster_cores", "CLUSTER_STARTUP", "TASK_SECONDS", "WRITE_SECONDS_PER_VARIABLE"]

#: Starting a local dask cluster: worker processes spawned, the package imported in each [s] (measured on the
#: 2-core machine: 2.5-3.5 s for 2 workers).
CLUSTER_STARTUP = 3.0
#: The dask scheduler's cost per task, submit to result in the main process [s] (measured: 1.5-1.9 ms with 2 workers).
TASK_SECONDS = 0.002
#: Writing one variable of a finished block into the zarr store [s] (measured: ~1 ms per variable of 2 x 250 values).
WRITE_SECONDS_PER_VARIABLE = 0.001
#: Cores that an estimate spreads the work over when it is for a cluster (None: this machine's).
_CLUSTER_CORES: ContextVar[int | None] = ContextVar("cluster_cores", default=None)

#: The package's own cost file.
COSTS_FILE = Path(__file__).with_name("costs.json")
#: The registered engine whose measured cost stands for each time-domain solution (``momentary`` by its CVODE method).
_SOLUTION_ENGINES = {"exact": "exact", "compliant": "compliant_ida"}
#: The fixed costs of a cost file (top-level numbers).
_FIXED = ("main_process_memory", "report_base", "report_per_figure", "speed_probe_seconds", "startup", "worker_process_memory")

#: rtol [-] -> seconds; ``exact`` has one value (no tolerance).
CostTable = Mapping[float, float]


@dataclass(frozen=True, eq=False)
class Costs:
    """Measured costs of the calibration machine, checked at construction.

    Attributes
    ----------
    closed_form_per_point : mapping
        Solution name -> seconds per grid point [s].
    per_period : mapping
        Registered engine -> seconds per simulated period of a stepped run [s], a number or a table rtol -> seconds.
    per_sweep_second : mapping
        Registered engine -> table rtol -> seconds per simulated second of a swept run [s s-1].
    main_process_memory, worker_process_memory : float
        Footprint of the main process and of one worker process [bytes].
    report_base, report_per_figure : float
        Wall time of a report: fixed, and per figure [s].
    speed_probe_seconds : float
        Time of :func:`vibroimpact.study.estimate.speed_probe` on the calibration machine [s].
    startup : float
        Fixed wall time of a run (imports, scene, dataset) [s].
    """

    closed_form_per_point: Mapping[str, float]
    per_period: Mapping[str, float | CostTable]
    per_sweep_second: Mapping[str, CostTable]
    main_process_memory: float
    worker_process_memory: float
    report_base: float
    report_per_figure: float
    speed_probe_seconds: float
    startup: float

    def __post_init__(self) -> None:
        problems = []
        tables = {"per_period": self.per_period, "per_sweep_second": self.per_sweep_second}
        for kind, table in tables.items():
            for engine, costs in table.items():
                try:
                    engine_spec(engine)
                except ValueError as error:
                    problems.append(f"{kind}: {error}")
                values = list(costs.values()) if isinstance(costs, Mapping) else [costs]
                if not values or not all(math.isfinite(v) and v > 0.0 for v in values):
                    problems.append(f"{kind}.{engine}: expected positive seconds, got {costs!r}")
        for name, value in (*self.closed_form_per_point.items(), *((name, getattr(self, name)) for name in _FIXED)):
            if not (math.isfinite(value) and value > 0.0):
                problems.append(f"{name} = {value!r} is out of range: allowed (0, inf)")
        if problems:
            raise ValueError("invalid costs: " + "; ".join(problems))

    def per_period_cost(self, engine: str, rtol: float) -> float:
        """Measured wall time of one simulated period of a stepped run of ``engine`` at ``rtol`` [s]."""
        table = self.per_period[engine]
        if not isinstance(table, Mapping):
            return float(table)  # exact: no tolerance
        return _interpolate(table, rtol)

    def per_sweep_second_cost(self, engine: str, rtol: float) -> float:
        """Measured wall time per simulated second of a swept-sine run of ``engine`` at ``rtol`` [s s-1]."""
        return _interpolate(self.per_sweep_second[engine], rtol)

    @classmethod
    def from_json(cls, text: str) -> "Costs":
        """Costs from the text of a cost file; ``ValueError`` if it is not one."""
        document = json.loads(text)
        if not isinstance(document, dict):
            raise ValueError("a cost file holds a JSON object")
        try:
            return cls(
                closed_form_per_point={str(k): float(v) for k, v in document["closed_form_per_point"].items()},
                per_period={str(k): _table(v) if isinstance(v, dict) else float(v) for k, v in document["per_period"].items()},
                per_sweep_second={str(k): _table(v) for k, v in document["per_sweep_second"].items()},
                **{name: float(document[name]) for name in _FIXED},
            )
        except (KeyError, TypeError, AttributeError) as error:
            raise ValueError(f"not a cost file: {type(error).__name__}: {error}") from None

    @classmethod
    def load(cls, path: Path) -> "Costs":
        """Costs from the file ``path``; ``OSError`` if it cannot be read, ``ValueError`` if it is not a cost file."""
        try:
            return cls.from_json(Path(path).read_text(encoding="utf-8"))
        except ValueError as error:
            raise ValueError(f"{path}: {error}") from None

    def to_json(self) -> str:
        """The text of a cost file (keys sorted; tolerances as their shortest exact decimal)."""

        def tables(source: Mapping[str, float | CostTable]) -> dict[str, object]:
            return {k: {repr(float(t)): s for t, s in v.items()} if isinstance(v, Mapping) else v for k, v in source.items()}

        document = {"closed_form_per_point": dict(self.closed_form_per_point), "per_period": tables(self.per_period), "per_sweep_second": tables(self.per_sweep_second), **{name: getattr(self, name) for name in _FIXED}}
        return json.dumps(document, indent=1, sort_keys=True) + "\n"


def _table(source: dict[str, float]) -> dict[float, float]:
    return {float(rtol): float(seconds) for rtol, seconds in source.items()}


def _interpolate(table: CostTable, rtol: float) -> float:
    tolerances = np.array(sorted(table))
    seconds = np.array([table[t] for t in tolerances])
    return float(np.exp(np.interp(np.log(rtol), np.log(tolerances), np.log(seconds))))


@functools.cache
def default_costs() -> Costs:
    """The package's calibrated costs (:data:`COSTS_FILE`), read once per process."""
    return Costs.load(COSTS_FILE)


def cost_engine(solution: str, method: str) -> str:
    """The registered engine whose costs stand for the time-domain ``solution`` run with the CVODE ``method``."""
    return _SOLUTION_ENGINES.get(solution, f"momentary_{method}")


@dataclass(frozen=True)
class Estimate:
    """Predicted cost of a scene.

    Attributes
    ----------
    wall_time : float
        Predicted wall time of ``run-study`` [s] (on this machine: ``speed_factor`` included).
    memory : float
        Predicted peak memory of the main process [bytes].
    parts : dict
        Wall time of each part (solution, report) [s], before dividing simulations over processes.
    points : dict
        Time-domain points (or sweeps) per solution, and how many are predicted to integrate.
    speed_factor : float
        This machine's time for the speed probe over the calibration machine's [-] (> 1: slower).
    """

    wall_time: float
    memory: float
    parts: dict[str, float] = field(default_factory=dict)
    points: dict[str, str] = field(default_factory=dict)
    speed_factor: float = 1.0

    def text(self) -> str:
        """The estimate as printed by ``run-study --estimate``."""
        lines = [f"predicted wall time: {_duration(self.wall_time)}; peak memory: {self.memory / 2**20:.0f} MiB"]
        for name, seconds in self.parts.items():
            detail = f" ({self.points[name]})" if name in self.points else ""
            lines.append(f"  {name}: {_duration(seconds)} of work{detail}")
        lines.append(
            f"(costs measured by the accuracy_cost study, scaled by this machine's speed: a probe took {self.speed_factor:.2f} x "
            "the calibration machine's time; an estimate, typically within a factor of 2)"
        )
        return "\n".join(lines)


def _duration(seconds: float) -> str:
    if seconds < 120.0:
        return f"{seconds:.0f} s"
    if seconds < 7200.0:
        return f"{seconds / 60.0:.1f} min"
    return f"{seconds / 3600.0:.1f} h"


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
    frequency = scene.all_frequencies
    bumpers = scene.bumper_frequency.size if scene.bumper_frequency is not None else 1
    grid = scene.restitution.size * scene.clearance.size * frequency.size
    closed_form = 0.0
    simulated = 0.0
    biggest_case = 0.0
    for name in scene.solutions:
        if name not in ENGINE_SOLUTIONS:
            seconds = costs.closed_form_per_point[name] * grid * (bumpers if name == "pgf" and scene.bumper_frequency is not None else 1) * closed_form_scale(name)
            parts[name] = seconds
            closed_form += seconds
            continue
        assert scene.simulation is not None
        parts[name], points[name], serial = engine_part(name, cost_engine(name, scene.simulation.engine.method))
        biggest_case = max(biggest_case, serial)
        simulated += parts[name]
    report = 0.0
    if scene.report:
        report = costs.report_base + costs.report_per_figure * figures
        parts["report"] = report
    workers = min(jobs, os_cpus())
    overhead = 0.0
    if blocks is not None:
        overhead = blocks(workers) * (TASK_SECONDS + WRITE_SECONDS_PER_VARIABLE * len(scene.quantities))
        parts["scheduler and store"] = overhead
        closed_form /= workers  # the closed forms are solved block by block on the workers too
    startup = costs.startup + (CLUSTER_STARTUP if jobs > 1 and _CLUSTER_CORES.get() is None else 0.0)
    wall = startup + closed_form + max(simulated / workers, biggest_case) + overhead + report
    return Estimate(wall_time=wall, memory=memory(scene, jobs, costs, sweep_samples, streamed=blocks is not None), parts=parts, points=points)


def os_cpus() -> int:
    """Processes that really run at once: the machine's cores, or a cluster's (:func:`cluster_cores`)."""
    return _CLUSTER_CORES.get() or os.cpu_count() or 1


@contextmanager
def cluster_cores(cores: int) -> Iterator[None]:
    """Estimates made inside spread the work over ``cores`` workers of a cluster, not this machine's cores."""
    token = _CLUSTER_CORES.set(max(1, cores))
    try:
        yield
    finally:
        _CLUSTER_CORES.reset(token)


def memory(scene: Scene, jobs: int, costs: Costs, sweep_samples: float = 0.0, streamed: bool = False) -> float:
    """Peak memory of the run, main process and workers [bytes]: the main process's footprint and its dataset (built,
    stacked, written: ~3 copies; ``streamed``: solved in blocks into the store and exported chunk by chunk, so only
    the report reads it whole), one worker footprint per process simulating, and the ``sweep_samples`` of one sweep
    per worker."""
    frequency = scene.all_frequencies
    bumpers = scene.bumper_frequency.size if scene.bumper_frequency is not None else 1
    directions = max(1, len(scene.sweep_directions))
    cells = scene.restitution.size * scene.clearance.size * bumpers * directions * frequency.size
    dataset = 3.0 * 8.0 * len(scene.quantities) * len(scene.solutions) * cells
    if streamed:
        dataset = dataset / 3.0 if scene.report else 0.0
    simulating = any(name in ENGINE_SOLUTIONS for name in scene.solutions)
    workers = min(jobs, os_cpus()) if (simulating or streamed) and jobs > 1 else 0
    sweep = 0.0
    if sweep_samples:
        sweep = sweep_samples * 8.0 * 16 * max(1, workers)  # samples, cumulative integrals and temporaries of the estimators
    return costs.main_process_memory + dataset + workers * costs.worker_process_memory + sweep
