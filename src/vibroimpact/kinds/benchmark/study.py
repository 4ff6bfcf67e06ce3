"""Benchmark studies: every engine at every tolerance on a few cases, timed against a reference
(:mod:`vibroimpact.kinds.benchmark.study`); dimensions (case, engine, rtol). A general scene's dataset also records its
structure, load and stops (:meth:`vibroimpact.model.layout.Layout.attributes`), which its page reads back."""

from __future__ import annotations

import math
import re
import statistics
import sys
import time
from dataclasses import replace
from typing import Any, Callable, TypeVar, cast

import numpy as np
import xarray as xr

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.engines.base import Engine, SweepRecord, Trajectory
from vibroimpact.engines.compliant.ivp import solve_ivp_sweep
from vibroimpact.engines.registry import BUMPER, ENGINES, RIGID, engine_for, engine_spec, make_engine
from vibroimpact.engines.settings import REFERENCE_RTOL, EngineSettings
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.runs.cluster import Progress
from vibroimpact.runs.estimate import Costs, Estimate, engine_scale
from vibroimpact.runs.runner import Runner
from vibroimpact.kinds.benchmark.scene import BenchmarkCase, BenchmarkSettings, LadderSettings
from vibroimpact.scene.schema import Scene
from vibroimpact.model.layout import Layout
from vibroimpact.kinds.benchmark.variables import BENCHMARK_ATTRIBUTES, LADDER_ATTRIBUTES
from vibroimpact.reporting.solutions import closed_form_methods
from vibroimpact.simulation.harmonics import measure, running_fundamental
from vibroimpact.simulation.steady import start_state

__all__ = ["run_benchmark", "REFERENCES", "model_ladder", "equal_error_speedup", "loosest_tolerance", "exact_kernel", "measured_names", "REFERENCE_RTOL", "TOLERANCE_FREE", "BenchmarkStudy"]


# --------------------------------------------------------------------------------------------------------------------
# Accuracy and cost: the same run through every engine and tolerance, measured in one process against a reference.
# --------------------------------------------------------------------------------------------------------------------

SLOW_RUN = 5.0  # [s] a run longer than this is not repeated
#: Engines whose runs ignore rtol and atol: measured once per case, stored at every tolerance.
TOLERANCE_FREE = frozenset(name for name, spec in ENGINES.items() if spec.capabilities.tolerance_free)

_T = TypeVar("_T")


def _compare(reference: Trajectory, trial: Trajectory, period: float) -> dict[str, float]:
    """Missed and extra impacts, and errors over matched impacts, of ``trial`` against ``reference``.

    Matching is one to one: candidate pairs (each reference impact with its nearest trial impacts on either side)
    closer than the window, 1e-3 of the case's ``period`` [s], are taken greedily from the closest, each impact used
    once; unmatched reference impacts are missed, unmatched trial impacts extra.
    """
    window = 1e-3 * period
    ref_t, trial_t = reference.impact_times, trial.impact_times
    time_error = impulse_error = 0.0
    pairs: list[tuple[float, int, int]] = []
    if trial_t.size and ref_t.size:
        right = np.searchsorted(trial_t, ref_t)
        for i, r in enumerate(right):
            for j in (r - 1, r, r + 1):
                if 0 <= j < trial_t.size and abs(trial_t[j] - ref_t[i]) < window:
                    pairs.append((abs(trial_t[j] - ref_t[i]), i, j))
    pairs.sort()
    used_ref, used_trial, matched = set(), set(), []
    for gap, i, j in pairs:
        if i not in used_ref and j not in used_trial:
            used_ref.add(i)
            used_trial.add(j)
            matched.append((gap, i, j))
    if matched:
        gaps, ref_index, trial_index = (np.array(column) for column in zip(*matched))
        time_error = float(gaps.max())
        impulse_error = float(np.max(np.abs(trial.impulses[trial_index] - reference.impulses[ref_index]) / reference.impulses[ref_index]))
    missed, extra = int(ref_t.size - len(matched)), int(trial_t.size - len(matched))
    scale = np.abs(reference.strobe_states).max(axis=0) + 1e-300
    state_error = float(np.max(np.abs(trial.final_state - reference.final_state) / scale))
    return {"missed_impacts": missed, "extra_impacts": extra, "impact_time_error": time_error, "impulse_error": impulse_error, "final_state_error": state_error}


