"""The study's chunked store (runs/store.py) and the grid's blocks (kinds/stepped/blocks.py): blocks tile the grid once,
a block is the same scene on fewer points (same numbers), finished blocks and cases survive a rerun, another scene or
other code starts afresh, and a second study on the same output is refused."""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from vibroimpact.scene import parse_scene
from vibroimpact.scene.schema import GRID_DIMS
from vibroimpact.kinds.stepped.blocks import BlockPlan, block_scene, plan_blocks
from vibroimpact.runs.run import run_study
from vibroimpact.runs.runner import Runner
from vibroimpact.kinds.stepped.study import general_block
from vibroimpact.runs.output_files import OutputBusy, claim_output
from vibroimpact.runs.store import StudyStore, store_fingerprint

from tests.study.test_estimate import small_scene


@settings(max_examples=60, deadline=None, derandomize=True)
@given(full=st.tuples(*(st.integers(1, 7) for _ in GRID_DIMS)), block=st.tuples(*(st.integers(1, 7) for _ in GRID_DIMS)))
def test_blocks_tile_the_grid_exactly_once(full: tuple[int, ...], block: tuple[int, ...]) -> None:
    plan = BlockPlan(full, tuple(min(b, n) for b, n in zip(block, full)))
    hits = np.zeros(full, dtype=int)
    for index in range(plan.count):
        region = plan.region(index)
        hits[tuple(region[dim] for dim in GRID_DIMS)] += 1
        assert plan.points(index) == np.prod([s.stop - s.start for s in region.values()])
    assert np.all(hits == 1)


def _grid_scene(**changes: object):
    document = small_scene() | {
        "sweep": {"restitution": [0.0, 0.4, 0.8], "clearance": [0.002, 0.003], "frequency": {"start": 20.0, "stop": 40.0, "step": 0.25}},
        "solutions": ["linear", "pgf", "pgf_paper"],
    }
    document.pop("stop", None)
    document.pop("simulation", None)
    return parse_scene(document | changes)


def test_a_block_is_the_same_scene_on_fewer_points() -> None:
    """Every variable of every block equals the whole grid's values at the block's points (closed forms: pointwise)."""
    scene = _grid_scene()
    whole = general_block(scene, Runner(progress=False))
    plan = BlockPlan(plan_blocks(scene, 1).full, (2, 1, 1, 1, 30))
    assert plan.count == 2 * 2 * 3
    for index in range(plan.count):
        region = plan.region(index)
        part = general_block(block_scene(scene, region), Runner(progress=False))
        for name, variable in part.data_vars.items():
            expected = whole[name].isel(region).values
            np.testing.assert_allclose(variable.values.astype(float), expected.astype(float), rtol=1e-15, atol=0.0, equal_nan=True, err_msg=name)


def test_block_scene_keeps_the_simulation_frequencies_inside_the_block() -> None:
    scene = parse_scene(small_scene() | {"sweep": {"frequency": {"start": 20.0, "stop": 30.0, "step": 0.5}}, "simulation": {"frequency": [21.0, 25.0, 29.5], "start": "pgf"}})
    region = {"restitution": slice(0, 1), "clearance": slice(0, 1), "bumper_frequency": slice(0, 1), "sweep": slice(0, 1), "frequency": slice(8, 15)}
    part = block_scene(scene, region)
    np.testing.assert_array_equal(part.settings.all_frequencies, scene.settings.all_frequencies[8:15])
    assert part.settings.simulation is not None and list(part.settings.simulation.frequency) == [25.0]


def test_the_stored_grid_reads_back_with_its_types_and_flags(tmp_path: Path) -> None:
    """A study through a store on disk equals the in-memory one, flags keep their int8 type (CF flag_values)."""
    scene = _grid_scene()
    store = StudyStore(tmp_path / "grid.zarr", store_fingerprint(scene.text))
    stored = run_study(scene, progress=None, store=store, load=False)
    memory = run_study(scene, progress=None)
    assert isinstance(stored["x1_amplitude"].data, __import__("dask").array.Array)  # lazy: read from the store
    xr.testing.assert_identical(stored.load(), memory)
    assert stored["regime"].dtype == np.int8 and stored["regime"].attrs["flag_values"].dtype == np.int8
    assert store.finished_blocks().all() and store.block_count() == plan_blocks(scene, 1).count


