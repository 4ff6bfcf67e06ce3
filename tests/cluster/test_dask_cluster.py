"""``run-study`` on a real dask cluster (a ``dask scheduler`` and two single-threaded ``dask worker`` processes on
loopback): the results equal the serial run's, through ``--scheduler`` and ``VIBROIMPACT_SCHEDULER``, with a worker
killed half-way, after Ctrl-C and a rerun, after the scheduler is lost and a rerun; a second study on the same output
is refused while the first runs."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact.runs.run import read_dataset
from vibroimpact.scene import load_scene
from vibroimpact.kinds.stepped.blocks import BlockPlan, plan_blocks

from tests.cluster.conftest import SCENE_NAME, DaskCluster, cluster_scene, finished_blocks, kill_group, wait_for_blocks
from tests.run_study_process import start_run_study, study_environment

pytestmark = pytest.mark.cluster

#: Variables that measure this machine, not the study (they differ between any two runs).
MEASURED = {"wall_time"}
#: Longest a study of :func:`cluster_scene` may take here, however loaded the machine [s] (it takes ~3-10 s).
STUDY_TIMEOUT = 180.0
#: Longest ``run-study`` may take to end after Ctrl-C or after losing its scheduler [s].
END_TIMEOUT = 60.0


@dataclass(frozen=True)
class Reference:
    """The serial run of the scene: where it is, its results and its block plan."""

    scene: Path
    dataset: xr.Dataset
    plan: BlockPlan


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Reference:
    """``run-study SCENE --jobs 1 --out ref``: the results every cluster run must reproduce."""
    folder = tmp_path_factory.mktemp("serial")
    scene = cluster_scene(folder)
    completed = subprocess.run([sys.executable, "-m", "vibroimpact.cli", str(scene), "--jobs", "1", "--out", "ref"], cwd=folder, capture_output=True, text=True, env=study_environment(), timeout=STUDY_TIMEOUT)
    assert completed.returncode == 0, completed.stderr
    plan = plan_blocks(load_scene(scene), 1)
    assert 8 <= plan.count <= 20, plan  # enough blocks to interrupt between two, few enough to stay quick
    return Reference(scene, read_dataset(folder / "ref" / f"{SCENE_NAME}.nc"), plan)


def study_scene(folder: Path, reference: Reference) -> Path:
    """The scene written into ``folder`` (a study's own folder), checked to be split like the serial run's: two
    single-threaded workers make the same block plan as one, so every value must be the same, bit for bit."""
    scene = cluster_scene(folder)
    assert scene.read_text(encoding="utf-8") == reference.scene.read_text(encoding="utf-8")
    assert plan_blocks(load_scene(scene), 2) == reference.plan, "the plans differ: values summed in another order may differ by an ulp"
    return scene


def assert_same_results(path: Path, reference: Reference) -> xr.Dataset:
    """The dataset at ``path`` has the serial run's coordinates and variables with the same values (NaN where it has
    NaN), except the measured ones; returns it."""
    dataset = read_dataset(path)  # the groups joined: the simulations on every frequency, as the serial run
    expected = reference.dataset
    assert set(dataset.variables) == set(expected.variables)
    for name in sorted(set(expected.variables) - MEASURED):
        assert dataset[name].dims == expected[name].dims, name
        np.testing.assert_array_equal(dataset[name].values, expected[name].values, err_msg=f"{name} differs from the serial run's (same block plan: must be identical)")
    return dataset


def progress_done(stderr: str) -> int:
    """The work done shown by the first progress line (``simulating [...] 46/202 points, ...``)."""
    first = next(line for line in stderr.splitlines() if line.startswith("simulating ["))
    return int(first.split("] ")[1].split("/")[0])


def kept_line(store: str, kept: int) -> str:
    """How ``run-study`` names the finished blocks it keeps."""
    return f"{kept} finished block{'s' if kept != 1 else ''} kept in {store}; run the same command to resume"


def run_to_end(run: subprocess.Popen[str], timeout: float = STUDY_TIMEOUT) -> tuple[str, str]:
    """``run``'s stdout and stderr once it has ended (killed, with its group, if it takes longer than ``timeout``)."""
    try:
        return run.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        kill_group(run)
        out, err = run.communicate()
        pytest.fail(f"run-study did not end within {timeout:.0f} s; stderr:\n{err}")