#: The coordinate whose fundamental the benchmark compares: the first (the paper's primary mass X1).
MEASURED = 0
#: The errors that are not of the measured fundamental.
_OTHER_ERRORS = ("impact_time_error", "impulse_error", "final_state_error")


def measured_names(coordinate: str) -> dict[str, str]:
    """The benchmark's variables named after the measured coordinate (``x1_error`` ... for the paper's ``x1``), by
    their name in :data:`~vibroimpact.kinds.benchmark.variables.BENCHMARK_ATTRIBUTES` and ``LADDER_ATTRIBUTES``."""
    return {template: template.replace("x1", coordinate, 1) for template in ("x1_error", "reference_x1", "ladder_x1_amplitude", "ladder_x1_difference")}


def _attributes(template: str, coordinate: str) -> dict[str, str]:
    """The attributes of a measured variable, the coordinate named (X1 for the paper's ``x1``)."""
    attrs = dict(BENCHMARK_ATTRIBUTES.get(template) or LADDER_ATTRIBUTES[template])
    label = coordinate.upper() if re.fullmatch(r"x[0-9]+", coordinate) else coordinate
    attrs["long_name"] = attrs["long_name"].replace("X1", label)
    return attrs


class _Run:
    """What one timed run returns: the trajectory, and the fundamental of the measured coordinate (a sweep: its
    running fundamental)."""

    def __init__(self, trajectory: Trajectory, fundamental: np.ndarray) -> None:
        self.trajectory, self.fundamental = trajectory, fundamental


def _fundamental_of(trajectory: Trajectory) -> np.ndarray:
    return np.array([abs(measure(trajectory).displacements[MEASURED])]) if trajectory.periods else np.array([np.nan])


def _runner(case: BenchmarkCase, method: str, settings: EngineSettings) -> Callable[[], _Run]:
    """A function doing one run of ``method`` on ``case``."""
    problem = case.problem
    if case.sweep is not None:
        sweep = case.sweep

        def from_record(record: SweepRecord) -> _Run:
            return _Run(record.trajectory, running_fundamental(record.time, record.displacements[:, MEASURED], sweep, cycles=8).amplitude)

        assert case.bumper is not None
        swept = ImpactProblem(problem.system, case.bumper, sweep)
        if engine_spec(method).contact == BUMPER:
            engine = make_engine(method, settings)
            return lambda: from_record(engine.sweep(swept, case.sample_rate))
        ivp = method.removeprefix("solve_ivp_")
        return lambda: from_record(solve_ivp_sweep(swept, case.sample_rate, ivp, settings.rtol, settings.atol))
    t0, y0 = start_state(problem, case.start)  # the rigid stop's start, for the compliant model too
    stepped: Engine = make_engine(method, settings)
    if engine_spec(method).contact == BUMPER:
        assert case.bumper is not None
        problem = replace(problem, contact=case.bumper)

    def run() -> _Run:
        trajectory = stepped.integrate(problem, y0, t0, case.periods, moments=True)
        return _Run(trajectory, _fundamental_of(trajectory))

    return run


def _timed(run: Callable[[], _T], repeats: int) -> tuple[_T, float]:
    """The last result of ``run`` and the median wall time [s] of up to ``repeats`` calls (one after a slow run)."""
    ((result, wall),) = _timed_together([run], repeats)
    return cast(_T, result), wall


def _timed_together(runs: list[Callable[[], Any]], repeats: int) -> list[tuple[Any, float]]:
    """Each of ``runs`` called in turn, ``repeats`` rounds (one round more only while no run took over 5 s), so that a
    change of the machine's load falls on all of them alike: the last result of each and its median wall time [s]."""
    times: list[list[float]] = [[] for _ in runs]
    results: list[Any] = []
    while not times[0] or (len(times[0]) < repeats and max(t[-1] for t in times) <= SLOW_RUN):
        results = []
        for run, record in zip(runs, times):
            started = time.perf_counter()
            results.append(run())
            record.append(time.perf_counter() - started)
    return [(result, statistics.median(record)) for result, record in zip(results, times)]


