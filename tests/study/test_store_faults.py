"""A store that proves its blocks (issue 22, item 1-2): every finished block is checked against the checksum it was
written with, on resume and before export; a damaged one is computed again and the run says so in one line, so a
damaged store never serves damaged values: each fault below ends in the undisturbed run's dataset, bit for bit.
Finished work is discarded only for a change of values or code, said in one line, never for another scene's store."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from vibroimpact.model.system import TwoDofSystem
from vibroimpact.runs.run import run_study
from vibroimpact.runs.store import StoreOfAnotherScene, StudyStore, store_fingerprint

from tests.study.test_store import _grid_scene


@pytest.fixture(scope="module")
def undisturbed(tmp_path_factory: pytest.TempPathFactory) -> tuple[object, xr.Dataset, Path]:
    """The closed-form grid of 18 blocks (30 frequencies each) run once into a store, kept as a pristine copy."""
    from vibroimpact.kinds.stepped import blocks

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(blocks, "CLOSED_FORM_POINTS", 30)
        scene = _grid_scene()
        path = tmp_path_factory.mktemp("pristine") / "grid.zarr"
        dataset = run_study(scene, progress=None, store=StudyStore(path, store_fingerprint(scene.text)))
    return scene, dataset, path


def _rerun(undisturbed: tuple[object, xr.Dataset, Path], tmp_path: Path, damage: object, monkeypatch: pytest.MonkeyPatch) -> tuple[xr.Dataset, list[str], int]:
    """Copy the pristine store, ``damage(path)`` it, rerun: the dataset, the run's lines and the blocks solved again."""
    from vibroimpact.kinds.stepped import blocks

    scene, _dataset, pristine = undisturbed
    path = tmp_path / "grid.zarr"
    shutil.copytree(pristine, path)
    damage(path)  # type: ignore[operator]
    monkeypatch.setattr(blocks, "CLOSED_FORM_POINTS", 30)
    real, solved = blocks._solve_block, []
    monkeypatch.setattr(blocks, "_solve_block", lambda shared, index, report: (solved.append(index), real(shared, index, report))[1])
    lines: list[str] = []
    dataset = run_study(scene, progress=None, store=StudyStore(path, store_fingerprint(scene.text), say=lines.append))  # type: ignore[attr-defined]
    return dataset, lines, len(solved)


def _chunks(path: Path, variable: str) -> list[Path]:
    return sorted(chunk for chunk in (path / variable).iterdir() if not chunk.name.startswith("."))


def _missing_chunk(path: Path) -> None:
    _chunks(path, "regime")[3].unlink()  # read back as the fill value 0: 'linear' everywhere in the block


def _truncated_chunk(path: Path) -> None:
    chunk = _chunks(path, "x1_amplitude")[5]
    chunk.write_bytes(chunk.read_bytes()[:20])  # blosc fails to decompress it


def _swapped_chunks(path: Path) -> None:
    first, second = _chunks(path, "x1_amplitude")[0], _chunks(path, "x1_amplitude")[7]
    a, b = first.read_bytes(), second.read_bytes()
    first.write_bytes(b)
    second.write_bytes(a)


def _missing_metadata(path: Path) -> None:
    (path / "regime" / ".zarray").unlink()