@pytest.mark.timeout(300)
def test_a_study_through_a_named_scheduler_equals_the_serial_run(tmp_path: Path, dask_cluster: DaskCluster, reference: Reference) -> None:
    """``--scheduler ADDRESS`` and ``VIBROIMPACT_SCHEDULER=ADDRESS``: the scheduler's workers solve every block, the
    netCDF holds the serial run's values, names the scheduler, and the zarr store is deleted."""
    scene = study_scene(tmp_path, reference)
    runs = {
        "option": start_run_study([str(scene), "--scheduler", dask_cluster.address, "--out", "option"], tmp_path),
        "environment": start_run_study([str(scene), "--out", "environment"], tmp_path, scheduler_variable=dask_cluster.address),
    }
    for out, run in runs.items():  # both at once: they share the two workers
        stdout, stderr = run_to_end(run)
        assert run.returncode == 0, stderr
        assert "Traceback" not in stderr, stderr
        assert f"wrote {out}/{SCENE_NAME}.nc" in stdout.splitlines()
        dataset = assert_same_results(tmp_path / out / f"{SCENE_NAME}.nc", reference)
        assert dataset.attrs["run_scheduler"] == dask_cluster.address
        assert not (tmp_path / out / f"{SCENE_NAME}.zarr").exists()
        assert not (tmp_path / out / ".run-study.lock").exists()


@pytest.mark.timeout(300)
def test_a_worker_killed_half_way_loses_nothing(tmp_path: Path, dask_cluster: DaskCluster, reference: Reference) -> None:
    """SIGKILL one of the two workers (no nanny: it stays dead) once a block is done: the scheduler runs its tasks on
    the other worker, the study ends normally and its results equal the serial run's."""
    scene = study_scene(tmp_path, reference)
    run = start_run_study([str(scene), "--scheduler", dask_cluster.address, "--out", "out"], tmp_path)
    done = wait_for_blocks(run, tmp_path / "out")
    assert run.poll() is None and 1 <= done < reference.plan.count, f"the study ended before a worker could be killed ({done} blocks)"
    kill_group(dask_cluster.workers[0])
    stdout, stderr = run_to_end(run)
    assert run.returncode == 0, stderr
    assert "Traceback" not in stderr, stderr
    assert_same_results(tmp_path / "out" / f"{SCENE_NAME}.nc", reference)
    dask_cluster.wait_for_workers(1)  # the scheduler knows one worker now ...
    assert dask_cluster.workers[0].returncode == -signal.SIGKILL and dask_cluster.workers[1].poll() is None  # ... the other


@pytest.mark.timeout(300)
def test_ctrl_c_keeps_the_finished_blocks_and_the_same_command_resumes(tmp_path: Path, dask_cluster: DaskCluster, reference: Reference) -> None:
    """Ctrl-C (SIGINT to run-study's process group; the workers run elsewhere): exit 130 with one line saying what
    was kept, no traceback; the same command then starts from the kept blocks and ends with the serial run's
    values."""
    scene = study_scene(tmp_path, reference)
    arguments = [str(scene), "--scheduler", dask_cluster.address, "--out", "out"]
    run = start_run_study(arguments, tmp_path)
    done = wait_for_blocks(run, tmp_path / "out")
    assert run.poll() is None and done < reference.plan.count, f"the study ended before Ctrl-C ({done} blocks)"
    os.killpg(run.pid, signal.SIGINT)
    _stdout, stderr = run_to_end(run, END_TIMEOUT)
    kept = finished_blocks(tmp_path / "out")
    assert run.returncode == 130, stderr
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr
    assert stderr.rstrip().splitlines()[-1] == f"interrupted: {kept_line(f'out/{SCENE_NAME}.zarr', kept)}", stderr
    assert 1 <= kept < reference.plan.count
    assert not (tmp_path / "out" / ".run-study.lock").exists()
    rerun = start_run_study(arguments, tmp_path)
    _stdout, stderr = run_to_end(rerun)
    assert rerun.returncode == 0, stderr
    assert progress_done(stderr) > 0, stderr  # the kept blocks count as done from the start
    assert_same_results(tmp_path / "out" / f"{SCENE_NAME}.nc", reference)
    assert not (tmp_path / "out" / f"{SCENE_NAME}.zarr").exists()


@dataclass(frozen=True)
class LostScheduler:
    """A study whose scheduler was killed half-way: its folder, command, what it printed and kept."""

    folder: Path
    arguments: list[str]
    address: str
    port: int
    returncode: int
    stderr: str
    kept: int