def exact_kernel(case: BenchmarkCase, moments: bool = True) -> Callable[[], int]:
    """A function running the exact engine's compiled kernel alone on ``case``'s stepped run; it returns the status.

    :func:`vibroimpact.engines.exact_core.run_periods` is called with the arguments the engine prepares for the
    problem (prepared here, once) and the run's start and periods, ``moments`` as the reference run asks for them
    (True) or not: no engine object, no checks, no :class:`Trajectory`. What the reference costs beyond this is the
    engine's Python face: this is its floor.
    """
    from vibroimpact.engines import exact_core
    from vibroimpact.engines.exact import loop_setup  # the engine's own per-problem preparation

    t0, y0 = start_state(case.problem, case.start)
    arguments = loop_setup(case.problem, EngineSettings()).arguments
    state = np.ascontiguousarray(y0, dtype=float)

    def kernel() -> int:
        status = exact_core.run_periods(*arguments, state, float(t0), int(case.periods), moments, False, False).status
        if status != exact_core.STATUS_OK:
            raise RuntimeError(f"benchmark case {case.name}: the exact kernel made no progress")
        return int(status)

    return kernel


#: The references, by the model they measure: the rigid stop's and the bumper's closed forms (the first registered
#: engine with an exact flow for each contact law, :func:`~vibroimpact.engines.registry.engine_for`: the compiled one,
#: which the registry lists before its pure-Python cross-check), and for a swept sine (no closed form: a chirp has no
#: closed-form particular solution) CVODE Adams at REFERENCE_RTOL; the dataset's ``reference`` coordinate, in this
#: order.
REFERENCES = {"rigid": engine_for(RIGID, "exact_flow"), "bumper": engine_for(BUMPER, "exact_flow"), "swept": "compliant_cvode_adams"}


def _model(case: BenchmarkCase, method: str) -> str:
    """The key of :data:`REFERENCES` that ``method``'s runs on ``case`` are measured against."""
    return "swept" if case.sweep is not None else "bumper" if engine_spec(method).contact == BUMPER else "rigid"


def _references(case: BenchmarkCase, settings: BenchmarkSettings) -> tuple[dict[str, tuple[_Run, float]], list[float]]:
    """The references a case needs, by :data:`REFERENCES` key: the rigid stop's closed form (rigid methods, stepped
    cases), the bumper's (compliant methods, stepped cases), both timed as the methods are (median of the repeats,
    compiled code loaded untimed first), and CVODE Adams at REFERENCE_RTOL (swept cases, run once); and the wall
    times [s] of the exact kernel alone with the moments and without (stepped cases; NaN otherwise), timed in turn
    with the rigid reference."""
    references: dict[str, tuple[_Run, float]] = {}
    floors = [math.nan, math.nan]
    if case.sweep is None:
        t0, y0 = start_state(case.problem, case.start)
        rigid = make_engine(REFERENCES["rigid"])

        def exact() -> _Run:
            trajectory = rigid.integrate(case.problem, y0, t0, case.periods, moments=True)
            return _Run(trajectory, _fundamental_of(trajectory))

        rigid.integrate(case.problem, y0, t0, 1, moments=True)  # untimed: loads the compiled kernel
        kernels = [exact_kernel(case, moments) for moments in (True, False)]
        timed = _timed_together([exact, *kernels], settings.repeats)
        references["rigid"] = timed[0]
        floors = [wall for _, wall in timed[1:]]
    models = {_model(case, m) for m in settings.methods if case.runs(m)}
    if "bumper" in models:
        closed = _runner(case, REFERENCES["bumper"], EngineSettings())
        _runner(replace(case, periods=1), REFERENCES["bumper"], EngineSettings())()  # untimed: loads the compiled loop
        references["bumper"] = _timed(closed, settings.repeats)
    if "swept" in models:
        tight = EngineSettings(rtol=REFERENCE_RTOL, atol=REFERENCE_RTOL * settings.atol_ratio, method="adams")
        references["swept"] = _timed(_runner(case, REFERENCES["swept"], tight), 1)
    return references, floors


