"""Every dataset's header is written once, by ``run_study``: ``title`` (its kind's row), ``scene_name``, the scene's
text, the provenance, then what the kind's run said, and ``study_kind`` last; the Python route (``parse_scene`` ->
``run_study`` -> ``write_dataset``) and ``run-study`` write the same header."""

from __future__ import annotations

from pathlib import Path

import pytest
import xarray as xr

from vibroimpact import __version__
from vibroimpact.runs import run as run_module
from vibroimpact.runs.fingerprints import source_hash
from vibroimpact.runs.run import HEADER_ATTRIBUTES, read_dataset, run_study, write_dataset
from vibroimpact.scene import load_scene, parse_scene
from vibroimpact.scene.kinds import KIND_NAMES
from vibroimpact.scene.reader import read_yaml

from tests.golden.golden import SCENES

#: A golden scene of each kind and the title its dataset has always had (written out: not read from the table).
TITLES = {
    "design_paper": ("design", "vibroimpact design 'design_paper'"),
    "absorber_concepts": ("concepts", "vibroimpact absorber concepts 'absorber_concepts'"),
    "validation_zeno": ("validation", "vibroimpact validation 'validation_zeno': zeno"),
    "accuracy_cost": ("benchmark", "vibroimpact benchmark 'accuracy_cost'"),
    "bifurcation": ("bifurcation", "vibroimpact bifurcation study 'bifurcation'"),
    "bumper_sweep": ("swept", "vibroimpact study 'bumper_sweep'"),
    "restitution": ("stepped", "vibroimpact study 'restitution'"),
}


class _Study:
    """A kind's study that computes nothing: its dataset holds one attribute of its own (``attrs``)."""

    def __init__(self, name: str, attrs: dict[str, object]) -> None:
        self.name, self.attrs = name, attrs

    def engines(self, scene: object) -> tuple[str, ...]:
        return ()

    def run(self, scene: object, progress: object, runner: object) -> xr.Dataset:
        return xr.Dataset(attrs=dict(self.attrs))


def test_the_table_covers_every_kind() -> None:
    assert {kind for kind, _ in TITLES.values()} == set(KIND_NAMES)


@pytest.mark.parametrize("name", list(TITLES))
def test_run_study_writes_the_header_first_and_the_kind_last(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    scene = load_scene(SCENES / f"{name}.yaml")
    kind, title = TITLES[name]
    assert scene.kind == kind
    monkeypatch.setattr(run_module, "study_kind", lambda scene: _Study(scene.kind, {"kind_own": 1.5}))
    dataset = run_study(scene, progress=None)
    assert list(dataset.attrs) == [*HEADER_ATTRIBUTES, "kind_own", "study_kind"]
    assert dataset.attrs["title"] == title and dataset.attrs["scene_name"] == name and dataset.attrs["study_kind"] == kind
    assert dataset.attrs["scene"] == scene.text and name in scene.text
    assert dataset.attrs["vibroimpact_version"] == __version__ and dataset.attrs["vibroimpact_source_sha256"] == source_hash()
    assert dataset.attrs["Conventions"] == "CF-1.8"


@pytest.mark.parametrize("written", ["title", "scene", "Conventions", "study_kind"])
def test_a_kind_that_writes_a_header_attribute_is_refused(written: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(run_module, "study_kind", lambda scene: _Study(scene.kind, {written: "mine"}))
    with pytest.raises(ValueError, match=f"the validation kind's run wrote {written}: run_study writes the header"):
        run_study(load_scene(SCENES / "validation_zeno.yaml"), progress=None)


@pytest.mark.timeout(120)
def test_the_python_route_and_run_study_write_the_same_header(tmp_path: Path) -> None:
    """A real run (the cheap Zeno validation, whose kind wrote its own header before): the file ``run-study`` writes
    and the one the Python route writes carry the same header, and the kind's own attributes after it."""
    from vibroimpact.cli import main

    path = SCENES / "validation_zeno.yaml"
    assert main([str(path), "--out", str(tmp_path / "cli"), "--jobs", "1", "--no-report"]) == 0
    by_cli = read_dataset(tmp_path / "cli" / "validation_zeno.nc")
    text = path.read_text(encoding="utf-8")
    by_python = read_dataset(write_dataset(run_study(parse_scene(read_yaml(text), text), progress=None), tmp_path / "python.nc"))
    keys = [*HEADER_ATTRIBUTES, "study_kind"]
    assert {key: by_cli.attrs[key] for key in keys} == {key: by_python.attrs[key] for key in keys}
    assert by_python.attrs["title"] == "vibroimpact validation 'validation_zeno': zeno" and by_python.attrs["scene"] == text
    assert list(by_python.attrs)[: len(HEADER_ATTRIBUTES)] == list(HEADER_ATTRIBUTES)
    assert by_python.attrs["validation_case"] == "zeno" and by_cli.attrs["validation_source"] == by_python.attrs["validation_source"]