@pytest.fixture(scope="module")
def lost_scheduler(tmp_path_factory: pytest.TempPathFactory, reference: Reference) -> LostScheduler:
    """``run-study --scheduler ADDRESS`` whose scheduler is SIGKILLed once a block is done (the workers, without a
    nanny, end with it); every dask process is gone afterwards."""
    folder = tmp_path_factory.mktemp("lost")
    scene = study_scene(folder, reference)
    (folder / "dask").mkdir()
    cluster = DaskCluster(folder / "dask")
    try:
        address = cluster.start_scheduler()
        cluster.add_workers(2)
        arguments = [str(scene), "--scheduler", address, "--out", "out"]
        run = start_run_study(arguments, folder)
        done = wait_for_blocks(run, folder / "out")
        assert run.poll() is None and done < reference.plan.count, f"the study ended before its scheduler was lost ({done} blocks)"
        cluster.kill_scheduler()
        _stdout, stderr = run_to_end(run, END_TIMEOUT)  # fails the test if the study hangs on the lost scheduler
    finally:
        cluster.close()
    return LostScheduler(folder, arguments, address, int(address.rsplit(":", 1)[1]), run.returncode, stderr, finished_blocks(folder / "out"))


@pytest.mark.timeout(300)
def test_a_lost_scheduler_ends_the_study_and_a_restarted_one_resumes_it(lost_scheduler: LostScheduler, reference: Reference) -> None:
    """Losing the scheduler ends run-study at once (exit 1, the lock released, the finished blocks kept); a scheduler
    restarted at the same address with one worker: the same command resumes from the kept blocks and ends with the
    serial run's values."""
    folder = lost_scheduler.folder
    assert lost_scheduler.returncode == 1, lost_scheduler.stderr
    assert 1 <= lost_scheduler.kept < reference.plan.count
    assert not (folder / "out" / ".run-study.lock").exists()
    assert not (folder / "out" / f"{SCENE_NAME}.nc").exists()
    (folder / "restarted").mkdir()
    cluster = DaskCluster(folder / "restarted")
    try:
        assert cluster.start_scheduler(port=lost_scheduler.port) == lost_scheduler.address
        cluster.add_workers(1)
        rerun = start_run_study(lost_scheduler.arguments, folder)
        _stdout, stderr = run_to_end(rerun)
    finally:
        cluster.close()
    assert rerun.returncode == 0, stderr
    assert "Traceback" not in stderr, stderr
    assert progress_done(stderr) > 0, stderr
    assert_same_results(folder / "out" / f"{SCENE_NAME}.nc", reference)
    assert not (folder / "out" / f"{SCENE_NAME}.zarr").exists()


@pytest.mark.timeout(120)
def test_a_lost_scheduler_is_told_in_one_line(lost_scheduler: LostScheduler) -> None:
    """The run that lost its scheduler ends with one line naming the scheduler and the kept blocks, and prints no
    traceback (neither its own nor one logged by distributed)."""
    lines = lost_scheduler.stderr.rstrip().splitlines()
    assert lines[-1].startswith(f"run-study: lost the dask scheduler at {lost_scheduler.address}"), lost_scheduler.stderr
    assert lines[-1].endswith(f": {kept_line(f'out/{SCENE_NAME}.zarr', lost_scheduler.kept)}"), lost_scheduler.stderr
    assert "Traceback" not in lost_scheduler.stderr, lost_scheduler.stderr


@pytest.mark.timeout(300)
def test_a_second_study_on_the_same_output_is_refused_while_the_first_runs(tmp_path: Path, dask_cluster: DaskCluster, reference: Reference) -> None:
    """A second run-study on the same --out exits 2 at once, naming the first (its process, host, start); the first
    is held (SIGSTOP) meanwhile so that it cannot end first, and then finishes with the serial run's values."""
    scene = study_scene(tmp_path, reference)
    arguments = [str(scene), "--scheduler", dask_cluster.address, "--out", "out"]
    first = start_run_study(arguments, tmp_path)
    wait_for_blocks(first, tmp_path / "out")
    assert first.poll() is None, "the first study ended before the second started"
    os.killpg(first.pid, signal.SIGSTOP)
    try:
        second = subprocess.run([sys.executable, "-m", "vibroimpact.cli", *arguments], cwd=tmp_path, capture_output=True, text=True, env=study_environment(), timeout=END_TIMEOUT)
    finally:
        os.killpg(first.pid, signal.SIGCONT)
    assert second.returncode == 2, second.stderr
    assert second.stderr.rstrip().splitlines()[-1].startswith(f"run-study: error: out is being written by another run-study (process {first.pid} on {socket.gethostname()}, since ")
    assert "Traceback" not in second.stderr and second.stdout == ""
    _stdout, stderr = run_to_end(first)
    assert first.returncode == 0, stderr
    assert_same_results(tmp_path / "out" / f"{SCENE_NAME}.nc", reference)
    assert not (tmp_path / "out" / ".run-study.lock").exists()