def run_benchmark(cases: list[BenchmarkCase], settings: BenchmarkSettings, progress: bool = True) -> xr.Dataset:
    """Every method at every tolerance on every case; returns a Dataset with dimensions (case, engine, rtol).

    The dimensions are called ``engine`` and ``rtol``, not ``method`` and ``tolerance``, which clash with the
    keyword arguments of ``Dataset.sel``. Methods that do not apply to a case (a compliant method without a bumper,
    a rigid-stop engine on a swept case) are NaN there.
    """
    shape = (len(cases), len(settings.methods), len(settings.tolerances))
    coordinate = str(cases[0].problem.structure.coordinates[MEASURED]) if cases else "x1"
    measured = measured_names(coordinate)
    names = ("wall_time", "rhs_calls", "steps", "impacts", "missed_impacts", "extra_impacts", "impact_time_error", "impulse_error", "final_state_error", "x1_error")
    data = {name: np.full(shape, np.nan) for name in names}
    reference_time, reference_impacts, reference_x1 = (np.full((len(cases), len(REFERENCES)), np.nan) for _ in range(3))
    periods = np.array([np.nan if case.sweep is not None else float(case.periods) for case in cases])
    floors = np.full((len(cases), 2), np.nan)  # [s] the exact kernel alone: with the moments, without
    for c, case in enumerate(cases):
        references, floors[c] = _references(case, settings)
        if case.sweep is None:
            if progress:
                per_period = 1e6 / case.periods
                print(
                    f"benchmark {case.name}: exact {references['rigid'][1] * per_period:.2f} us/period, its compiled kernel alone "
                    f"{floors[c, 0] * per_period:.2f} (without moments {floors[c, 1] * per_period:.2f})",
                    file=sys.stderr,
                    flush=True,
                )
        for r, kind in enumerate(REFERENCES):
            if kind in references:
                reference, reference_time[c, r] = references[kind]
                reference_impacts[c, r] = reference.trajectory.impact_times.size
                reference_x1[c, r] = float(np.nanmax(reference.fundamental))
        for m, method in enumerate(settings.methods):
            if not case.runs(method):
                continue
            reference = references[_model(case, method)][0]
            for k, rtol in enumerate(settings.tolerances):
                if method in TOLERANCE_FREE and k:  # the same run at every tolerance: measured once
                    for name in names:
                        data[name][c, m, k] = data[name][c, m, 0]
                    continue
                run, wall = _timed(_runner(case, method, EngineSettings(rtol=rtol, atol=rtol * settings.atol_ratio)), settings.repeats)
                trajectory = run.trajectory
                scale = float(np.nanmax(reference.fundamental))
                values = _compare(reference.trajectory, trajectory, case.problem.period) | {
                    "wall_time": wall,
                    "rhs_calls": trajectory.stats.get("rhs_calls", np.nan),
                    "steps": trajectory.stats.get("steps", np.nan),
                    "impacts": trajectory.impact_times.size,
                    "x1_error": float(np.nanmax(np.abs(run.fundamental - reference.fundamental))) / scale if run.fundamental.shape == reference.fundamental.shape else np.nan,
                }
                if case.sweep is not None:
                    values["final_state_error"] = np.nan  # samples, not strobes: x1_error says it
                for name in names:
                    data[name][c, m, k] = values[name]
                if progress:
                    print(f"benchmark {case.name}: {method} rtol {'(none)' if method in TOLERANCE_FREE else format(rtol, 'g')}: {wall:.3f} s, {coordinate} error {values['x1_error']:.1e}, missed {values['missed_impacts']}", file=sys.stderr, flush=True)
                if wall > settings.max_seconds and method not in TOLERANCE_FREE:
                    break  # tighter tolerances would only take longer
    dataset = xr.Dataset(
        {measured.get(name, name): (("case", "engine", "rtol"), data[name], _attributes(name, coordinate)) for name in names},
        coords={"case": [c.name for c in cases], "engine": list(settings.methods), "rtol": list(settings.tolerances), "reference": list(REFERENCES.values())},
    )
    dataset["reference_wall_time"] = (("case", "reference"), reference_time, dict(BENCHMARK_ATTRIBUTES["reference_wall_time"]))
    dataset["reference_impacts"] = (("case", "reference"), reference_impacts, dict(BENCHMARK_ATTRIBUTES["reference_impacts"]))
    dataset[measured["reference_x1"]] = (("case", "reference"), reference_x1, _attributes("reference_x1", coordinate))
    dataset["exact_wall_time"] = dataset["reference_wall_time"].sel(reference="exact", drop=True).assign_attrs(BENCHMARK_ATTRIBUTES["exact_wall_time"])
    dataset["periods"] = ("case", periods, dict(BENCHMARK_ATTRIBUTES["periods"]))
    dataset["time_per_period"] = (dataset["wall_time"] / dataset["periods"]).assign_attrs(BENCHMARK_ATTRIBUTES["time_per_period"])
    dataset["reference_time_per_period"] = (dataset["exact_wall_time"] / dataset["periods"]).assign_attrs(BENCHMARK_ATTRIBUTES["reference_time_per_period"])
    dataset["floor_time_per_period"] = ("case", floors[:, 0] / periods, dict(BENCHMARK_ATTRIBUTES["floor_time_per_period"]))
    dataset["floor_no_moments_time_per_period"] = ("case", floors[:, 1] / periods, dict(BENCHMARK_ATTRIBUTES["floor_no_moments_time_per_period"]))
    for coordinate in ("rtol", "reference"):
        dataset[coordinate].attrs.update(BENCHMARK_ATTRIBUTES[coordinate])
    dataset.attrs["atol_ratio_m"] = settings.atol_ratio
    dataset.attrs["repeats"] = settings.repeats
    dataset.attrs["reference_rtol_compliant"] = REFERENCE_RTOL
    dataset.attrs["tolerance_free_engines"] = " ".join(m for m in settings.methods if m in TOLERANCE_FREE)
    for case in cases:  # what a run simulates, for per-period and per-second costs (vibroimpact.runs.estimate.calibrate)
        dataset.attrs[f"case_{case.name}_duration_s"] = case.sweep.duration if case.sweep is not None else case.periods / case.problem.frequency
        dataset.attrs[f"case_{case.name}_frequency_Hz"] = case.problem.frequency
        if case.bumper is not None:  # the bumpers' Omega_b / 2 pi, for the page's words
            dataset.attrs[f"case_{case.name}_bumper_frequency_Hz"] = " ".join(f"{stop.law.frequency:g}" for stop in replace(case.problem, contact=case.bumper).stops)
    if settings.ladder is not None and cases:
        if progress:
            print("benchmark: model cost ladder", file=sys.stderr, flush=True)
        ladder = model_ladder(settings.ladder, settings.atol_ratio)
        dataset = dataset.merge(ladder, combine_attrs="no_conflicts")
    return dataset


