"""A kept store whose bookkeeping or metadata is damaged recovers (issue 34, items 1-2): a kill while the first block created the grid
(its variables without ``block_done``), or a lost ``block_done`` or ``block_checksum``, makes the rerun compute the
grid again and write the same dataset, saying so in one line, with no traceback (before: ``KeyError: 'block_done'``
on every rerun)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
import xarray as xr
import zarr

from tests.kinds.stepped.test_cases import _case
from tests.test_cli_runner import _scene_file
from vibroimpact import cli
from vibroimpact.kinds.stepped.cases import FIELDS
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.runs.runner import Runner
from vibroimpact.runs.store import StudyStore
from vibroimpact.runs import store as store_module


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
    assert "Traceback" not in err and "rebuilt from the store's record: " + lost in err, err  # its metadata; lost flags read as unfinished
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


def _edit_json(path: Path, change: Callable[[dict[str, Any]], None]) -> None:
    document = json.loads(path.read_text())
    change(document)
    path.write_text(json.dumps(document))


def _halve_chunks(document: dict[str, Any]) -> None:
    document["chunks"] = [max(1, size // 2) for size in document["chunks"]]


def _reverse_dimensions(document: dict[str, Any]) -> None:
    document["_ARRAY_DIMENSIONS"] = list(reversed(document["_ARRAY_DIMENSIONS"]))


#: Damage to one grid array's metadata, or the grid's plan, as a hand, a tool or a failing disk leaves it.
_METADATA_DAMAGE: dict[str, Callable[[Path], None]] = {
    "dtype edited": lambda store: _edit_json(store / "x1_amplitude/.zarray", lambda m: m.update(dtype="<i8")),
    "fill value edited": lambda store: _edit_json(store / "x1_amplitude/.zarray", lambda m: m.update(fill_value=5.0)),
    "compressor removed": lambda store: _edit_json(store / "x1_amplitude/.zarray", lambda m: m.update(compressor=None)),
    "chunks edited": lambda store: _edit_json(store / "x1_amplitude/.zarray", _halve_chunks),
    ".zarray lost": lambda store: (store / "x1_amplitude/.zarray").unlink(),
    ".zarray truncated": lambda store: (store / "x1_amplitude/.zarray").write_text((store / "x1_amplitude/.zarray").read_text()[:20]),
    "scale_factor added": lambda store: _edit_json(store / "x1_amplitude/.zattrs", lambda m: m.update(scale_factor=1000.0)),
    "units edited": lambda store: _edit_json(store / "x1_amplitude/.zattrs", lambda m: m.update(units="furlong")),
    "flag meanings edited": lambda store: _edit_json(store / "stable/.zattrs", lambda m: m.update(flag_meanings="a b c")),
    "dimensions swapped": lambda store: _edit_json(store / "x1_amplitude/.zattrs", _reverse_dimensions),
    ".zattrs lost": lambda store: (store / "x1_amplitude/.zattrs").unlink(),
    ".zattrs truncated": lambda store: (store / "x1_amplitude/.zattrs").write_text((store / "x1_amplitude/.zattrs").read_text()[:10]),
    "block_done .zarray lost": lambda store: (store / "block_done/.zarray").unlink(),
    "block_shape edited": lambda store: _edit_json(store / ".zattrs", lambda m: m.update(block_shape=[1] * len(m["block_shape"]))),
    "block_shape garbage": lambda store: _edit_json(store / ".zattrs", lambda m: m.update(block_shape="x")),
}


def _run_kept(scene: Path, out: Path) -> int:
    return cli.main([str(scene), "--out", str(out), "--jobs", "1", "--keep-zarr", "--no-report"])


def _damage_and_rerun(folder: Path, damage: Callable[[Path], object], capsys: pytest.CaptureFixture[str]) -> tuple[xr.Dataset, xr.Dataset, str]:
    """Run the tiny scene keeping its store, ``damage(store)``, run it again: both datasets and the rerun's stderr
    (which must hold no traceback)."""
    scene, out = _scene_file(folder), folder / "out"
    assert _run_kept(scene, out) == 0
    first = xr.load_dataset(out / "tiny.nc")
    damage(out / "tiny.zarr")
    capsys.readouterr()
    assert _run_kept(scene, out) == 0
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    return first, xr.load_dataset(out / "tiny.nc"), err


def _assert_same_results(again: xr.Dataset, first: xr.Dataset) -> None:
    """Every variable and coordinate identical (values, dtype, attributes); the dataset's attributes but the run's own."""
    assert set(again.variables) == set(first.variables)
    for name in first.variables:
        xr.testing.assert_identical(again[name], first[name])
    assert {key: value for key, value in again.attrs.items() if not key.startswith("run_")}.keys() == {key for key in first.attrs if not key.startswith("run_")}


@pytest.mark.faults
@pytest.mark.timeout(300)
@pytest.mark.parametrize("damage", sorted(_METADATA_DAMAGE))
def test_damaged_metadata_of_a_kept_store_is_rebuilt_never_exported(tmp_path: Path, damage: str, capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 34, item 1: with an edited dtype the rerun exported garbage, with an edited attribute the edit, with a
    lost .zarray no variable, exit 0 each time; a truncated .zarray, edited chunks or block_shape failed every rerun.
    Now every metadata file is compared with the record written when the grid began, and rebuilt from it."""
    first, again, err = _damage_and_rerun(tmp_path, _METADATA_DAMAGE[damage], capsys)
    assert "rebuilt from the store's record" in err, err
    _assert_same_results(again, first)