def test_a_rerun_takes_finished_blocks_from_the_store(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    scene = _grid_scene()
    path = tmp_path / "grid.zarr"
    first = run_study(scene, progress=None, store=StudyStore(path, store_fingerprint(scene.text)))
    from vibroimpact.kinds.stepped import blocks

    def fail(*_arguments: object) -> None:
        raise AssertionError("a finished block was solved again")

    monkeypatch.setattr(blocks, "_solve_block", fail)
    again = run_study(scene, progress=None, store=StudyStore(path, store_fingerprint(scene.text)))
    xr.testing.assert_identical(first, again)


def _interrupt_after(blocks_solved: int, scene: object, path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Run ``scene`` into the store at ``path`` in blocks of 30 frequencies (18 blocks) and interrupt it (Ctrl-C)
    after ``blocks_solved`` blocks."""
    from vibroimpact.kinds.stepped import blocks

    monkeypatch.setattr(blocks, "CLOSED_FORM_POINTS", 30)
    real = blocks._solve_block
    solved: list[int] = []

    def interrupted(shared: object, index: int, report: object) -> object:
        if len(solved) == blocks_solved:
            raise KeyboardInterrupt
        solved.append(index)
        return real(shared, index, report)  # type: ignore[arg-type]

    monkeypatch.setattr(blocks, "_solve_block", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_study(scene, progress=None, store=StudyStore(path, store_fingerprint(scene.text)))  # type: ignore[arg-type, attr-defined]
    monkeypatch.setattr(blocks, "_solve_block", real)


@pytest.mark.slow
def test_a_half_written_store_resumes_with_the_missing_blocks_only(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Interrupted after some blocks (a block whose flag is not set counts as not written): the rerun solves the
    others only and the result equals an uninterrupted run."""
    scene = _grid_scene()
    path = tmp_path / "grid.zarr"
    from vibroimpact.kinds.stepped import blocks

    _interrupt_after(4, scene, path, monkeypatch)
    assert StudyStore(path, store_fingerprint(scene.text)).block_count() == 4
    real = blocks._solve_block
    solved: list[int] = []
    monkeypatch.setattr(blocks, "_solve_block", lambda shared, index, report: (solved.append(index), real(shared, index, report))[1])
    resumed = run_study(scene, progress=None, store=StudyStore(path, store_fingerprint(scene.text)))
    assert len(solved) == plan_blocks(scene, 1).count - 4 and not set(solved) & set(range(4))
    xr.testing.assert_identical(resumed, run_study(scene, progress=None))


def test_another_scene_or_other_code_starts_afresh(tmp_path: Path) -> None:
    scene = _grid_scene()
    path = tmp_path / "grid.zarr"
    run_study(scene, progress=None, store=StudyStore(path, store_fingerprint(scene.text)))
    assert StudyStore(path, store_fingerprint(scene.text)).block_count() > 0
    assert StudyStore(path, store_fingerprint(scene.text + "\nsweep: {clearance: [0.0025]}")).block_count() == 0


def test_cases_keep_their_text_and_numbers(tmp_path: Path) -> None:
    store = StudyStore(tmp_path / "cases.zarr", "fingerprint")
    result = {
        "x": np.array([1.0, np.nan]), "z": np.array([1 + 2j]), "notes": np.array(["fold at 24.1 Hz", "grazing"], dtype=object), "flag": np.int8([1, -1]),
        "duration": np.array(300.0), "none": np.zeros((0, 3)),
    }  # fmt: skip
    store.save_case("exact-abc", result)
    loaded = StudyStore(tmp_path / "cases.zarr", "fingerprint").load_case("exact-abc", ("x", "z", "notes", "flag", "duration", "none"))
    assert loaded is not None
    np.testing.assert_array_equal(loaded["x"], result["x"])
    np.testing.assert_array_equal(loaded["z"], result["z"])
    assert list(loaded["notes"]) == ["fold at 24.1 Hz", "grazing"] and loaded["flag"].dtype == np.int8
    assert loaded["duration"].shape == () and float(loaded["duration"]) == 300.0 and loaded["none"].shape == (0, 3)  # exact: stored as given
    assert store.load_case("exact-abc", ("x", "missing")) is None  # written by older code: run again


def test_a_second_study_on_the_same_output_is_refused(tmp_path: Path) -> None:
    with claim_output(tmp_path):
        with pytest.raises(OutputBusy, match=rf"is being written by another run-study \(process {os.getpid()} on "):
            with claim_output(tmp_path):
                pass
    assert not (tmp_path / ".run-study.lock").exists()


def test_a_lock_file_left_by_a_killed_run_holds_nothing(tmp_path: Path) -> None:
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True, check=True)
    import socket

    (tmp_path / ".run-study.lock").write_text(f"{dead.stdout.strip()} {socket.gethostname()} 2026-01-01T00:00:00\n")
    with claim_output(tmp_path) as lock:
        assert lock.read_text().split()[0] == str(os.getpid())


def test_the_block_plan_follows_the_work() -> None:
    """Closed forms only: blocks of up to 50 000 points; a stepped sweep (a chain along frequency) keeps whole rows;
    independent simulated points: 16-256 per block, more blocks for more workers."""
    closed = _grid_scene()
    assert plan_blocks(closed, 2).count == 1
    simulated = parse_scene(small_scene() | {"stop": {"clearance": 0.003}, "sweep": {"restitution": [0.2, 0.4], "frequency": {"start": 20.0, "stop": 40.0, "step": 0.01}}, "simulation": {"frequency": {"start": 20.0, "stop": 40.0, "step": 0.05}, "start": "pgf"}})
    one, eight = plan_blocks(simulated, 1), plan_blocks(simulated, 8)
    assert one.count < eight.count
    chain = replace(simulated, settings=replace(simulated.settings, simulation=replace(simulated.settings.simulation, start="sweep_up")))
    assert plan_blocks(chain, 8).block[-1] == simulated.settings.all_frequencies.size


@pytest.mark.slow
def test_a_resumed_study_keeps_its_blocks_whatever_its_workers(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The block plan depends on the workers; a study resumed with other workers (another plan) reuses the plan
    stored with its blocks, so its values land where they belong."""
    scene = _grid_scene()
    path = tmp_path / "grid.zarr"
    from vibroimpact.kinds.stepped import blocks

    _interrupt_after(5, scene, path, monkeypatch)  # the first run's plan: 18 blocks of 30 frequencies
    monkeypatch.setattr(blocks, "CLOSED_FORM_POINTS", 50)  # the resumed run would plan other blocks
    store = StudyStore(path, store_fingerprint(scene.text))
    assert store.grid_plan() == ((3, 2, 1, 1, 81), (1, 1, 1, 1, 30))
    resumed = run_study(scene, progress=None, store=store)
    monkeypatch.setattr(blocks, "CLOSED_FORM_POINTS", 30)  # the same plan, uninterrupted: bit for bit
    xr.testing.assert_identical(resumed, run_study(scene, progress=None))


def test_where_the_work_runs_is_not_part_of_the_fingerprint() -> None:
    text = "name: a\nsweep: {frequency: [20.0, 21.0]}\n"
    assert store_fingerprint(text) == store_fingerprint(text + "cluster: {scheduler: tcp://head:8786}\n")
    assert store_fingerprint(text) != store_fingerprint(text.replace("21.0", "22.0"))


def test_a_removed_store_leaves_nothing_behind(tmp_path: Path) -> None:
    scene = _grid_scene()
    store = StudyStore(tmp_path / "grid.zarr", store_fingerprint(scene.text))
    run_study(scene, progress=None, store=store)
    store.remove()
    assert list(tmp_path.iterdir()) == []