def loosest_tolerance(dataset: xr.Dataset, case: str, method: str, target: float) -> tuple[float, float]:
    """The loosest rtol of ``method`` whose error of the measured fundamental (``<coordinate>_error``, ``x1_error`` on
    the paper's layout) on ``case`` is within ``target`` (no missed or extra impact), with all tighter ones that were
    run too (a method stops at its time limit); returns (rtol, wall time) or (nan, nan)."""
    line = dataset.sel(case=case, engine=method)
    error_name = next(str(n) for n in dataset.data_vars if str(n).endswith("_error") and str(n) not in _OTHER_ERRORS)
    error, missed, extra, wall = line[error_name].values, line["missed_impacts"].values, line["extra_impacts"].values, line["wall_time"].values
    order = [i for i in np.argsort(line["rtol"].values) if np.isfinite(wall[i])]  # tight to loose, the tolerances run
    best = (math.nan, math.nan)
    for i in order:
        if not (np.isfinite(error[i]) and error[i] <= target and missed[i] == 0 and extra[i] == 0):
            break
        best = (float(line["rtol"].values[i]), float(wall[i]))
    return best


def equal_error_speedup(dataset: xr.Dataset, case: str, method: str, tolerance: float, against: list[str]) -> tuple[float, str]:
    """Speed-up of ``method`` at ``tolerance`` over the fastest of ``against`` at the same impact-time error.

    Each competitor's wall time at that error is interpolated log-log between its tolerances; competitors that
    missed impacts at the tolerances used are excluded. Returns (ratio, competitor) or (nan, '').
    """
    point = dataset.sel(case=case, engine=method, rtol=tolerance)
    target = float(point["impact_time_error"])
    if not (target > 0 and float(point["missed_impacts"]) == 0):
        return math.nan, ""
    best, best_name = math.inf, ""
    for other in against:
        line = dataset.sel(case=case, engine=other)
        error = line["impact_time_error"].values
        wall = line["wall_time"].values
        ok = np.isfinite(error) & (error > 0) & (line["missed_impacts"].values == 0)
        if ok.sum() < 2 or not (error[ok].min() <= target <= error[ok].max()):
            continue
        order = np.argsort(np.log(error[ok]))
        needed = float(np.exp(np.interp(np.log(target), np.log(error[ok])[order], np.log(wall[ok])[order])))
        if needed < best:
            best, best_name = needed, other
    if not best_name:
        return math.nan, ""
    return best / float(point["wall_time"]), best_name


