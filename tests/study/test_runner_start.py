"""A study whose kind shares its work among dask workers starts them before it imports the kind's code, and they import
their libraries meanwhile; a kind that runs in the study's process (a benchmark's timings, a validation) starts none."""

from __future__ import annotations

import sys
import time

import pytest

from vibroimpact.runs import run as run_module
from vibroimpact.runs.cluster import WORKER_LIBRARIES
from vibroimpact.runs.runner import Runner
from vibroimpact.scene.kinds import KINDS, kind_named
from vibroimpact.scene import load_scene, shipped_studies_dir


def _libraries_loaded() -> bool:
    return all(name in sys.modules for name in WORKER_LIBRARIES)


def test_started_workers_import_their_libraries_before_any_task(capsys: pytest.CaptureFixture[str]) -> None:
    with Runner(jobs=2, progress=True) as runner:
        runner.start()
        assert runner._connection is not None  # started now, not at the first task
        assert capsys.readouterr().err == "starting 2 worker processes\n"  # the start's wait is said before it
        client = runner.connection.client
        deadline = time.monotonic() + 60.0
        loaded = client.run(_libraries_loaded)  # type: ignore[attr-defined]
        while not all(loaded.values()) and time.monotonic() < deadline:
            time.sleep(0.2)
            loaded = client.run(_libraries_loaded)  # type: ignore[attr-defined]
        assert len(loaded) == 2 and all(loaded.values()), loaded


def test_one_process_starts_no_cluster() -> None:
    runner = Runner(jobs=1, progress=False)
    runner.start()
    assert runner._connection is None


def test_only_kinds_run_in_the_study_process_start_no_workers(monkeypatch: pytest.MonkeyPatch) -> None:
    """run_study starts the cluster before importing a kind's code only for a kind that shares its work: a
    validation scene with --jobs 2 runs with no cluster (its timings undisturbed by starting workers)."""
    assert {kind.name for kind in KINDS if not kind.shares_work} == {"benchmark", "validation"}
    started: list[int] = []
    monkeypatch.setattr(Runner, "start", lambda self: started.append(self.jobs))
    scene = load_scene(shipped_studies_dir() / "validation" / "zeno.yaml")
    assert not kind_named(scene.kind).shares_work
    run_module.run_study(scene, progress=None, jobs=2)
    assert started == []
