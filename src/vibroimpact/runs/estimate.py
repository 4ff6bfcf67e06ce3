"""Predict a scene's wall time and memory before running it (``run-study SCENE --estimate``), and calibrate the costs
the prediction rests on (``run-study calibrate ACCURACY.nc``).

The prediction multiplies what the scene asks for by costs measured on the calibration machine (the package's
``costs.json``, :mod:`vibroimpact.runs.estimate`, written by ``run-study calibrate`` from the ``accuracy_cost``
study); each kind of study (:data:`vibroimpact.scene.kinds.KINDS`) sums its own work:

* closed forms: seconds per grid point of each solution;
* stepped steady states: seconds per simulated period of each engine at its tolerance (interpolated log-log between
  the measured tolerances) times the periods each point will need, predicted from the closed form: none where the
  answer is the linear state (no integration), a short transient plus the measured periods where a stable one-impact
  orbit exists, and ``max_periods`` plus the irregular measurement elsewhere (motion that may never settle);
* swept sines: seconds per simulated second of the compliant engine at its tolerance;
* benchmarks: every method at every tolerance, as the benchmark runs them;
* the work is spread over ``jobs`` processes; the report adds a fixed cost per figure;
* everything is scaled by this machine's speed against the calibration machine's: a probe of about 0.1 s (the same
  short runs of the pure-Python exact flow and of ``momentary``, timed at calibration too) measures it, so a slower or
  busier machine gets a longer prediction. The probe needs no compiled core (a fresh install answers in seconds, not
  after the core's 30-60 s of compiling); a probe outside :data:`SPEED_FACTOR_RANGE` is clamped, and the estimate
  says so.

Memory: the dataset (every variable over the full grid, the running estimates of sweeps), the samples a sweep holds
while it runs, and the measured footprint of one worker process. It is an estimate: the report of
``accuracy_cost`` and ``tests/study/test_estimate.py`` compare it with measured runs.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import os
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.engines.registry import ENGINES, engine_spec
from vibroimpact.model.layout import Layout
from vibroimpact.runs.labels import decode_labels
from vibroimpact.runs.output_files import atomic_path
from vibroimpact.scene.kinds import kind_named
from vibroimpact.scene.schema import Scene

__all__ = ["COSTS_FILE", "Costs", "Estimate", "default_costs", "cost_engine", "cluster_startup", "os_cpus", "cluster_cores", "CLUSTER_STARTUP", "TASK_SECONDS", "WRITE_SECONDS_PER_VARIABLE", "estimate_scene", "engine_scale", "speed_probe", "speed_factor", "measured_speed_factor", "clamped_speed", "calibrate", "write_costs", "SPEED_FACTOR_RANGE"]


# --------------------------------------------------------------------------------------------------------------------
# The calibrated costs (``costs.json``, shipped with the package) and the sums every kind of study's estimate shares.
# --------------------------------------------------------------------------------------------------------------------

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
_SOLUTION_ENGINES = {"exact": "exact", "compliant": "compliant_ida", "compliant_exact": "compliant_exact"}
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
        Time of :func:`vibroimpact.runs.estimate.speed_probe` on the calibration machine [s].
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
        This machine's time for the speed probe over the calibration machine's [-] (> 1: slower), as the prediction
        uses it (within :data:`SPEED_FACTOR_RANGE`).
    measured_speed_factor : float or None
        The probe's own ratio where it fell outside :data:`SPEED_FACTOR_RANGE` and ``speed_factor`` is its clamp [-];
        None where the probe was used as measured (or the factor was given).
    """

    wall_time: float
    memory: float
    parts: dict[str, float] = field(default_factory=dict)
    points: dict[str, str] = field(default_factory=dict)
    speed_factor: float = 1.0
    measured_speed_factor: float | None = None

    def text(self) -> str:
        """The estimate as printed by ``run-study --estimate``."""
        lines = [f"predicted wall time: {_duration(self.wall_time)}; peak memory: {self.memory / 2**20:.0f} MiB"]
        for name, seconds in self.parts.items():
            detail = f" ({self.points[name]})" if name in self.points else ""
            lines.append(f"  {name}: {_duration(seconds)} of work{detail}")
        if self.measured_speed_factor is None:
            speed = f"a probe took {self.speed_factor:.2f} x the calibration machine's time"
        else:
            short = "short" if self.measured_speed_factor > self.speed_factor else "long"
            speed = (f"a probe took {self.measured_speed_factor:.2f} x the calibration machine's time, outside the believable range "
                     f"{SPEED_FACTOR_RANGE[0]:g}-{SPEED_FACTOR_RANGE[1]:g} x (a glitch, or a machine under heavy load): the prediction "
                     f"is clamped to {self.speed_factor:.2f} x and may be {short}")
        lines.append(f"(costs measured by the accuracy_cost study, scaled by this machine's speed: {speed}; an estimate, typically within a factor of 2)")
        return "\n".join(lines)


