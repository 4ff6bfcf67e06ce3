"""A kept store whose bookkeeping is damaged recovers (issue 34, item 2): a kill while the first block created the grid
(its variables without ``block_done``), or a lost ``block_done`` or ``block_checksum``, makes the rerun compute the
grid again and write the same dataset, saying so in one line, with no traceback (before: ``KeyError: 'block_done'``
on every rerun)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import xarray as xr

from tests.test_cli_runner import _scene_file
from vibroimpact import cli


@pytest.mark.faults
@pytest.mark.timeout(300)
@pytest.mark.parametrize("lost", ["block_done", "block_checksum"])
def test_a_store_without_its_block_bookkeeping_is_computed_again(tmp_path: Path, lost: str, capsys: pytest.CaptureFixture[str]) -> None:
    scene = _scene_file(tmp_path)
    out = tmp_path / "out"
    assert cli.main([str(scene), "--out", str(out), "--jobs", "1", "--keep-zarr"]) == 0
    first = xr.load_dataset(out / "tiny.nc")
    shutil.rmtree(out / "tiny.zarr" / lost)  # as a kill between the grid's variables and its bookkeeping leaves it
    capsys.readouterr()
    assert cli.main([str(scene), "--out", str(out), "--jobs", "1", "--keep-zarr"]) == 0
    err = capsys.readouterr().err
    assert "Traceback" not in err and "computed again" in err, err
    again = xr.load_dataset(out / "tiny.nc")
    for name in first.data_vars:
        xr.testing.assert_identical(again[name], first[name])


@pytest.mark.faults
@pytest.mark.timeout(300)
def test_a_store_whose_removal_was_cut_off_goes_with_the_next_run(tmp_path: Path) -> None:
    """A Ctrl-C while a finished store was being removed left ``.NAME.zarr.removed-<pid>`` for ever; the next run on
    the same output deletes it (it only ever holds a store whose results were exported)."""
    out = tmp_path / "out"
    doomed = out / ".tiny.zarr.removed-4242"
    (doomed / "x1_amplitude").mkdir(parents=True)
    (doomed / "x1_amplitude" / "0.0").write_bytes(b"\0" * 64)
    assert cli.main([str(_scene_file(tmp_path)), "--out", str(out), "--jobs", "1"]) == 0
    assert not doomed.exists() and (out / "tiny.nc").is_file()
