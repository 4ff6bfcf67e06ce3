"""Predict a scene's wall time and memory before running it (``run-study SCENE --estimate``).

The prediction multiplies what the scene asks for by costs measured on this machine kind
(:mod:`vibroimpact.cost_table`, written by ``python -m vibroimpact.estimate --calibrate ACCURACY.nc`` from the
``accuracy_cost`` study):

* closed forms: seconds per grid point of each solution;
* stepped steady states: seconds per simulated period of each engine at its tolerance (interpolated log-log between
  the measured tolerances) times the periods each point will need, predicted from the closed form: none where the
  answer is the linear state (no integration), a short transient plus the measured periods where a stable one-impact
  orbit exists, and ``max_periods`` plus the irregular measurement elsewhere (motion that may never settle);
* swept sines: seconds per simulated second of the compliant engine at its tolerance;
* the work is spread over ``jobs`` processes; the report adds a fixed cost per figure;
* everything is scaled by this machine's speed against the calibration machine's: a probe of about 0.25 s (the same
  short ``exact`` and ``momentary`` runs, timed at calibration too) measures it, so a slower or busier machine gets a
  longer prediction.

Memory: the dataset (every variable over the full grid, the running estimates of sweeps), the samples a sweep holds
while it runs, and the measured footprint of one worker process. It is an estimate: the report of
``accuracy_cost`` and ``tests/test_estimate.py`` compare it with measured runs.
"""

from __future__ import annotations

import argparse
import functools
import math
import pprint
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vibroimpact.study.cost_table import COSTS
from vibroimpact.scene.core import ENGINE_SOLUTIONS, Scene

__all__ = ["Estimate", "estimate_scene", "per_period_cost", "calibrate"]

#: Periods of a transient that settles on a stable orbit (two convergence chunks), before the measurement.
SETTLING_PERIODS = 40
#: Bounds of the machine-speed factor: a probe outside them is a glitch rather than a machine.
SPEED_FACTOR_RANGE = (0.2, 10.0)
#: Engine names of the cost table for each time-domain solution (momentary by its CVODE family).
_ENGINE_KEYS = {"exact": "exact", "compliant": "compliant_ida"}


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


def speed_probe(repeats: int = 3) -> float:
    """Wall time of a fixed short workload, the best of ``repeats`` [s]: 100 periods of ``exact`` and 100 of
    ``momentary`` (CVODE Adams, rtol 1e-8) at 25 Hz from rest, the kind of work the simulations spend their time on."""
    import time

    from vibroimpact.engines.exact import ExactEngine

    from vibroimpact.engines.base import ImpactProblem

    from vibroimpact.engines.settings import EngineSettings
    from vibroimpact.engines.momentary import MomentaryEngine
    from vibroimpact.model.system import PAPER_SYSTEM

    problem = ImpactProblem(PAPER_SYSTEM, 3e-3, 0.2, 10.0, 25.0)
    engines = (ExactEngine(), MomentaryEngine(EngineSettings(rtol=1e-8, atol=1e-12)))
    best = math.inf
    for _ in range(repeats):
        started = time.perf_counter()
        for engine in engines:
            engine.integrate(problem, np.zeros(4), 0.0, 100)
        best = min(best, time.perf_counter() - started)
    return best


@functools.cache
def speed_factor() -> float:
    """This machine's probe time over the calibration machine's [-], within :data:`SPEED_FACTOR_RANGE`; measured once
    per process (the accuracy report estimates every shipped study)."""
    low, high = SPEED_FACTOR_RANGE
    return min(max(speed_probe() / COSTS["speed_probe_seconds"], low), high)


def per_period_cost(engine: str, rtol: float) -> float:
    """Measured wall time of one simulated period of a stepped run of ``engine`` at ``rtol`` [s]."""
    table = COSTS["per_period"][engine]
    if isinstance(table, float):
        return table  # exact: no tolerance
    return _interpolate(table, rtol)


def per_sweep_second_cost(engine: str, rtol: float) -> float:
    """Measured wall time per simulated second of a swept-sine run at ``rtol`` [s s-1]."""
    return _interpolate(COSTS["per_sweep_second"][engine], rtol)


