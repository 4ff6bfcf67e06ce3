"""A task that kills its worker every time: the scheduler gives up after its allowed failures, and the study says so
in one line (a RuntimeError run-study reports), instead of dask's KilledWorker traceback."""

from __future__ import annotations

import os

import pytest

from vibroimpact.runs.runner import Runner, WorkerDied

pytestmark = [pytest.mark.cluster, pytest.mark.timeout(180)]


def _die(_shared: object, _item: object, _report: object) -> None:
    os._exit(1)  # what a worker killed by the kernel for its memory looks like to dask


def test_a_task_that_kills_every_worker_it_runs_on_ends_the_study_clearly() -> None:
    with Runner(jobs=2, progress=False) as runner:
        with pytest.raises(WorkerDied, match=r"task 0 of 1 killed its worker 3 times"):
            runner.run_tasks(_die, None, [None], [1.0], "tasks", lambda index, result: None)
    assert issubclass(WorkerDied, RuntimeError)  # run-study prints it in one line
