"""Benchmark studies: every engine at every tolerance on a few cases, timed against a reference
(:mod:`vibroimpact.benchmarks.accuracy`); dimensions (case, engine, rtol). A general scene's dataset also records its
structure, load and stops (:func:`vibroimpact.study.grid.layout_attributes`), which its page reads back."""

from __future__ import annotations


import xarray as xr

from vibroimpact.benchmarks.accuracy import SLOW_RUN, run_benchmark
from vibroimpact.scene.schema import Scene
from vibroimpact.study.cost_model import Costs, Estimate
from vibroimpact.study.general_estimate import engine_scale
from vibroimpact.study.grid import Progress, layout_attributes
from vibroimpact.study.io import provenance
from vibroimpact.study.runner import Runner

__all__ = ["BenchmarkStudy"]


class BenchmarkStudy:
    """The accuracy and cost of engines on a scene's benchmark cases."""

    name = "benchmark"

    def run(self, scene: Scene, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """Every method at every tolerance on every case, in this process (timings are compared with each other:
        ``runner`` is not used)."""
        assert scene.benchmark is not None
        dataset = run_benchmark(list(scene.benchmark.cases), scene.benchmark.settings, progress=progress is not None)
        dataset.attrs.update({"title": f"vibroimpact benchmark '{scene.name}'", "scene_name": scene.name, "scene": scene.text} | provenance())
        if scene.general:
            dataset.attrs.update(layout_attributes(scene) | {"excitation_amplitude_N": scene.amplitude})
        return dataset

    def estimate(self, scene: Scene, jobs: int, costs: Costs) -> Estimate:
        """Every method at every tolerance (loose to tight), repeated unless a run is slow, and no tighter tolerance
        after a run over the scene's time limit, as :func:`vibroimpact.benchmarks.accuracy.run_benchmark` does; on the
        calibration machine, scaled for a general layout's coordinates and stops."""
        assert scene.benchmark is not None
        bench = scene.benchmark
        scale = engine_scale(scene)
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