def _interpolate(table: dict[float, float], rtol: float) -> float:
    tolerances = np.array(sorted(table))
    seconds = np.array([table[t] for t in tolerances])
    return float(np.exp(np.interp(np.log(rtol), np.log(tolerances), np.log(seconds))))


def estimate_scene(scene: Scene, jobs: int = 1, speed: float | None = None) -> Estimate:
    """Predict the wall time and peak memory of running ``scene`` with ``jobs`` processes.

    ``speed`` is the machine-speed factor (this machine's time over the calibration machine's); by default it is
    measured with :func:`speed_factor`."""
    jobs = max(1, jobs)
    speed = speed_factor() if speed is None else speed
    unscaled = _estimate_benchmark(scene) if scene.benchmark is not None else _estimate_study(scene, jobs)
    return Estimate(
        wall_time=unscaled.wall_time * speed,
        memory=unscaled.memory,
        parts={name: seconds * speed for name, seconds in unscaled.parts.items()},
        points=unscaled.points,
        speed_factor=speed,
    )


def _estimate_study(scene: Scene, jobs: int) -> Estimate:
    """The estimate of a regular (not benchmark) scene on the calibration machine."""
    parts: dict[str, float] = {}
    points: dict[str, str] = {}
    frequency = scene.all_frequencies
    bumpers = scene.bumper_frequency.size if scene.bumper_frequency is not None else 1
    directions = max(1, len(scene.sweep_directions))
    grid = scene.restitution.size * scene.clearance.size * frequency.size
    closed_form = 0.0
    simulated = 0.0
    biggest_case = 0.0
    for name in scene.solutions:
        if name not in ENGINE_SOLUTIONS:
            seconds = COSTS["closed_form_per_point"][name] * grid * (bumpers if name == "pgf" and scene.bumper_frequency is not None else 1)
            parts[name] = seconds
            closed_form += seconds
            continue
        assert scene.simulation is not None
        rtol = scene.simulation.engine.rtol
        key = _ENGINE_KEYS.get(name, f"momentary_{scene.simulation.engine.method}")
        if scene.swept_sine is not None:
            s = scene.swept_sine
            duration = abs(s.stop_frequency - s.start_frequency) / s.rate
            one = per_sweep_second_cost(key, rtol) * duration
            runs = scene.restitution.size * scene.clearance.size * bumpers * directions
            parts[name] = one * runs
            points[name] = f"{runs} sweeps of {duration:g} s"
            biggest_case = max(biggest_case, one)
        else:
            periods, scale = _periods(scene)
            copies = bumpers if name == "compliant" else 1
            total_periods = float(periods.sum()) * scale * copies
            seconds = per_period_cost(key, rtol) * total_periods
            parts[name] = seconds
            integrated = int(np.count_nonzero(periods) * scale) * copies
            points[name] = f"{scene.restitution.size * scene.clearance.size * scene.simulation.frequency.size * copies} points, ~{integrated} integrated, ~{total_periods:.0f} periods"
            if scene.simulation.start in ("sweep_up", "sweep_down"):  # one serial chain per (R, Delta, bumper)
                biggest_case = max(biggest_case, seconds / (scene.restitution.size * scene.clearance.size * copies))
        simulated += parts[name]
    report = 0.0
    if scene.report:
        report = COSTS["report_base"] + COSTS["report_per_figure"] * _figures(scene)
        parts["report"] = report
    wall = COSTS["startup"] + closed_form + max(simulated / min(jobs, os_cpus()), biggest_case) + report
    return Estimate(wall_time=wall, memory=_memory(scene, jobs), parts=parts, points=points)


def os_cpus() -> int:
    """Processes that really run at once (the machine's cores)."""
    import os

    return os.cpu_count() or 1


#: Largest number of simulated points whose closed form is solved for the estimate (a larger grid is subsampled).
ESTIMATE_POINTS = 20_000