@pytest.mark.faults
@pytest.mark.timeout(300)
def test_a_grid_without_its_record_is_computed_again(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A kill after the grid's arrays were created but before its record was written (the record goes last)."""
    first, again, err = _damage_and_rerun(tmp_path, lambda store: _edit_json(store / ".zattrs", lambda m: m.pop("grid_record")), capsys)
    assert "finished blocks are computed again" in err, err
    _assert_same_results(again, first)


@pytest.mark.faults
@pytest.mark.timeout(300)
@pytest.mark.parametrize("readable", [True, False])
def test_an_array_foreign_to_the_grid_is_never_exported(tmp_path: Path, readable: bool, capsys: pytest.CaptureFixture[str]) -> None:
    """An array put into a kept store's root reached the .nc; an unreadable one failed every rerun. A readable one is
    left where it is and not exported; a store with an unreadable one is set aside (renamed) and computed again."""

    def intrude(store: Path) -> None:
        if readable:
            array = zarr.open_group(str(store), mode="a", zarr_format=2, use_consolidated=False).create_array("intruder", shape=(3,), dtype="f8")
            array[...] = 7.0
            array.attrs["_ARRAY_DIMENSIONS"] = ["intruder_dim"]
        else:
            (store / "intruder").mkdir()
            (store / "intruder" / ".zarray").write_text("{not json")

    first, again, err = _damage_and_rerun(tmp_path, intrude, capsys)
    _assert_same_results(again, first)
    out = tmp_path / "out"
    assert (out / "tiny.zarr" / "intruder").exists() == readable
    set_aside = list(out.glob("tiny.zarr.damaged-*"))
    assert len(set_aside) == (0 if readable else 1) and all((path / "intruder").is_dir() for path in set_aside), err
    assert readable or f"set aside as {set_aside[0].name}" in err


@pytest.mark.faults
@pytest.mark.timeout(300)
def test_a_store_without_its_attributes_is_set_aside_and_said_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A deleted root .zattrs was called "the package's code changed" and the store deleted; it is set aside, named."""
    first, again, err = _damage_and_rerun(tmp_path, lambda store: (store / ".zattrs").unlink(), capsys)
    assert "attributes are lost (damaged): set aside as tiny.zarr.damaged-" in err and "code changed" not in err, err
    assert len(list((tmp_path / "out").glob("tiny.zarr.damaged-*/x1_amplitude"))) == 1
    _assert_same_results(again, first)


@pytest.mark.faults
@pytest.mark.timeout(300)
def test_an_interrupt_while_the_store_is_removed_is_one_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """A Ctrl-C while the finished store was removed: exit 1 with a traceback. The results are written by then: the
    run says so in one line, exits 130, and the next run removes what is left."""
    scene, out = _scene_file(tmp_path), tmp_path / "out"

    def interrupted(*_args: object, **_kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(store_module.shutil, "rmtree", interrupted)
    assert cli.main([str(scene), "--out", str(out), "--jobs", "1", "--no-report"]) == cli.EXIT_INTERRUPTED
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.strip().splitlines()[-1].startswith("interrupted while removing"), err
    assert (out / "tiny.nc").is_file() and list(out.glob(".tiny.zarr.removed-*"))
    monkeypatch.undo()
    assert cli.main([str(scene), "--out", str(out), "--jobs", "1", "--no-report"]) == 0
    assert not list(out.glob(".tiny.zarr.removed-*"))


#: Damage to a store's finished cases: the group's own metadata, one case's metadata, the group replaced by a file.
_CASE_DAMAGE: dict[str, Callable[[Path], None]] = {
    "cases .zgroup lost": lambda store: (store / "cases/.zgroup").unlink(),
    "cases .zgroup truncated": lambda store: (store / "cases/.zgroup").write_text("{"),
    "a case's .zarray truncated": lambda store: next(store.glob("cases/*/.zarray")).write_text("{"),
    "a case's .zattrs truncated": lambda store: next(store.glob("cases/*/.zattrs")).write_text("{"),
    "cases a file": lambda store: (shutil.rmtree(store / "cases"), (store / "cases").write_text("x")),
}


@pytest.mark.faults
@pytest.mark.timeout(300)
@pytest.mark.parametrize("damage", sorted(_CASE_DAMAGE))
def test_damaged_cases_are_computed_again_never_a_traceback(system: TwoDofSystem, tmp_path: Path, damage: str) -> None:
    """A truncated .zgroup or .zattrs of the finished cases raised a JSONDecodeError on every rerun; now the group's
    metadata is rebuilt, a case whose own is damaged is computed again, and the results are those of the first run."""
    cases = [_case(system, "pgf", frequencies=(25.0,)), _case(system, "linear", frequencies=(30.0, 31.0))]
    path = tmp_path / "study.zarr"
    first = Runner(store=StudyStore(path, "fingerprint"), progress=False).map(cases)
    _CASE_DAMAGE[damage](path)
    said: list[str] = []
    again = Runner(store=StudyStore(path, "fingerprint", say=said.append), progress=False).map(cases)
    for before, after in zip(first, again):
        for name in FIELDS:
            if name != "wall_time":
                np.testing.assert_array_equal(after[name], before[name])
    assert StudyStore(path, "fingerprint").case_count() == 2
    assert damage.startswith("a case's") or said, damage  # the group's damage is said in one line


@pytest.mark.faults
def test_only_a_store_this_run_began_counts_as_fresh(tmp_path: Path) -> None:
    """A run whose cluster is lost removes a store of nothing finished only if it began it: an earlier run's store
    whose flags cannot be read (so that it seems to hold nothing) is never removed unasked."""
    path = tmp_path / "study.zarr"
    assert StudyStore(path, "fingerprint").fresh
    assert not StudyStore(path, "fingerprint").fresh
    assert StudyStore(path, "another scene").fresh  # the other fingerprint's store was discarded: this one is new