@pytest.mark.faults  # a real store damaged on disk, run again (1-2 s each): with the other injected faults
@pytest.mark.parametrize(("damage", "blocks_again"), [(_missing_chunk, 1), (_truncated_chunk, 1), (_swapped_chunks, 2)])
def test_a_damaged_store_ends_in_the_undisturbed_dataset(undisturbed: tuple[object, xr.Dataset, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, damage: object, blocks_again: int) -> None:
    dataset, lines, solved = _rerun(undisturbed, tmp_path, damage, monkeypatch)
    xr.testing.assert_identical(dataset, undisturbed[1])
    assert solved == blocks_again
    assert lines == [f"{blocks_again} damaged blocks of 18 finished (resumed) are computed again"]


@pytest.mark.faults  # a real store damaged on disk, run again (1-2 s each): with the other injected faults
def test_lost_metadata_is_rebuilt_and_no_block_computed_again(undisturbed: tuple[object, xr.Dataset, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A lost ``.zarray`` is written back from the record the store kept when its grid began (issue 34): the 18
    finished blocks then prove their values and none is computed again (before the record: all 18 were)."""
    dataset, lines, solved = _rerun(undisturbed, tmp_path, _missing_metadata, monkeypatch)
    xr.testing.assert_identical(dataset, undisturbed[1])
    assert solved == 0
    assert len(lines) == 1 and lines[0].endswith("metadata lost or changed since it was written, rebuilt from the store's record: regime"), lines


@pytest.mark.faults  # a real store damaged on disk, run again (1-2 s each): with the other injected faults
def test_a_damaged_root_attribute_file_sets_the_store_aside_in_one_line(undisturbed: tuple[object, xr.Dataset, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Unreadable root attributes: the store is set aside (renamed, kept for whoever wants to look; issue 34) and
    computed again."""
    dataset, lines, solved = _rerun(undisturbed, tmp_path, lambda path: (path / ".zattrs").write_text("{ not json"), monkeypatch)
    xr.testing.assert_identical(dataset, undisturbed[1])
    assert solved == 18
    assert len(lines) == 1 and "its attributes are unreadable (damaged): set aside as grid.zarr.damaged-" in lines[0] and "(18 finished blocks and 0 finished cases), computed again" in lines[0], lines
    assert len(list(tmp_path.glob("grid.zarr.damaged-*/regime"))) == 1


@pytest.mark.faults  # a real store damaged on disk, run again (1-2 s each): with the other injected faults
def test_an_undamaged_store_is_served_without_a_word(undisturbed: tuple[object, xr.Dataset, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    dataset, lines, solved = _rerun(undisturbed, tmp_path, lambda path: None, monkeypatch)
    xr.testing.assert_identical(dataset, undisturbed[1])
    assert (solved, lines) == (0, [])


def test_the_fingerprint_covers_values_not_words() -> None:
    document = {"name": "s", "description": "first words", "system": {"m1": 1.0}, "report": True, "sweep": {"frequency": [20.0, 21.0]}}
    text = yaml.safe_dump(document)
    same = [text + "# a comment\n", yaml.safe_dump(document | {"description": "better words"}), yaml.safe_dump(document | {"report": False}),
            yaml.safe_dump(document | {"cluster": {"scheduler": "tcp://host:8786"}})]  # fmt: skip
    assert {store_fingerprint(other) for other in same} == {store_fingerprint(text)}
    assert store_fingerprint(yaml.safe_dump(document | {"system": {"m1": 1.5}})) != store_fingerprint(text)


def test_changed_values_discard_in_one_line_and_another_scenes_store_is_kept(tmp_path: Path) -> None:
    path = tmp_path / "s.zarr"
    first, second = tmp_path / "a.yaml", tmp_path / "b.yaml"
    store = StudyStore(path, "one", scene_path=first)
    store.save_case("exact-1", {"x": np.arange(3.0)})
    with pytest.raises(StoreOfAnotherScene, match=r"holds the finished work of another scene \(.*a\.yaml\); it is kept"):
        StudyStore(path, "two", scene_path=second)
    assert StudyStore(path, "one", scene_path=first).case_count() == 1, "the refused run deleted nothing"
    lines: list[str] = []
    assert StudyStore(path, "two", scene_path=first, say=lines.append).case_count() == 0
    assert lines == [f"{path}: the scene's values changed since it was written: 0 finished blocks and 1 finished cases discarded, computed again"]


def test_changed_values_are_named_and_an_edited_fingerprint_is_told_apart(tmp_path: Path) -> None:
    """A store records the values its fingerprint is made of: a rerun of changed values names the keys that changed,
    and a fingerprint edited in the store is said as what it is, the store set aside, not deleted (before:
    "the scene's values changed", and the store deleted)."""
    from vibroimpact.runs.fingerprints import fingerprinted_values, store_fingerprint

    first = "name: s\nsystem: {m1: 1.0, k1: 25000}\nexcitation: {amplitude: 10.0}\ndesign: {band: {start: 15, stop: 45}}\n"
    second = first.replace("amplitude: 10.0", "amplitude: 12.0").replace("stop: 45", "stop: 40")
    path = tmp_path / "s.zarr"

    def open_store(text: str, lines: list[str]) -> StudyStore:
        return StudyStore(path, store_fingerprint(text), tmp_path / "s.yaml", lines.append, fingerprinted_values(text))

    open_store(first, []).save_case("exact-1", {"x": np.arange(3.0)})
    lines: list[str] = []
    assert open_store(second, lines).case_count() == 0
    assert lines == [f"{path}: the scene's values changed (design.band.stop, excitation.amplitude) since it was written: 0 finished blocks and 1 "
                     "finished cases discarded, computed again"]
    open_store(first, []).save_case("exact-1", {"x": np.arange(3.0)})
    attributes = json.loads((path / ".zattrs").read_text())
    attributes["fingerprint"] = "0" * 24
    (path / ".zattrs").write_text(json.dumps(attributes))
    lines = []
    assert open_store(first, lines).case_count() == 0
    assert len(lines) == 1 and lines[0].startswith(f"{path}: its fingerprint is not that of the scene values and code it recorded (edited or "
                                                   "damaged): set aside as s.zarr.damaged-"), lines
    assert lines[0].endswith("(0 finished blocks and 1 finished cases), computed again"), lines
    aside = list(tmp_path.glob("s.zarr.damaged-*"))
    assert len(aside) == 1 and (aside[0] / "cases" / "exact-1").is_dir(), "the edited store is kept, never deleted"


def test_a_case_that_fails_its_checksum_is_computed_again(tmp_path: Path) -> None:
    store = StudyStore(tmp_path / "c.zarr", "f")
    store.save_case("exact-1", {"x": np.arange(1000.0), "y": np.ones(4)})
    assert store.load_case("exact-1", ("x", "y")) is not None and store.damaged_cases == 0
    chunk = next(c for c in (tmp_path / "c.zarr" / "cases" / "exact-1").iterdir() if not c.name.startswith("."))  # its one chunk
    chunk.write_bytes(chunk.read_bytes()[:-8] + bytes(8))
    assert StudyStore(tmp_path / "c.zarr", "f").load_case("exact-1", ("x", "y")) is None


def test_a_case_cut_off_or_without_its_chunk_is_computed_again(tmp_path: Path) -> None:
    store = StudyStore(tmp_path / "c.zarr", "f")
    for name in ("exact-1", "exact-2"):
        store.save_case(name, {"x": np.arange(10.0), "note": np.array("a text")})
    (tmp_path / "c.zarr" / "cases" / "exact-1" / "0").unlink()  # the packed fields lost: read as zeros
    (tmp_path / "c.zarr" / "cases" / "exact-2" / ".zattrs").unlink()  # killed before its checksum was written
    again = StudyStore(tmp_path / "c.zarr", "f")
    assert again.case_count() == 1, "only the case with a checksum counts as finished"
    assert again.load_case("exact-1", ("x",)) is None and again.damaged_cases == 1
    assert again.load_case("exact-2", ("x",)) is None and again.damaged_cases == 1, "a case cut off is not damaged: it was never finished"
    again.save_case("exact-1", {"x": np.arange(10.0), "note": np.array("a text")})
    loaded = again.load_case("exact-1", ("x", "note"))
    assert loaded is not None and np.array_equal(loaded["x"], np.arange(10.0)) and str(loaded["note"]) == "a text"


def test_a_finished_case_gone_from_the_store_is_told_from_one_never_computed(tmp_path: Path) -> None:
    path = tmp_path / "c.zarr"
    store = StudyStore(path, "f")
    for name in ("exact-1", "exact-2"):
        store.save_case(name, {"x": np.arange(3.0)})
    shutil.rmtree(path / "cases" / "exact-1")  # a whole finished case removed
    again = StudyStore(path, "f")
    assert again.load_case("exact-1", ("x",)) is None and again.lost_cases == 1
    assert again.load_case("exact-3", ("x",)) is None and again.lost_cases == 1, "never computed: not lost"
    assert again.load_case("exact-2", ("x",)) is not None and again.damaged_cases == again.unsealed_cases == 0
    (tmp_path / ".c.zarr.finished").write_text("exact-2\nexac")  # a line cut off by a kill names no case
    assert StudyStore(path, "f").load_case("exact-1", ("x",)) is None
    fresh = StudyStore(tmp_path / "other.zarr", "f")
    assert fresh.load_case("exact-1", ("x",)) is None and fresh.lost_cases == 0


def test_a_runner_says_in_one_line_how_many_finished_cases_were_gone(system: TwoDofSystem, tmp_path: Path) -> None:
    from tests.kinds.stepped.test_cases import _case
    from vibroimpact.runs.runner import Runner

    cases = [_case(system, "pgf", frequencies=(25.0,)), _case(system, "linear", frequencies=(30.0, 31.0))]
    path = tmp_path / "study.zarr"
    Runner(store=StudyStore(path, "f"), progress=False).map(cases)
    for case in (path / "cases").iterdir():
        if case.is_dir():
            shutil.rmtree(case)
    said: list[str] = []
    again = Runner(store=StudyStore(path, "f", say=said.append), progress=False)
    again.map(cases)
    assert said == ["2 cases of 2 that the store had finished are gone from it (removed): computed again"]
    assert again.reuse_line() == ""


def test_cases_written_by_older_code_are_counted_when_discarded(tmp_path: Path) -> None:
    """A store of the older layout (a group per case, marked complete) counts its cases in the discard message."""
    import zarr

    path = tmp_path / "old.zarr"
    root = zarr.open_group(str(path), mode="a", zarr_format=2)
    root.attrs.update({"fingerprint": "one", "code": "old", "scene_path": ""})
    for name in ("exact-1", "exact-2"):
        group = root.require_group(f"cases/{name}")
        group.create_array("x", data=np.arange(3.0))
        group.attrs["complete"] = True
    lines: list[str] = []
    StudyStore(path, "two", say=lines.append)
    assert len(lines) == 1 and "0 finished blocks and 2 finished cases discarded" in lines[0]


def test_a_kept_store_s_consolidated_metadata_lost_or_edited_is_said_and_a_case_without_checksum_too(tmp_path: Path) -> None:
    """A kept store's ``.zmetadata`` (a copy of the arrays' own metadata, for readers) lost or edited is said when a run
    opens it, once (the next run, cut off before keeping it, is not taken for damage); a case whose checksum file is
    lost is said as computed again (before: both silent)."""
    path = tmp_path / "k.zarr"
    store = StudyStore(path, "f")
    store.save_case("exact-1", {"x": np.arange(3.0)})
    store.keep(xr.Dataset(attrs={"title": "kept"}))
    (path / ".zmetadata").unlink()
    lines: list[str] = []
    StudyStore(path, "f", say=lines.append)
    assert lines == [f"{path / '.zmetadata'}: the store's consolidated metadata is lost: the run reads every array's own, and writes it again when it keeps the store"]
    lines.clear()
    StudyStore(path, "f", say=lines.append)
    assert lines == [], "said once: a run that did not keep the store left no copy to check"
    store = StudyStore(path, "f")
    store.keep(xr.Dataset(attrs={"title": "kept"}))
    consolidated = json.loads((path / ".zmetadata").read_text())
    consolidated["metadata"]["cases/.zgroup"] = {"zarr_format": 3}
    (path / ".zmetadata").write_text(json.dumps(consolidated))
    (path / "cases" / "exact-1" / ".zattrs").unlink()
    lines.clear()
    store = StudyStore(path, "f", say=lines.append)
    assert lines == [f"{path / '.zmetadata'}: the store's consolidated metadata differs from the arrays' own metadata (cases/.zgroup, cases/exact-1/.zattrs): "
                     "the run reads every array's own, and writes it again when it keeps the store"]
    assert store.load_case("exact-1", ("x",)) is None and store.unsealed_cases == 1 and store.damaged_cases == 0