def _duration(seconds: float) -> str:
    if seconds < 120.0:
        return f"{seconds:.0f} s"
    if seconds < 7200.0:
        return f"{seconds / 60.0:.1f} min"
    return f"{seconds / 3600.0:.1f} h"


def cluster_startup(jobs: int) -> float:
    """What starting a local cluster of ``jobs`` worker processes adds to a run [s] (nothing on a running cluster,
    :func:`cluster_cores`, or in this process alone)."""
    return CLUSTER_STARTUP if jobs > 1 and _CLUSTER_CORES.get() is None else 0.0


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


#: Bounds of the machine-speed factor: a probe outside them is a glitch rather than a machine.
SPEED_FACTOR_RANGE = (0.2, 10.0)


def speed_probe(repeats: int = 3) -> float:
    """Wall time of a fixed short workload, the best of ``repeats`` [s]: 100 periods of ``exact_python`` (the exact
    flow in Python and numpy) and 100 of ``momentary`` (CVODE Adams, rtol 1e-8, compiled callbacks) at 25 Hz from rest,
    the kind of work the simulations spend their time on. It needs no compiled exact core: on a fresh install it
    answers after the callbacks' few seconds of compiling, not the core's 30-60 s."""
    import time

    from vibroimpact.engines.registry import make_engine
    from vibroimpact.engines.settings import STEPPED_TOLERANCES, EngineSettings
    from vibroimpact.model.contact import RigidStop
    from vibroimpact.model.excitation import HarmonicForce
    from vibroimpact.model.problem import ImpactProblem
    from vibroimpact.model.system import PAPER_SYSTEM

    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(3e-3, 0.2), HarmonicForce(10.0, 25.0))
    engines = (make_engine("exact_python"), make_engine("momentary", EngineSettings(*STEPPED_TOLERANCES)))
    best = math.inf
    for _ in range(repeats):
        started = time.perf_counter()
        for engine in engines:
            engine.integrate(problem, np.zeros(4), 0.0, 100)
        best = min(best, time.perf_counter() - started)
    return best


@functools.cache
def _probe_time() -> float:
    """:func:`speed_probe` on this machine, measured once per process (the accuracy report estimates every shipped study)."""
    return speed_probe()


def speed_factor(costs: Costs | None = None) -> float:
    """This machine's probe time over the calibration machine's (``costs``, by default the package's) [-], within
    :data:`SPEED_FACTOR_RANGE`."""
    return clamped_speed(measured_speed_factor(costs))


def measured_speed_factor(costs: Costs | None = None) -> float:
    """This machine's probe time over the calibration machine's (``costs``, by default the package's) [-], unclamped."""
    costs = default_costs() if costs is None else costs
    return _probe_time() / costs.speed_probe_seconds


def clamped_speed(factor: float) -> float:
    """``factor`` [-] within :data:`SPEED_FACTOR_RANGE`."""
    low, high = SPEED_FACTOR_RANGE
    return min(max(factor, low), high)


def estimate_scene(scene: Scene, jobs: int = 1, speed: float | None = None, costs: Costs | None = None) -> Estimate:
    """Predict the wall time and peak memory of running ``scene`` with ``jobs`` processes.

    ``speed`` is the machine-speed factor (this machine's time over the calibration machine's); by default it is
    measured with :func:`speed_factor`. ``costs`` are the calibrated costs, by default the package's."""
    jobs = max(1, jobs)
    costs = default_costs() if costs is None else costs
    measured = measured_speed_factor(costs) if speed is None else None
    speed = clamped_speed(measured) if measured is not None else speed
    unscaled = kind_named(scene.kind).make_study().estimate(scene, jobs, costs)
    return Estimate(
        wall_time=unscaled.wall_time * speed,
        memory=unscaled.memory,
        parts={name: seconds * speed for name, seconds in unscaled.parts.items()},
        points=unscaled.points,
        speed_factor=speed,
        measured_speed_factor=measured if measured is not None and measured != speed else None,  # exact: clamped or not
    )


