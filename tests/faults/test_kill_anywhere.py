"""A study killed (SIGKILL: an OOM kill, a batch system's hard limit, a power cut) at any instant of its store's life
leaves something the rerun recovers: the rerun exits 0, prints no traceback and writes the dataset an undisturbed run
writes (issue 34, item 2: a kill while the first block created the grid failed every rerun with KeyError)."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path
from typing import Callable

import pytest
import xarray as xr

from tests.run_study_process import start_run_study
from tests.test_cli_runner import _scene_file
from vibroimpact import cli

#: When to kill: a moment the run reaches (its output folder seen from outside) and a delay after it [s]. The grid is
#: created (bookkeeping, about 30 variables, the record) within about 0.1 s of its ``block_done`` appearing.
_MOMENTS: dict[str, Callable[[Path], bool]] = {
    "store begun": lambda out: (out / "tiny.zarr").exists(),
    "grid being created": lambda out: (out / "tiny.zarr" / "block_done").exists(),
    "dataset being written": lambda out: any(out.glob(".tiny.nc*")) or (out / "tiny.nc").exists(),
    "dataset written": lambda out: (out / "tiny.nc").exists(),
}
_KILLS = [("store begun", 0.0), ("store begun", 0.5)] + [("grid being created", delay) for delay in (0.0, 0.005, 0.01, 0.02, 0.04, 0.07, 0.1, 0.15)] + [("dataset being written", 0.0), ("dataset written", 0.0), ("dataset written", 0.01)]
#: Several restitutions: several blocks.
_SWEEP = {"restitution": [0.1, 0.3, 0.5, 0.7], "frequency": {"start": 18.0, "stop": 30.0, "step": 0.05}}


@pytest.fixture(scope="module")
def undisturbed(tmp_path_factory: pytest.TempPathFactory) -> xr.Dataset:
    folder = tmp_path_factory.mktemp("undisturbed")
    assert cli.main([str(_scene_file(folder, sweep=_SWEEP, stop={"clearance": 0.003})), "--out", str(folder / "out"), "--jobs", "1", "--no-report"]) == 0
    return xr.load_dataset(folder / "out" / "tiny.nc")


@pytest.mark.faults
@pytest.mark.timeout(300)
@pytest.mark.parametrize(("moment", "delay"), _KILLS)
def test_a_kill_at_any_instant_is_recovered_by_the_rerun(tmp_path: Path, moment: str, delay: float, undisturbed: xr.Dataset, capsys: pytest.CaptureFixture[str]) -> None:
    scene = _scene_file(tmp_path, sweep=_SWEEP, stop={"clearance": 0.003})
    arguments = [str(scene), "--out", str(tmp_path / "out"), "--jobs", "1", "--no-report"]
    process = start_run_study(arguments, tmp_path)
    while not _MOMENTS[moment](tmp_path / "out") and process.poll() is None:
        time.sleep(0.001)
    time.sleep(delay)
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGKILL)
    process.communicate(timeout=60)
    capsys.readouterr()
    assert cli.main(arguments) == 0
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    again = xr.load_dataset(tmp_path / "out" / "tiny.nc")
    assert set(again.variables) == set(undisturbed.variables)
    for name in undisturbed.variables:
        xr.testing.assert_identical(again[name], undisturbed[name])
