"""The runner's overhead against the work of a block, for the compiled exact engine whose points cost milliseconds:
the scheduler's cost per task and the store's write per block, each a share of the smallest simulated block's work,
measured as ratios in one run (a benchmark, in the ``cluster`` tier)."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from vibroimpact.scene import parse_scene
from vibroimpact.kinds.stepped.blocks import SIMULATED_POINTS, plan_blocks
from vibroimpact.runs.runner import Runner, _run_cases
from vibroimpact.kinds.stepped.study import general_block
from vibroimpact.runs.store import StudyStore

from tests.study.test_estimate import small_scene

pytestmark = [pytest.mark.cluster, pytest.mark.timeout(300)]

#: Empty tasks timed through a local cluster of two workers.
TASKS = 400


def _exact_scene():
    """The design map's settings on one row of it: the exact engine started by shooting, 0.1 Hz steps."""
    document = small_scene() | {
        "stop": {"clearance": 0.002},
        "sweep": {"restitution": [0.2, 0.7], "frequency": {"start": 18.0, "stop": 42.0, "step": 0.1}},
        "solutions": ["linear", "pgf", "exact"],
        "quantities": ["x1_amplitude", "x2_amplitude", "force_amplitude", "impulse", "regime", "stable", "impacts_per_period", "converged", "peak_acceleration", "wall_time"],
        "simulation": {"start": "shooting", "rtol": 1e-8, "atol": 1e-12, "tolerance": 1e-7, "max_periods": 100, "lyapunov_periods": 256},
    }
    return parse_scene(document)


def test_the_runner_costs_under_a_tenth_of_an_exact_block(tmp_path: Path) -> None:
    scene = _exact_scene()
    general_block(scene, Runner(progress=False))  # compile and warm the caches
    started = time.perf_counter()
    block = general_block(scene, Runner(progress=False))
    points = scene.settings.restitution.size * scene.settings.simulation.frequency.size
    per_point = (time.perf_counter() - started) / points  # closed forms included: what a block of the grid costs
    smallest = SIMULATED_POINTS[0] * per_point

    with Runner(jobs=2, progress=False) as runner:
        runner.run_tasks(_run_cases, None, [[]] * 20, [1.0] * 20, "tasks", lambda index, result: None)  # warm
        started = time.perf_counter()
        runner.run_tasks(_run_cases, None, [[]] * TASKS, [1.0] * TASKS, "tasks", lambda index, result: None)
        per_task = (time.perf_counter() - started) / TASKS

    store = StudyStore(tmp_path / "s.zarr", "overhead")
    plan = plan_blocks(scene, 2)
    variables = {name: (tuple(map(str, v.dims)), np.asarray(v.values), dict(v.attrs)) for name, v in block.data_vars.items()}
    from vibroimpact.kinds.stepped.blocks import _template

    store.begin_grid(_template(variables, dict(zip(("restitution", "clearance", "bumper_frequency", "sweep", "frequency"), plan.full)) | {"solution": 3}, {"frequency": plan.full[-1]}), 10, (plan.full, plan.block))
    started = time.perf_counter()
    for index in range(10):
        store.write_block(index, {}, {name: (dims, values) for name, (dims, values, _attrs) in variables.items()})
    per_write = (time.perf_counter() - started) / 10  # per block, whatever its size: a call per variable
    largest = SIMULATED_POINTS[1] * per_point
    message = f"exact point {per_point * 1e3:.2f} ms, task {per_task * 1e3:.2f} ms, store write per block {per_write * 1e3:.2f} ms, smallest block {smallest * 1e3:.0f} ms"
    print(message)
    assert per_task < 0.1 * smallest, message  # the scheduler, for every block size
    # the store's write runs in the main process while the workers compute: under a tenth of the largest blocks'
    # work (the design map's), a larger share of the smallest (a small study, whose blocks are few)
    assert per_write < 0.1 * largest, message
