"""Predict a scene's wall time and memory before running it (``run-study SCENE --estimate``), and calibrate the costs
the prediction rests on (``run-study calibrate ACCURACY.nc``).

The prediction multiplies what the scene asks for by costs measured on the calibration machine (the package's
``costs.json``, :mod:`vibroimpact.study.cost_model`, written by ``run-study calibrate`` from the ``accuracy_cost``
study); each kind of study (:mod:`vibroimpact.study.kinds`) sums its own work:

* closed forms: seconds per grid point of each solution;
* stepped steady states: seconds per simulated period of each engine at its tolerance (interpolated log-log between
  the measured tolerances) times the periods each point will need, predicted from the closed form: none where the
  answer is the linear state (no integration), a short transient plus the measured periods where a stable one-impact
  orbit exists, and ``max_periods`` plus the irregular measurement elsewhere (motion that may never settle);
* swept sines: seconds per simulated second of the compliant engine at its tolerance;
* benchmarks: every method at every tolerance, as the benchmark runs them;
* the work is spread over ``jobs`` processes; the report adds a fixed cost per figure;
* everything is scaled by this machine's speed against the calibration machine's: a probe of about 0.25 s (the same
  short ``exact`` and ``momentary`` runs, timed at calibration too) measures it, so a slower or busier machine gets a
  longer prediction.

Memory: the dataset (every variable over the full grid, the running estimates of sweeps), the samples a sweep holds
while it runs, and the measured footprint of one worker process. It is an estimate: the report of
``accuracy_cost`` and ``tests/study/test_estimate.py`` compare it with measured runs.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.scene.schema import Scene
from vibroimpact.study.cost_model import COSTS_FILE, Costs, Estimate, default_costs
from vibroimpact.study.io import atomic_path
from vibroimpact.study.kinds import study_kind

__all__ = ["Estimate", "estimate_scene", "speed_probe", "speed_factor", "calibrate", "write_costs", "SPEED_FACTOR_RANGE"]

#: Bounds of the machine-speed factor: a probe outside them is a glitch rather than a machine.
SPEED_FACTOR_RANGE = (0.2, 10.0)


def speed_probe(repeats: int = 3) -> float:
    """Wall time of a fixed short workload, the best of ``repeats`` [s]: 100 periods of ``exact`` and 100 of
    ``momentary`` (CVODE Adams, rtol 1e-8) at 25 Hz from rest, the kind of work the simulations spend their time on."""
    import time

    from vibroimpact.engines.registry import make_engine
    from vibroimpact.engines.settings import STEPPED_TOLERANCES, EngineSettings
    from vibroimpact.model.contact import RigidStop
    from vibroimpact.model.excitation import HarmonicForce
    from vibroimpact.model.problem import ImpactProblem
    from vibroimpact.model.system import PAPER_SYSTEM

    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(3e-3, 0.2), HarmonicForce(10.0, 25.0))
    engines = (make_engine("exact"), make_engine("momentary", EngineSettings(*STEPPED_TOLERANCES)))
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
    costs = default_costs() if costs is None else costs
    low, high = SPEED_FACTOR_RANGE
    return min(max(_probe_time() / costs.speed_probe_seconds, low), high)


def estimate_scene(scene: Scene, jobs: int = 1, speed: float | None = None, costs: Costs | None = None) -> Estimate:
    """Predict the wall time and peak memory of running ``scene`` with ``jobs`` processes.

    ``speed`` is the machine-speed factor (this machine's time over the calibration machine's); by default it is
    measured with :func:`speed_factor`. ``costs`` are the calibrated costs, by default the package's."""
    jobs = max(1, jobs)
    costs = default_costs() if costs is None else costs
    speed = speed_factor(costs) if speed is None else speed
    unscaled = study_kind(scene).estimate(scene, jobs, costs)
    return Estimate(
        wall_time=unscaled.wall_time * speed,
        memory=unscaled.memory,
        parts={name: seconds * speed for name, seconds in unscaled.parts.items()},
        points=unscaled.points,
        speed_factor=speed,
    )


def calibrate(accuracy: Path, base: Costs | None = None) -> Costs:
    """Costs from an ``accuracy_cost`` dataset: per period of the stepped one-impact case, per simulated second of
    the swept case, for each method and tolerance; the closed-form and fixed costs are kept from ``base`` (by default
    the package's costs); the speed probe is timed on this machine, the one that measured the costs.

    Raises
    ------
    OSError
        If ``accuracy`` cannot be read.
    ValueError
        If it is not a dataset of the ``accuracy_cost`` study (a stepped ``one_impact`` case and a ``swept`` case).
    """
    with xr.open_dataset(accuracy) as data:
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
    base = default_costs() if base is None else base
    # the speed probe on the machine that measured the costs
    return dataclasses.replace(base, per_period=per_period, per_sweep_second=per_sweep, speed_probe_seconds=speed_probe())


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
