"""Smaller misuse cases of issue 34, item 8: a dask scheduler without workers is refused in one line within a bounded
wait, leaving no store (before: ``TimeoutError: No valid workers found`` after 30-46 s, exit 1, an empty store
left)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from vibroimpact import cli
from vibroimpact.runs import cluster, runner
from vibroimpact.runs.cluster import ClusterLost
from vibroimpact.runs.runner import Runner

from tests.cluster.conftest import DaskCluster
from tests.test_cli_runner import _scene_file

pytestmark = pytest.mark.faults


@pytest.fixture
def idle_scheduler(tmp_path: Path) -> Iterator[str]:
    """The address of a ``dask scheduler`` on loopback with no worker; killed at the end of the test."""
    folder = tmp_path / "dask"
    folder.mkdir()
    scheduler = DaskCluster(folder)
    try:
        yield scheduler.start_scheduler()
    finally:
        scheduler.close()


@pytest.mark.timeout(180)
def test_a_scheduler_without_workers_is_refused_in_one_line_and_leaves_no_store(tmp_path: Path, idle_scheduler: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(cluster, "WORKER_WAIT", 1.0, raising=False)  # the bounded wait for a worker to join [s]
    out = tmp_path / "out"
    code = cli.main([str(_scene_file(tmp_path)), "--scheduler", idle_scheduler, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == cli.EXIT_BAD_INPUT, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"run-study: error: cannot reach the dask scheduler at {idle_scheduler}"), err
    assert f"it has no workers: none joined within 1 s (start some with 'dask worker {idle_scheduler}'" in lines[0], err
    assert not out.exists()


@pytest.mark.timeout(180)
def test_a_runner_on_a_scheduler_without_workers_gives_up_naming_it(idle_scheduler: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The check at run time (the workers gone between the command's check and the work, or ``run_study`` called
    with a scheduler): :class:`ClusterLost` naming the scheduler, not dask's ``TimeoutError`` of the broadcast."""
    monkeypatch.setattr(runner, "NO_WORKER_TIMEOUT", 1.0)
    with Runner(scheduler=idle_scheduler, progress=False) as work:
        with pytest.raises(ClusterLost, match=rf"^the dask scheduler at {idle_scheduler} has no workers: none joined within 1 s$"):
            work.run_tasks(_twice, np.arange(3.0), [1.0], [1.0], "points", lambda _index, _result: None)


def _twice(shared: np.ndarray, item: float, _report: object) -> np.ndarray:
    return shared * item * 2.0