def model_ladder(ladder: LadderSettings, atol_ratio: float) -> xr.Dataset:
    """Wall time of one steady-state point and the fundamental of its first coordinate for ``pgf`` (where the layout
    has a closed form), ``exact``, ``momentary`` and ``compliant`` at each bumper frequency, and the relative difference
    from ``exact``; dimension ``model``. ``ladder.problem`` is the structure, load and rigid stops at the point,
    ``ladder.compliant`` the bumpers of each frequency."""
    from vibroimpact.simulation.steady import steady_state
    from vibroimpact.simulation.settings import SteadySettings

    problem = ladder.problem
    assert problem is not None
    coordinate = str(problem.structure.coordinates[MEASURED])
    measured = measured_names(coordinate)
    stops = problem.stops
    settings = EngineSettings(rtol=ladder.rtol, atol=ladder.rtol * atol_ratio)
    steady = SteadySettings(tolerance=max(10.0 * ladder.rtol, 1e-10))
    omega = np.array([problem.omega])

    def pgf() -> float:
        return float(np.abs(solve_impact_orbit(problem, omega=omega).harmonics()[0, MEASURED]))

    models: dict[str, Callable[[], float]] = {"pgf": pgf} if closed_form_refusal(problem) is None else {}
    engines: dict[str, tuple[Engine, ImpactProblem]] = {"exact": (make_engine("exact"), problem), "momentary": (make_engine("momentary", settings), problem)}
    for frequency, bumpers in zip(ladder.bumper_frequencies, ladder.compliant):
        engines[f"compliant_{frequency:g}Hz"] = (make_engine("compliant", settings), replace(problem, contact=bumpers))
    for name, (engine, run_problem) in engines.items():
        # every model starts from the rigid stops' closed-form orbit (a bumper's own R(xi_b) differs in the last
        # digits), the linear motion where the layout has none
        models[name] = lambda engine=engine, run_problem=run_problem: abs(steady_state(engine, run_problem, "pgf", steady, stops).measures.displacements[MEASURED])
    wall, fundamental = [], []
    for name, model in models.items():
        times = []
        for _ in range(ladder.repeats):
            started = time.perf_counter()
            value = model()
            times.append(time.perf_counter() - started)
        wall.append(statistics.median(times))
        fundamental.append(value)
    exact = fundamental[list(models).index("exact")]
    if math.isfinite(ladder.restitution) and math.isfinite(ladder.clearance):
        point = f"{ladder.frequency:g} Hz, R = {ladder.restitution:g}, Delta = {ladder.clearance * 1e3:g} mm"
    else:
        point = f"{ladder.frequency:g} Hz, stops {'; '.join(stop.describe(tuple(problem.structure.coordinates)) + f', R = {stop.law.restitution:g}' for stop in stops)}"
    start = "one-impact orbit" if Layout.of_problem(problem).paper_view() is not None else "closed-form orbit" if "pgf" in models else "linear motion (no closed form for this layout)"
    return xr.Dataset(
        {
            "ladder_wall_time": ("model", wall, dict(LADDER_ATTRIBUTES["ladder_wall_time"])),
            measured["ladder_x1_amplitude"]: ("model", fundamental, _attributes("ladder_x1_amplitude", coordinate)),
            measured["ladder_x1_difference"]: ("model", np.abs(np.array(fundamental) - exact) / exact, _attributes("ladder_x1_difference", coordinate)),
        },
        coords={"model": list(models)},
        attrs={
            "ladder_description": (
                f"{point}; steady states from the slightly perturbed {start}, integrators at rtol {ladder.rtol:g}, "
                f"steady-state tolerance {steady.tolerance:g}; bumpers with the loss factor that gives R. The compliant "
                "differences are the bumper's physics, not error."
            )
        },
    )

