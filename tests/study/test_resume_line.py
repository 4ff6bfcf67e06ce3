"""A resumed run says what its store gave back, in one line, the same in every kind (issue 50): ``resumed: 2 of 2
cases reused from ...`` for the cases of a runner, ``resumed: 4 of 4 blocks reused`` for a stepped grid; a fresh run,
and a case asked twice within one run, say nothing of it."""

from __future__ import annotations

from pathlib import Path

from tests.kinds.stepped.test_cases import _case
from tests.study.test_estimate import small_scene
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.runs.run import run_study
from vibroimpact.runs.runner import Runner
from vibroimpact.runs.store import StudyStore
from vibroimpact.scene.reader import parse_scene


def test_a_runner_says_how_many_cases_its_store_gave_back(system: TwoDofSystem, tmp_path: Path) -> None:
    cases = [_case(system, "pgf", frequencies=(25.0,)), _case(system, "linear", frequencies=(30.0, 31.0))]
    path = tmp_path / "study.zarr"
    fresh = Runner(store=StudyStore(path, "fingerprint"), progress=False)
    fresh.map(cases)
    fresh.map(cases)  # asked again in the same run: what it stored itself is no resume
    assert fresh.reuse_line() == ""
    again = Runner(store=StudyStore(path, "fingerprint"), progress=False)
    again.map(cases[:1])
    assert again.reuse_line() == f"resumed: 1 of 1 cases reused from {path}"
    again.map(cases)
    assert again.reuse_line() == f"resumed: 3 of 3 cases reused from {path}"
    assert Runner(progress=False).reuse_line() == ""  # no store: nothing to say


def test_a_stepped_study_resumed_from_its_store_says_so_in_one_line(tmp_path: Path) -> None:
    document = small_scene() | {"solutions": ["linear", "pgf"]}
    document.pop("simulation")
    scene = parse_scene(document)
    path = tmp_path / "small.zarr"
    said: list[str] = []
    first = run_study(scene, progress=said.append, store=StudyStore(path, "fingerprint"))
    assert not any(line.startswith("resumed:") for line in said), said
    said.clear()
    second = run_study(scene, progress=said.append, store=StudyStore(path, "fingerprint"))
    resumed = [line for line in said if line.startswith("resumed:")]
    assert len(resumed) == 1 and resumed[0].endswith(f"blocks reused from {path}"), said
    reused, _, total = resumed[0].removeprefix("resumed: ").partition(" blocks")[0].partition(" of ")
    assert int(reused) == int(total) >= 1
    assert first["x1_amplitude"].equals(second["x1_amplitude"])