def _periods(scene: Scene) -> tuple[np.ndarray, float]:
    """Periods each simulated (restitution, clearance, frequency) point is predicted to integrate, on the grid or on
    an evenly subsampled frequency grid, and the factor that scales its sum to the whole grid.

    As :func:`vibroimpact.steady.steady_state` and :func:`vibroimpact.simulate.run_case` do: ``linear`` and stepped
    sweeps answer a point whose linear motion fits without integrating; ``pgf`` also needs no admissible one-impact
    orbit there; a stable orbit settles in a short transient; elsewhere the motion may never settle (``max_periods``
    plus the irregular measurement). From ``rest`` every point integrates, and the lightly damped transient of the
    linear modes (damping ratios ~1e-3) outlasts ``max_periods``.
    """
    from vibroimpact.analysis.pgf import solve_one_impact
    from vibroimpact.analysis.stability import floquet_multipliers

    assert scene.simulation is not None
    sim = scene.simulation
    per_line = max(1, ESTIMATE_POINTS // (scene.restitution.size * scene.clearance.size))
    frequencies = sim.frequency if sim.frequency.size <= per_line else sim.frequency[np.linspace(0, sim.frequency.size - 1, per_line).astype(int)]
    scale = sim.frequency.size / frequencies.size
    steady = sim.steady
    wander = steady.max_periods + steady.irregular_measure_periods
    shape = (scene.restitution.size, scene.clearance.size, frequencies.size)
    if sim.start == "rest":
        return np.full(shape, float(wander)), scale
    omega = 2.0 * np.pi * frequencies[None, None, :]
    orbit = solve_one_impact(scene.system, omega, scene.clearance[None, :, None], scene.restitution[:, None, None], scene.amplitude)
    admissible = orbit.admissible()
    stable = np.zeros(admissible.shape, dtype=bool)
    if admissible.any():
        modulus = np.max(np.abs(floquet_multipliers(orbit)), axis=-1)
        stable = admissible & (modulus < 1.0)
    fits = orbit.linear_amplitude_x2 <= orbit.clearance
    settle = SETTLING_PERIODS + steady.measure_periods
    if sim.start in ("sweep_up", "sweep_down"):
        # a chain: a fitting point is answered linear unless the point before it impacted (then it integrates from
        # there, and keeps impacting where a one-impact orbit coexists with the linear motion)
        order = range(frequencies.size) if sim.start == "sweep_up" else range(frequencies.size - 1, -1, -1)
        no_integration = np.zeros(shape, dtype=bool)
        impacting = np.zeros(shape[:2], dtype=bool)
        for k in order:
            no_integration[..., k] = fits[..., k] & ~impacting
            impacting = ~fits[..., k] | (impacting & admissible[..., k])
    else:
        no_integration = fits & ~admissible if sim.start == "pgf" else fits
    return np.where(no_integration, 0, np.where(stable, settle, wander)).astype(float), scale


def _figures(scene: Scene) -> int:
    if scene.swept_sine is not None:
        return 4
    per_clearance = 12 if any(s in ENGINE_SOLUTIONS for s in scene.solutions) else 7
    return 1 + per_clearance * scene.clearance.size + (2 if len(scene.swept) > 1 else 0)


def _memory(scene: Scene, jobs: int) -> float:
    """Peak memory of the run, main process and workers [bytes]: the main process's footprint and its dataset (built,
    stacked, written: ~3 copies), one worker footprint per process simulating, and the samples of one sweep per
    worker."""
    frequency = scene.all_frequencies
    bumpers = scene.bumper_frequency.size if scene.bumper_frequency is not None else 1
    directions = max(1, len(scene.sweep_directions))
    cells = scene.restitution.size * scene.clearance.size * bumpers * directions * frequency.size
    dataset = 3.0 * 8.0 * len(scene.quantities) * len(scene.solutions) * cells
    simulating = any(name in ENGINE_SOLUTIONS for name in scene.solutions)
    workers = min(jobs, os_cpus()) if simulating and jobs > 1 else 0
    sweep = 0.0
    if scene.swept_sine is not None:
        s = scene.swept_sine
        samples = abs(s.stop_frequency - s.start_frequency) / s.rate * s.sample_rate
        sweep = samples * 8.0 * 16 * max(1, workers)  # samples, cumulative integrals and temporaries of the estimators
    return COSTS["main_process_memory"] + dataset + workers * COSTS["worker_process_memory"] + sweep


def _estimate_benchmark(scene: Scene) -> Estimate:
    """Benchmarks: every method at every tolerance (loose to tight), repeated unless a run is slow, and no tighter
    tolerance after a run over the scene's time limit, as :func:`vibroimpact.benchmark.run_benchmark` does."""
    from vibroimpact.benchmarks.accuracy import SLOW_RUN

    assert scene.benchmark is not None
    bench = scene.benchmark
    total = 0.0
    for case in bench.cases:
        periods = case.periods if case.sweep is None else case.sweep.duration * case.sweep.start_frequency
        total += per_period_cost("exact", 0.0) * periods * bench.settings.repeats
        for method in bench.settings.methods:
            if not case.runs(method):
                continue
            for rtol in bench.settings.tolerances:
                if case.sweep is not None:
                    key = method if method in COSTS["per_sweep_second"] else "compliant_ida"
                    one = per_sweep_second_cost(key, rtol) * case.sweep.duration
                else:
                    key = method if method in COSTS["per_period"] else "momentary_adams"
                    one = per_period_cost(key, rtol) * periods
                total += one * (1 if one > SLOW_RUN else bench.settings.repeats)
                if one > bench.settings.max_seconds:
                    break
    return Estimate(wall_time=COSTS["startup"] + total, memory=COSTS["main_process_memory"], parts={"benchmark": total})


def _duration(seconds: float) -> str:
    if seconds < 120.0:
        return f"{seconds:.0f} s"
    if seconds < 7200.0:
        return f"{seconds / 60.0:.1f} min"
    return f"{seconds / 3600.0:.1f} h"


def calibrate(accuracy: Path) -> dict[str, object]:
    """Costs from an ``accuracy_cost`` dataset: per period of the stepped one-impact case, per simulated second of
    the swept case, for each method and tolerance; the fixed costs are kept from the current table."""
    import xarray as xr

    with xr.open_dataset(accuracy) as data:
        stepped = next(str(c) for c in data["case"].values if "one_impact" in str(c))
        swept = next(str(c) for c in data["case"].values if "swept" in str(c))
        duration = float(data.attrs.get(f"case_{stepped}_duration_s", 2.0))
        frequency = float(data.attrs.get(f"case_{stepped}_frequency_Hz", 25.0))
        sweep_duration = float(data.attrs.get(f"case_{swept}_duration_s", 10.0))
        periods = duration * frequency
        per_period: dict[str, object] = {"exact": float(data["reference_wall_time"].sel(case=stepped, reference="exact")) / periods}
        per_sweep: dict[str, object] = {}
        for method in data["engine"].values:
            for case, target, scale in ((stepped, per_period, periods), (swept, per_sweep, sweep_duration)):
                line = data["wall_time"].sel(case=case, engine=method)
                table = {float(t): float(w) / scale for t, w in zip(line["rtol"].values, line.values) if math.isfinite(float(w))}
                if table:
                    target[str(method)] = table
    costs = dict(COSTS)
    costs["per_period"] = per_period
    costs["per_sweep_second"] = per_sweep
    costs["speed_probe_seconds"] = speed_probe()  # on the machine that measured the costs
    return costs


def main(argv: list[str] | None = None) -> int:
    """``python -m vibroimpact.estimate --calibrate ACCURACY.nc``: rewrite :mod:`vibroimpact.cost_table`."""
    parser = argparse.ArgumentParser(prog="python -m vibroimpact.estimate", description=__doc__.split("\n")[0])
    parser.add_argument("--calibrate", type=Path, required=True, help="dataset of the accuracy_cost study")
    args = parser.parse_args(argv)
    costs = calibrate(args.calibrate)
    target = Path(__file__).with_name("cost_table.py")
    header = '"""Measured costs for :mod:`vibroimpact.estimate` (written by ``python -m vibroimpact.estimate --calibrate``)."""\n\n'
    target.write_text(header + "COSTS: dict = " + pprint.pformat(costs, width=120, sort_dicts=True) + "\n", encoding="utf-8")
    print(f"wrote {target}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
