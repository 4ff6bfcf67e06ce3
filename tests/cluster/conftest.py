"""A real dask cluster on loopback for the ``cluster`` tier: a ``dask scheduler`` and ``dask worker`` processes started
with the venv's own ``dask`` command, each in its own process group (so that a test can kill one of them, with all of
its children, as a crash would), always torn down at the end of the test that started them; the study scene these
tests run; and ``run-study`` started as a terminal's foreground job."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from tests.run_study_process import stored_blocks
from tests.scene.test_scene import base_scene, write_yaml

#: The venv's ``dask`` command (the same dask and distributed as the study's own process).
DASK = Path(sys.executable).parent / "dask"
#: How long a scheduler or worker may take to start (import dask, numba, bind a port) on a busy 2-core machine [s].
START_TIMEOUT = 60.0
#: How long a process may take to end after SIGKILL [s].
KILL_TIMEOUT = 10.0
#: The study's name (its files: ``<out>/cluster.nc``, ``<out>/cluster.zarr``).
SCENE_NAME = "cluster"


def cluster_scene(folder: Path) -> Path:
    """The paper's system, restitution 0.2 and 0.6, 20-40 Hz: closed forms on a 0.05 Hz grid, the exact engine on
    every 0.2 Hz (from the PGF orbit), no report. 2 x 101 simulated points in blocks of the smallest size
    (``blocks.SIMULATED_POINTS[0]``, 16 or 32): 8-14 blocks of ~0.3-1 s each, the same plan for 1 and for 2 workers."""
    document = base_scene()
    document.update(
        name=SCENE_NAME,
        stop={"clearance": 0.003},
        sweep={"restitution": [0.2, 0.6], "frequency": {"start": 20.0, "stop": 40.0, "step": 0.05}},
        solutions=["linear", "pgf", "exact"],
        simulation={"start": "pgf", "frequency": {"start": 20.0, "stop": 40.0, "step": 0.2}},
        report=False,
    )
    return write_yaml(folder / f"{SCENE_NAME}.yaml", document)


def finished_blocks(out: Path) -> int:
    """Blocks flagged done in the study's zarr store under ``out`` (0 before the store or its flags exist)."""
    return stored_blocks(out / f"{SCENE_NAME}.zarr")


def wait_for_blocks(run: subprocess.Popen[str], out: Path, timeout: float = 120.0) -> int:
    """Wait until the running study under ``out`` has finished at least one block (or has ended); the count."""
    deadline = time.monotonic() + timeout
    while (done := finished_blocks(out)) == 0 and run.poll() is None:
        if time.monotonic() > deadline:
            raise TimeoutError(f"no block finished within {timeout:.0f} s")
        time.sleep(0.02)
    return done


def kill_group(process: subprocess.Popen[str]) -> None:
    """SIGKILL ``process``'s whole process group (its children too) and reap it."""
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass  # already gone with its group
    try:
        process.wait(timeout=KILL_TIMEOUT)
    except subprocess.TimeoutExpired:
        pass  # a zombie that cannot be reaped is left to init; nothing of it runs any more


@dataclass
class DaskCluster:
    """A ``dask scheduler`` and its ``dask worker`` processes (one single-threaded worker process each, no nanny: a
    worker killed stays dead, as a lost machine), all on 127.0.0.1 and logging into ``folder``."""

    folder: Path
    scheduler: subprocess.Popen[str] | None = None
    workers: list[subprocess.Popen[str]] = field(default_factory=list)
    address: str = ""

    def _spawn(self, arguments: list[str], log_name: str) -> subprocess.Popen[str]:
        log = open(self.folder / log_name, "w", encoding="utf-8")  # the child writes it; closed here once passed on
        try:
            return subprocess.Popen([str(DASK), *arguments], cwd=self.folder, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, text=True, start_new_session=True)
        finally:
            log.close()

    def start_scheduler(self, port: int = 0) -> str:
        """Start the scheduler on loopback ``port`` (0: a free one); its address, read from its scheduler file."""
        scheduler_file = self.folder / "scheduler.json"
        scheduler_file.unlink(missing_ok=True)
        self.scheduler = self._spawn(["scheduler", "--host", "127.0.0.1", "--port", str(port), "--dashboard-address", "127.0.0.1:0", "--scheduler-file", str(scheduler_file)], "scheduler.log")
        deadline = time.monotonic() + START_TIMEOUT
        while True:
            try:
                self.address = json.loads(scheduler_file.read_text(encoding="utf-8"))["address"]
                return self.address
            except (FileNotFoundError, json.JSONDecodeError, KeyError):
                pass  # not written yet, or half-written
            if self.scheduler.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"the dask scheduler did not start: {(self.folder / 'scheduler.log').read_text()}")
            time.sleep(0.1)

    def add_workers(self, count: int) -> None:
        """Start ``count`` workers and wait until the scheduler knows all of this cluster's live workers."""
        for _ in range(count):
            arguments = ["worker", self.address, "--nworkers", "1", "--nthreads", "1", "--host", "127.0.0.1", "--dashboard-address", "127.0.0.1:0", "--no-nanny"]
            self.workers.append(self._spawn(arguments, f"worker-{len(self.workers)}.log"))
        self.wait_for_workers(sum(1 for worker in self.workers if worker.poll() is None))

    def wait_for_workers(self, count: int) -> None:
        """Wait until the scheduler lists ``count`` workers (no more, no fewer: a killed worker is seen to be gone)."""
        from distributed import Client

        deadline = time.monotonic() + START_TIMEOUT
        with Client(self.address, timeout=START_TIMEOUT, set_as_default=False) as client:
            while (listed := len(client.scheduler_info(n_workers=-1)["workers"])) != count:
                if time.monotonic() > deadline:
                    raise RuntimeError(f"the dask scheduler lists {listed} workers, not {count}, after {START_TIMEOUT:.0f} s")
                time.sleep(0.1)

    def kill_scheduler(self) -> None:
        """SIGKILL the scheduler's process group, as a crash of its machine."""
        if self.scheduler is not None:
            kill_group(self.scheduler)

    def close(self) -> None:
        """Kill every process of this cluster (workers first) and reap them."""
        for worker in self.workers:
            kill_group(worker)
        self.kill_scheduler()


@contextmanager
def running_cluster(folder: Path, workers: int) -> Iterator[DaskCluster]:
    """A scheduler on loopback and ``workers`` single-threaded workers (0: none), running and registered, their files
    in ``folder``; killed on leaving."""
    folder.mkdir()
    cluster = DaskCluster(folder)
    try:
        cluster.start_scheduler()
        if workers:
            cluster.add_workers(workers)
        yield cluster
    finally:
        cluster.close()


@pytest.fixture
def dask_cluster(tmp_path: Path) -> Iterator[DaskCluster]:
    """A scheduler and two single-threaded workers, running and registered; killed at the end of the test."""
    with running_cluster(tmp_path / "dask", 2) as cluster:
        yield cluster
