"""Engine cost: the same run through every engine and tolerance, measured in one process against ``exact``.

For each case (frequency, restitution, clearance, start) every method integrates the same span; the ``exact``
engine's trajectory is the reference. Each impact of the reference is matched to the nearest impact of the method
(within 1e-3 of a period); unmatched reference impacts are *missed*, unmatched method impacts *extra*. Errors are
over matched impacts. Wall time is the median of ``repeats`` runs (one run when a run takes more than 5 s). Timings
on shared machines are noisy: read the ratios, measured in the same process run, not the absolute seconds.
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np
import xarray as xr

from .engines import EngineSettings, ExactEngine, ImpactProblem, Trajectory
from .engines.base import Engine
from .engines.momentary import MomentaryEngine
from .engines.scipy_ivp import SolveIvpEngine
from .steady import start_state

__all__ = ["BENCHMARK_METHODS", "BenchmarkCase", "BenchmarkSettings", "run_benchmark", "equal_error_speedup"]

#: Methods a benchmark can compare (``exact`` is always run: it is the reference).
BENCHMARK_METHODS: dict[str, Callable[[EngineSettings], Engine]] = {
    "momentary_adams": lambda s: MomentaryEngine(EngineSettings(rtol=s.rtol, atol=s.atol, method="adams")),
    "momentary_bdf": lambda s: MomentaryEngine(EngineSettings(rtol=s.rtol, atol=s.atol, method="bdf")),
    "solve_ivp_DOP853": lambda s: SolveIvpEngine(s, "DOP853"),
    "solve_ivp_LSODA": lambda s: SolveIvpEngine(s, "LSODA"),
    "solve_ivp_Radau": lambda s: SolveIvpEngine(s, "Radau"),
    "solve_ivp_RK45": lambda s: SolveIvpEngine(s, "RK45"),
}
SLOW_RUN = 5.0  # [s] a run longer than this is not repeated


@dataclass(frozen=True)
class BenchmarkCase:
    """One benchmark run: the problem, where it starts and how long it lasts.

    Attributes
    ----------
    name : str
        Label of the case.
    problem : ImpactProblem
        System, stop and excitation.
    start : str
        ``rest`` or ``linear`` (see :func:`vibroimpact.steady.start_state`).
    periods : int
        Whole periods integrated.
    """

    name: str
    problem: ImpactProblem
    start: str
    periods: int


@dataclass(frozen=True)
class BenchmarkSettings:
    """What to compare.

    Attributes
    ----------
    methods : tuple of str
        Keys of :data:`BENCHMARK_METHODS`.
    tolerances : tuple of float
        Relative tolerances; atol = rtol * ``atol_ratio`` [m, m s-1].
    atol_ratio : float
        Absolute tolerance per unit of relative tolerance [m].
    repeats : int
        Runs per point (median wall time).
    max_seconds : dict
        Per method, the largest run time allowed: tighter tolerances of a method are skipped once a run took longer.
    """

    methods: tuple[str, ...]
    tolerances: tuple[float, ...]
    atol_ratio: float = 1e-4
    repeats: int = 3
    max_seconds: float = 60.0


def _compare(reference: Trajectory, trial: Trajectory) -> dict[str, float]:
    """Missed and extra impacts, and errors over matched impacts, of ``trial`` against ``reference``."""
    window = 1e-3 * reference.problem.period
    ref_t, trial_t = reference.impact_times, trial.impact_times
    missed = extra = 0
    time_error = impulse_error = 0.0
    if trial_t.size:
        right = np.clip(np.searchsorted(trial_t, ref_t), 0, trial_t.size - 1)
        left = np.clip(right - 1, 0, trial_t.size - 1)
        nearest = np.where(np.abs(trial_t[left] - ref_t) <= np.abs(trial_t[right] - ref_t), left, right)
        gap = np.abs(trial_t[nearest] - ref_t)
        matched = gap < window
        missed = int(np.sum(~matched))
        extra = int(trial_t.size - np.unique(nearest[matched]).size)
        if matched.any():
            time_error = float(gap[matched].max())
            impulse_error = float(np.max(np.abs(trial.impulses[nearest[matched]] - reference.impulses[matched]) / reference.impulses[matched]))
    else:
        missed = int(ref_t.size)
    scale = np.abs(reference.strobe_states).max(axis=0) + 1e-300
    state_error = float(np.max(np.abs(trial.final_state - reference.final_state) / scale))
    return {"missed_impacts": missed, "extra_impacts": extra, "impact_time_error": time_error, "impulse_error": impulse_error, "final_state_error": state_error}


def _timed(engine: Engine, case: BenchmarkCase, repeats: int) -> tuple[Trajectory, float]:
    t0, y0 = start_state(case.problem, case.start)
    times = []
    trajectory = None
    for _ in range(repeats):
        started = time.perf_counter()
        trajectory = engine.integrate(case.problem, y0, t0, case.periods)
        times.append(time.perf_counter() - started)
        if times[-1] > SLOW_RUN:
            break
    assert trajectory is not None
    return trajectory, statistics.median(times)


def run_benchmark(cases: list[BenchmarkCase], settings: BenchmarkSettings, progress: bool = True) -> xr.Dataset:
    """Every method at every tolerance on every case; returns a Dataset with dimensions (case, engine, rtol).

    The dimensions are called ``engine`` and ``rtol``, not ``method`` and ``tolerance``, which clash with the
    keyword arguments of ``Dataset.sel``.
    """
    shape = (len(cases), len(settings.methods), len(settings.tolerances))
    names = ("wall_time", "rhs_calls", "steps", "impacts", "missed_impacts", "extra_impacts", "impact_time_error", "impulse_error", "final_state_error")
    data = {name: np.full(shape, np.nan) for name in names}
    exact_time = np.full(len(cases), np.nan)
    reference_impacts = np.zeros(len(cases))
    for c, case in enumerate(cases):
        reference, exact_time[c] = _timed(ExactEngine(), case, settings.repeats)
        reference_impacts[c] = reference.impact_times.size
        for m, method in enumerate(settings.methods):
            for k, rtol in enumerate(settings.tolerances):
                engine = BENCHMARK_METHODS[method](EngineSettings(rtol=rtol, atol=rtol * settings.atol_ratio))
                trajectory, wall = _timed(engine, case, settings.repeats)
                values = _compare(reference, trajectory) | {
                    "wall_time": wall,
                    "rhs_calls": trajectory.stats.get("rhs_calls", np.nan),
                    "steps": trajectory.stats.get("steps", np.nan),
                    "impacts": trajectory.impact_times.size,
                }
                for name in names:
                    data[name][c, m, k] = values[name]
                if progress:
                    print(f"benchmark {case.name}: {method} rtol {rtol:g}: {wall:.3f} s, missed {values['missed_impacts']}", file=sys.stderr, flush=True)
                if wall > settings.max_seconds:
                    break  # tighter tolerances would only take longer
    attrs = {
        "wall_time": ("s", "median wall time of one run"),
        "rhs_calls": ("1", "right-hand-side evaluations"),
        "steps": ("1", "integrator steps (not available from scikit-sundae in normal mode: NaN)"),
        "impacts": ("1", "impacts found"),
        "missed_impacts": ("1", "impacts of the exact reference not found within 1e-3 of a period"),
        "extra_impacts": ("1", "impacts found that the exact reference does not have"),
        "impact_time_error": ("s", "largest impact-time error over matched impacts"),
        "impulse_error": ("1", "largest relative impulse error over matched impacts"),
        "final_state_error": ("1", "error of the final state relative to the reference's largest values"),
    }
    dataset = xr.Dataset(
        {name: (("case", "engine", "rtol"), data[name], {"units": attrs[name][0], "long_name": attrs[name][1]}) for name in names},
        coords={"case": [c.name for c in cases], "engine": list(settings.methods), "rtol": list(settings.tolerances)},
    )
    dataset["exact_wall_time"] = (("case",), exact_time, {"units": "s", "long_name": "median wall time of the exact reference"})
    dataset["reference_impacts"] = (("case",), reference_impacts, {"units": "1", "long_name": "impacts of the exact reference"})
    dataset["rtol"].attrs.update({"units": "1", "long_name": "relative tolerance rtol (atol = rtol x atol_ratio)"})
    dataset.attrs["atol_ratio_m"] = settings.atol_ratio
    dataset.attrs["repeats"] = settings.repeats
    return dataset


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