class BenchmarkStudy:
    """The accuracy and cost of engines on a scene's benchmark cases."""

    name = "benchmark"

    @staticmethod
    def engines(scene: Any) -> tuple[str, ...]:
        """The benchmarked methods, the references and the model ladder's engines."""
        settings: BenchmarkSettings = scene.settings.settings
        ladder = ("exact", "momentary", "compliant") if settings.ladder is not None else ()
        return tuple(dict.fromkeys((*settings.methods, *REFERENCES.values(), *ladder)))

    def run(self, scene: Scene, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """Every method at every tolerance on every case, in this process (timings are compared with each other:
        ``runner`` is not used)."""
        assert scene.settings is not None
        dataset = run_benchmark(list(scene.settings.cases), scene.settings.settings, progress=progress is not None)
        if scene.layout.paper_view() is None:  # the paper's layout needs no record: its page draws the paper's names
            dataset.attrs.update(scene.layout.attributes(*_shared_values(scene.settings.cases, scene.layout.stops)) | closed_form_methods() | {"excitation_amplitude_N": scene.amplitude})
        return dataset

    def estimate(self, scene: Scene, jobs: int, costs: Costs) -> Estimate:
        """Every method at every tolerance (loose to tight), repeated unless a run is slow, and no tighter tolerance
        after a run over the scene's time limit, as :func:`vibroimpact.kinds.benchmark.study.run_benchmark` does; on the
        calibration machine, scaled for a general layout's coordinates and stops."""
        assert scene.settings is not None
        bench = scene.settings
        scale = engine_scale(scene.layout)
        total = 0.0
        for case in bench.cases:
            periods = case.periods if case.sweep is None else case.sweep.duration * case.sweep.start_frequency
            total += costs.per_period_cost("exact", 0.0) * periods * bench.settings.repeats * scale
            for method in bench.settings.methods:
                if not case.runs(method):
                    continue
                for rtol in bench.settings.tolerances:
                    if case.sweep is not None:
                        key = method if method in costs.per_sweep_second else "compliant_ida"
                        one = costs.per_sweep_second_cost(key, rtol) * case.sweep.duration
                    else:
                        key = method if method in costs.per_period else "momentary_adams"
                        one = costs.per_period_cost(key, rtol) * periods
                    one *= scale
                    total += one * (1 if one > SLOW_RUN else bench.settings.repeats)
                    if one > bench.settings.max_seconds:
                        break
        return Estimate(wall_time=costs.startup + total, memory=costs.main_process_memory, parts={"benchmark": total})


def _shared_values(cases: Any, specs: Any) -> tuple[np.ndarray, np.ndarray]:
    """The restitutions [-] and clearances [m] the cases give the stops that take the study's values: the distinct
    finite ones, sorted ([NaN] where every stop gives its own)."""

    def given(values: Any) -> np.ndarray:
        finite = sorted({float(v) for v in values if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)})
        return np.array(finite) if finite else np.array([math.nan])

    taking_r = [k for k, spec in enumerate(specs) if spec.restitution is None]
    taking_d = [k for k, spec in enumerate(specs) if spec.clearance is None]
    restitution = given(case.problem.stops[k].law.restitution for case in cases for k in taking_r)
    clearance = given(case.problem.stops[k].clearance for case in cases for k in taking_d)
    return restitution, clearance
