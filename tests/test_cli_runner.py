"""run-study and the dask runner: where the scheduler comes from, an unreachable one refused before any work,
--keep-zarr, --workers for the estimate, a second run on the same output refused, the scene's cluster section."""

from __future__ import annotations

import functools
import os
import socket
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from vibroimpact import cli
from vibroimpact.scene import SceneError, parse_scene
from vibroimpact.runs import cluster
from vibroimpact.runs.cluster import SCHEDULER_VARIABLE, choose_scheduler

from tests.study.test_estimate import small_scene


def _scene_file(folder: Path, **changes: object) -> Path:
    document = small_scene() | {"solutions": ["linear", "pgf"], "name": "tiny"} | changes
    document.pop("simulation", None)
    path = folder / "tiny.yaml"
    path.write_text(yaml.safe_dump(document))
    return path


def test_the_scheduler_comes_from_the_option_then_the_environment_then_the_scene(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(SCHEDULER_VARIABLE, "tcp://env:8786")
    assert choose_scheduler("tcp://option:8786", "tcp://scene:8786") == "tcp://option:8786"
    assert choose_scheduler(None, "tcp://scene:8786") == "tcp://env:8786"
    monkeypatch.delenv(SCHEDULER_VARIABLE)
    assert choose_scheduler(None, "tcp://scene:8786") == "tcp://scene:8786"
    assert choose_scheduler(None, None) is None


def test_the_scene_names_its_cluster() -> None:
    assert parse_scene(small_scene() | {"cluster": {"scheduler": "tcp://head:8786"}}).cluster_scheduler == "tcp://head:8786"
    with pytest.raises(SceneError, match=r"cluster.scheduler: expected a string, got 3 \(int\)"):
        parse_scene(small_scene() | {"cluster": {"scheduler": 3}})
    with pytest.raises(SceneError, match=r"cluster.workers: unknown key \(allowed: scheduler\)"):
        parse_scene(small_scene() | {"cluster": {"scheduler": "tcp://head:8786", "workers": 4}})


def test_an_unreachable_scheduler_is_refused_before_any_work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(cli, "unreachable", functools.partial(cluster.unreachable, timeout=1.0))
    with socket.socket() as probe:  # a loopback port nothing listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    out = tmp_path / "out"
    assert cli.main([str(_scene_file(tmp_path)), "--scheduler", f"tcp://127.0.0.1:{port}", "--out", str(out)]) == cli.EXIT_BAD_INPUT
    assert f"run-study: error: cannot use the dask scheduler at tcp://127.0.0.1:{port}" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("jobs", ["0", "1000", str(cluster.local_worker_limit() + 1)])
def test_a_worker_count_beyond_the_machine_is_refused_before_any_work(tmp_path: Path, capsys: pytest.CaptureFixture[str], jobs: str) -> None:
    """``--jobs 1000`` on a 2-core machine once started 1000 workers and ran out of memory after 341 s: refused at
    once (exit 2, nothing written), naming the option and the range this machine allows."""
    out = tmp_path / "out"
    assert cli.main([str(_scene_file(tmp_path)), "--jobs", jobs, "--out", str(out)]) == cli.EXIT_BAD_INPUT
    said = capsys.readouterr().err
    assert f"--jobs = {jobs} is out of range: allowed an integer in [1, {cluster.local_worker_limit()}] on this machine" in said, said
    assert not out.exists()


@pytest.mark.parametrize("jobs", [0, 1000, 1.5, True])
def test_the_python_runner_refuses_the_same_worker_counts(jobs: object) -> None:
    from vibroimpact.runs.runner import Runner

    with pytest.raises(ValueError, match=r"jobs = .* is out of range: allowed an integer in \[1, "):
        Runner(jobs=jobs, progress=False)  # type: ignore[arg-type]
    assert Runner(jobs=cluster.local_worker_limit(), progress=False).jobs == cluster.local_worker_limit()  # starts nothing yet


def test_keep_zarr_keeps_the_store_beside_the_netcdf_file(tmp_path: Path) -> None:
    scene = _scene_file(tmp_path)
    assert cli.main([str(scene), "--out", str(tmp_path / "kept"), "--jobs", "1", "--keep-zarr"]) == 0
    assert cli.main([str(scene), "--out", str(tmp_path / "plain"), "--jobs", "1"]) == 0
    assert (tmp_path / "kept" / "tiny.zarr").is_dir() and not (tmp_path / "plain" / "tiny.zarr").exists()
    written = xr.load_dataset(tmp_path / "kept" / "tiny.nc")
    stored = xr.open_zarr(tmp_path / "kept" / "tiny.zarr")  # consolidated: opens without a warning
    assert stored.attrs["scene_name"] == "tiny" and stored.attrs["fingerprint"]
    # the store holds the unsqueezed grid: (solution, restitution, clearance, bumper_frequency, sweep, frequency)
    assert stored["x1_amplitude"].shape == (2, 1, 1, 1, 1, written.sizes["frequency"])
    xr.testing.assert_equal(stored["x1_amplitude"].squeeze(drop=True).load().variable, written["x1_amplitude"].variable)
    # labelled: the frequencies, the parameters and the solutions
    np.testing.assert_array_equal(stored["frequency"].values, written["frequency"].values)
    assert list(stored["solution"].values) == ["linear", "pgf"] and stored["clearance"].values.tolist() == [float(written["clearance"])]
    assert not (tmp_path / "kept" / ".run-study.lock").exists()


def test_a_second_run_on_the_same_output_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from vibroimpact.runs.output_files import claim_output

    out = tmp_path / "out"
    out.mkdir()
    with claim_output(out):  # a live run: this process, through another open file
        assert cli.main([str(_scene_file(tmp_path)), "--out", str(out), "--jobs", "1"]) == cli.EXIT_BAD_INPUT
        assert f"is being written by another run-study (process {os.getpid()} on {socket.gethostname()}, since " in capsys.readouterr().err
        assert sorted(p.name for p in out.iterdir()) == [".run-study.lock"]  # nothing written
    assert cli.main([str(_scene_file(tmp_path)), "--out", str(out), "--jobs", "1"]) == 0  # released


def test_the_estimate_is_for_a_number_of_workers(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--workers N spreads the work over N workers of a cluster, beyond this machine's cores."""
    document = small_scene() | {"sweep": {"frequency": {"start": 15.0, "stop": 45.0, "step": 0.01}}}
    path = tmp_path / "big.yaml"
    path.write_text(yaml.safe_dump(document))

    def wall(*options: str) -> float:
        assert cli.main([str(path), "--estimate", *options]) == 0
        text = capsys.readouterr().out
        first = text.splitlines()[0].split("predicted wall time: ")[1].split(";")[0]
        value, unit = first.split()
        return float(value) * {"s": 1.0, "min": 60.0, "h": 3600.0}[unit]

    one, many = wall("--jobs", "1"), wall("--workers", "64")
    assert many < one / 4
    assert cli.main([str(path), "--estimate", "--workers", "0"]) == cli.EXIT_BAD_INPUT


def test_a_worker_running_other_code_refuses_its_tasks(monkeypatch: pytest.MonkeyPatch) -> None:
    """The study's source hash travels with every task; a worker whose package differs raises instead of computing."""
    from vibroimpact.runs import runner as runner_module
    from vibroimpact.runs.runner import OtherCode, Runner, _run_cases

    monkeypatch.setattr(runner_module, "source_hash", lambda: "0" * 64)  # this process "runs other code"
    with Runner(jobs=2, progress=False) as runner:
        with pytest.raises(OtherCode, match=r"the dask worker .* runs vibroimpact .* whose source differs from the study's"):
            runner.run_tasks(_run_cases, None, [[]], [1.0], "tasks", lambda index, result: None)


def test_an_explicit_jobs_runs_here_whatever_the_environment_says(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(SCHEDULER_VARIABLE, "tcp://127.0.0.1:1")  # nothing listens there
    assert cli.main([str(_scene_file(tmp_path)), "--out", str(tmp_path / "out"), "--jobs", "1"]) == 0
    assert xr.load_dataset(tmp_path / "out" / "tiny.nc").attrs["run_scheduler"] == "this process"


def test_workers_is_for_the_estimate(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main([str(_scene_file(tmp_path)), "--out", str(tmp_path / "out"), "--workers", "4"]) == cli.EXIT_BAD_INPUT
    assert "--workers is for --estimate" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()



def test_a_rerun_of_a_finished_run_keeps_its_dataset_or_says_why_not(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A finished run's dataset is this scene's (the same values, the same code): a rerun keeps it as it is and says
    so (a new description changes no number); with a value changed it says why it computes again."""
    out = tmp_path / "out"
    scene = _scene_file(tmp_path)
    assert cli.main([str(scene), "--out", str(out), "--jobs", "1", "--no-report"]) == 0
    dataset = out / "tiny.nc"
    made = dataset.stat().st_mtime_ns
    capsys.readouterr()
    scene = _scene_file(tmp_path, description="the same values, other words")
    assert cli.main([str(scene), "--out", str(out), "--jobs", "1", "--no-report"]) == 0
    said = capsys.readouterr()
    assert f"{dataset}: this scene's finished run (the same values, the same code): kept as it is; remove it to compute again" in said.err
    assert dataset.stat().st_mtime_ns == made and "wrote" not in said.out
    scene = _scene_file(tmp_path, excitation={"amplitude": 12.0})
    assert cli.main([str(scene), "--out", str(out), "--jobs", "1", "--no-report"]) == 0
    said = capsys.readouterr()
    assert f"{dataset}: the scene's values changed since it was made (excitation.amplitude): computed again, and replaced when done" in said.err
    assert dataset.stat().st_mtime_ns != made and f"wrote {dataset}" in said.out
    import netCDF4

    with netCDF4.Dataset(dataset, "a") as handle:  # as if an older vibroimpact had made it
        handle.setncattr("vibroimpact_source_sha256", "0" * 64)
    assert cli.main([str(scene), "--out", str(out), "--jobs", "1", "--no-report"]) == 0
    assert f"{dataset}: other code made it (another vibroimpact version or source): computed again" in capsys.readouterr().err