def calibrate(accuracy: Path, base: Costs | None = None) -> Costs:
    """Costs from an ``accuracy_cost`` dataset: per period of the stepped one-impact case, per simulated second of
    the swept case, for each method and tolerance (one value for a tolerance-free engine); the closed-form and fixed
    costs are kept from ``base`` (by default the package's costs), and so is the per-period cost of an engine the
    dataset does not time, scaled by this machine's speed probe over ``base``'s; the speed probe is timed on this
    machine, the one that measured the costs.

    Raises
    ------
    OSError
        If ``accuracy`` cannot be read.
    ValueError
        If it is not a dataset of the ``accuracy_cost`` study (a stepped ``one_impact`` case and a ``swept`` case).
    """
    with xr.open_dataset(accuracy) as opened:
        data = decode_labels(opened)  # the cases, engines and references by name (:mod:`vibroimpact.runs.labels`)
        missing = [name for name in ("case", "engine", "wall_time", "reference_wall_time") if name not in data.variables]
        if missing:
            raise ValueError(f"{accuracy} is not an accuracy_cost dataset: no {', '.join(missing)}")
        cases = [str(c) for c in data["case"].values]
        stepped = next((c for c in cases if "one_impact" in c), None)
        swept = next((c for c in cases if "swept" in c), None)
        if stepped is None or swept is None:
            raise ValueError(f"{accuracy} has no {'one_impact' if stepped is None else 'swept'} case to calibrate from (cases: {', '.join(cases)})")
        duration = float(data.attrs.get(f"case_{stepped}_duration_s", 2.0))
        frequency = float(data.attrs.get(f"case_{stepped}_frequency_Hz", 25.0))
        sweep_duration = float(data.attrs.get(f"case_{swept}_duration_s", 10.0))
        periods = duration * frequency
        per_period: dict[str, float | dict[float, float]] = {"exact": float(data["reference_wall_time"].sel(case=stepped, reference="exact")) / periods}
        per_sweep: dict[str, dict[float, float]] = {}
        for method in data["engine"].values:
            for case, target, scale in ((stepped, per_period, periods), (swept, per_sweep, sweep_duration)):  # type: ignore[assignment]
                line = data["wall_time"].sel(case=case, engine=method)
                table = {float(t): float(w) / scale for t, w in zip(line["rtol"].values, line.values) if math.isfinite(float(w))}
                if table:
                    target[str(method)] = table
    for engine, table in list(per_period.items()):
        if isinstance(table, dict) and engine in ENGINES and ENGINES[engine].capabilities.tolerance_free:
            per_period[engine] = float(np.median(list(table.values())))  # one cost: its tolerances change nothing
    base = default_costs() if base is None else base
    probe = speed_probe()  # on the machine that measured the costs
    # an engine this dataset does not time keeps its cost in base, carried to this machine by the speed probes' ratio
    ratio = probe / base.speed_probe_seconds
    carried = {engine: _scaled(cost, ratio) for engine, cost in base.per_period.items() if engine not in per_period}
    return dataclasses.replace(base, per_period={**carried, **per_period}, per_sweep_second=per_sweep, speed_probe_seconds=probe)


def _scaled(cost: float | CostTable, factor: float) -> float | dict[float, float]:
    """A per-period cost (one value or a table over rtol) times ``factor``."""
    if isinstance(cost, Mapping):
        return {rtol: value * factor for rtol, value in cost.items()}
    return float(cost) * factor


def write_costs(costs: Costs, path: Path | None = None) -> Path:
    """Write ``costs`` to ``path`` atomically; by default to the package's own :data:`COSTS_FILE`.

    Raises
    ------
    PermissionError
        If the package's file is not writable (an installed package): give ``path``.
    """
    if path is None:
        path = COSTS_FILE
        if not os.access(path, os.W_OK) or not os.access(path.parent, os.W_OK):
            raise PermissionError(f"the package's cost file {path} is not writable (an installed package?): write elsewhere with --out FILE")
    with atomic_path(Path(path)) as temporary:
        temporary.write_text(costs.to_json(), encoding="utf-8")
    return Path(path)


def engine_scale(layout: Layout) -> float:
    """(N / 2)^2 K: an engine's cost per period on ``layout`` (N coordinates, K stops) relative to the paper's
    layout's, on which the costs are calibrated."""
    return (layout.size / 2.0) ** 2 * len(layout.stops)
